#pragma once
// Emitters besides the scene's lights (lights.h): emissive triangles and the environment,
// prepared for sampling. Each gives its emitted radiance, a way to sample it, the density of
// that sampling and an estimate of its power (the light sampler's selection weight, light.h).
// The scene description the loaders fill in (scene.h: Material emission, Environment) stays
// in scene/; this is where it becomes something that can be sampled.
//
// Units: radiance Le in W·sr⁻¹·m⁻², intensity I in W·sr⁻¹, irradiance E in W·m⁻²; "power" is
// a luminance-weighted flux estimate (Y of the RGB), used only to choose between lights.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/math.h"
#include "env/env.h"
#include "scene/scene.h"

namespace pl {

/// A triangle of an emissive material, prepared for sampling points on it: the one list the
/// path tracer and the bake sample their area lights from.
struct EmissiveTriangle {
  uint32_t mesh = 0, triangle = 0, material = 0;
  Vec3 p0{0.0f}, edge1{0.0f}, edge2{0.0f};  ///< point = p0 + b₁·edge1 + b₂·edge2
  Vec3 normal{0.0f};                        ///< unit geometric normal (winding), the emitting side
  float area = 0.0f;
  Rgb radiance{0.0f};                       ///< the material's emission (W·sr⁻¹·m⁻²), untextured
  /// The mean of the emission texture over the triangle (meanEmissionModulation; exactly 1
  /// without a texture): the triangle's mean Le is radiance × meanModulation.
  Rgb meanModulation{1.0f};
  bool textured = false;  ///< whether Le varies over the triangle (its material's emissionTexture)
  bool twoSided = false;

  /// The material's emission towards a direction whose cosine against `normal` is cosFront
  /// (the emission sidedness rule of scene.h emittedRadiance: the front only, unless
  /// two-sided), before any texture: Le at a point is this × emissionModulation there.
  Rgb Le(float cosFront) const { return emittedRadiance(radiance, twoSided, cosFront); }
  /// The barycentrics (b1, b2) of a point uniformly distributed by area for u ∈ [0, 1)²
  /// (density 1/area), and that point (p0 + b1·edge1 + b2·edge2).
  Vec2 barycentricsAt(Vec2 u) const;
  Vec3 pointAt(Vec2 b) const { return p0 + b.x * edge1 + b.y * edge2; }
  /// Exitant flux of a Lambertian emitter of the triangle's mean Le, π·A·Y(Le·meanModulation)
  /// (×2 when two-sided): with a texture, its textured power.
  float power() const { return kPi * area * luminance(radiance * meanModulation) * (twoSided ? 2.0f : 1.0f); }
};

/// Every non-degenerate triangle of an emissive material, mesh by mesh in triangle order.
std::vector<EmissiveTriangle> emissiveTriangles(const Scene& scene);

/// The mean of emissionModulation (scene.h) over triangle `triangle` of mesh `mesh` (its
/// material has an emission texture), by the midpoint rule on a regular subdivision: the
/// triangle cut into n² congruent triangles (n per edge in barycentric coordinates), the
/// texture read at each one's centroid, n = clamp(⌈2·√(texels under the triangle)⌉, 4, 128)
/// so that every texel under it gets about four reads. A triangle whose every read is black
/// is tested exactly (Texture::maxOver its uv bounding box): black there, the mean is 0 (the
/// triangle emits nothing anywhere, and the light sampler never picks it); otherwise it is
/// that maximum / n², one read's worth, so that the light sampler keeps it with a small
/// probability — any positive weight is unbiased.
Rgb meanEmissionModulation(const Scene& scene, uint32_t mesh, uint32_t triangle);

/// Everything that arrives from infinity as one light: a constant radiance plus an optional
/// map (exactly what scene.h's Environment holds). radiance(dir) = constant + map(dir).
/// sample() is a one-sample mixture: the map's importance sampling (env.h EnvironmentMap) with
/// probability P_map / (P_map + P_const) and uniform sphere sampling otherwise, P = ∫ Y(L) dω
/// of each part. pdf() is the mixture density (per solid angle), and sample() returns pdf() of
/// the direction it chose, so MIS weights built from either agree. Cheap to copy (shared map).
class EnvironmentLight {
 public:
  EnvironmentLight() = default;
  EnvironmentLight(const Rgb& constant, std::shared_ptr<const EnvironmentMap> map);

  bool isBlack() const { return !map_ && isBlackConstant_; }
  /// Le arriving from unit world direction `dir`.
  Rgb radiance(const Vec3& dir) const { return map_ ? constant_ + map_->radiance(dir) : constant_; }
  EnvironmentSample sample(Vec2 u) const;
  float pdf(const Vec3& dir) const;
  /// ∫ Y(L) dω over the sphere (luminance-weighted, W·m⁻²). The power an environment
  /// delivers into a scene bounded by a sphere of radius R is at most π R² times this.
  double integratedLuminance() const { return integratedLuminance_; }
  /// π R²·∫ Y(L) dω (= 4π·πR²·Y(Le) for a constant one, as pbrt-v4's UniformInfiniteLight::Phi).
  double power(float sceneRadius) const { return kPiD * double(sceneRadius) * double(sceneRadius) * integratedLuminance_; }
  float mapProbability() const { return mapProbability_; }

 private:
  Rgb constant_{0.0f};
  bool isBlackConstant_ = true;
  std::shared_ptr<const EnvironmentMap> map_;
  float mapProbability_ = 0.0f;
  double integratedLuminance_ = 0.0;
};

}  // namespace pl
