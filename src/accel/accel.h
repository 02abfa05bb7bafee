#pragma once
// Ray casting against a Scene. Embree 3 lives behind this header: nothing else in plenoptic
// includes it. Vertex and index buffers are shared with the Scene, not copied, so the Scene
// must outlive the Accel and must not change while it exists.
#include "core/math.h"

#include <cstdint>
#include <memory>
#include <span>

namespace pl {

struct Scene;

/// Alpha masks (Material::alphaTexture/alphaFactor/alphaCutoff) are honoured by every query
/// below: a point whose coverage is below the cutoff is not a hit, not an occluder.

/// A ray's closest hit. barycentrics are Embree's (u, v): p = (1−u−v)·p0 + u·p1 + v·p2.
struct RayHit {
  static constexpr uint32_t kNone = 0xffffffffu;
  float t = kInfinity;
  uint32_t mesh = kNone;
  uint32_t triangle = kNone;
  Vec2 barycentrics{0.0f};
  bool hit() const { return mesh != kNone; }
};

class Accel {
 public:
  /// Builds the BVH (Embree's default quality; high quality for static scenes). Throws
  /// pl::Error with Embree's message if the device or the build fails.
  explicit Accel(const Scene& scene);
  ~Accel();
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  /// Closest hit along the ray within (tMin, tMax); returns hit.hit().
  bool intersect(const Ray& ray, RayHit& hit) const;
  /// True when anything blocks the ray within (tMin, tMax).
  bool occluded(const Ray& ray) const;

  /// Coherent rays (camera rays of a tile): intersected as 16-wide packets. Any count.
  void intersectCoherent(std::span<const Ray> rays, std::span<RayHit> hits) const;
  /// Incoherent rays (gather/bounce rays): intersected as an Embree stream. Any count.
  void intersectIncoherent(std::span<const Ray> rays, std::span<RayHit> hits) const;
  /// Occlusion for many rays at once; occluded[i] = 1 when ray i is blocked.
  void occludedMany(std::span<const Ray> rays, std::span<uint8_t> occluded) const;
  /// The same for coherent rays (e.g. shadow rays from one point towards one light, in
  /// order): traced as 16-wide packets, which share the BVH traversal.
  void occludedCoherent(std::span<const Ray> rays, std::span<uint8_t> occluded) const;

  /// World-space bounds of the scene.
  Vec3 boundsMin() const { return boundsMin_; }
  Vec3 boundsMax() const { return boundsMax_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Vec3 boundsMin_{0.0f}, boundsMax_{0.0f};
};

/// Moves a ray origin off a surface along its geometric normal, to the side `direction`
/// leaves towards, so the new ray does not hit the surface it starts on. The offset is
/// relative to the magnitude of the coordinates (float precision scales with them).
///
/// Why 2e-5·scale: a float's spacing at magnitude m is m·2⁻²³ ≈ 1.2e-7·m, and a hit point
/// rebuilt from barycentrics (or as o + t·d) is off the true plane by a few such ulps of the
/// largest coordinate (Wächter & Binder, "A Fast and Robust Method for Avoiding
/// Self-Intersection", Ray Tracing Gems ch. 6, bound the error at ~10 ulp). 2e-5 ≈ 170 ulp
/// keeps a margin of more than 10× over that, while staying far below any feature size: at
/// most 2e-5 of the scene's extent (0.011 units in the 556-unit Cornell box), so contact
/// shadows and thin walls are unaffected. `1 +` keeps an absolute floor
/// (2e-5 units) near the origin, where the relative spacing would vanish.
inline Vec3 offsetRayOrigin(const Vec3& position, const Vec3& geometricNormal, const Vec3& direction) {
  const float scale = 1.0f + std::max(std::abs(position.x), std::max(std::abs(position.y), std::abs(position.z)));
  const float offset = 2e-5f * scale;
  return position + (glm::dot(direction, geometricNormal) >= 0.0f ? offset : -offset) * geometricNormal;
}

}  // namespace pl
