#pragma once
// Light: the one light sampler of plenoptic, used by the path tracer's next-event estimation
// and by the bake's first shot, and the one definition of a shadow ray (where it ends, and how
// much light passes along it).
//
// Emitters are the scene's emissive triangles (EmissiveTriangle, emitters.h), its lights
// (scene.lights: the Light types of lights.h) and the environment (EnvironmentLight).
//
// Light selection: one discrete distribution over every emitter, proportional to an estimate
// of its emitted power (luminance), each emitter's power() in emitters.h:
//   emissive triangle  π · A · Y(Le)            (×2 when two-sided; Le the triangle's mean,
//                      its emission texture's mean over it: meanEmissionModulation)
//   scene light        its power(R) (lights.h: 4π·Y(I) for a point light, π R²·Y(E) for a
//                      directional one, …)
//   environment        π R² · ∫ Y(Le) dω
// where R is the radius of the scene's bounding sphere. Any positive weights give an
// unbiased estimator; these make the variance small when emitters differ a lot. The bake,
// which samples emissive surfaces by area, uses the same weights restricted to the triangles.
//
// Textured emitters: a triangle is chosen ∝ its textured power and a point on it uniformly by
// area (density P(triangle)/A, exact whatever the texture does within it); the sample's
// radiance is the texel there (emissionModulation), so the estimate Le(x)·G/pdf is unbiased
// for any texture — the mean only steers the choice between triangles. A triangle whose
// texture is black under it has weight 0: it emits nothing, so nothing is missed.
//
// Sample numbers: the choice of emitter and the point on it come from ONE 2-D sample: u.x
// picks the emitter and is stretched back onto [0, 1) within its bin, then (u.x', u.y) picks
// the point. A stratified 2-D point set (the path tracer's sobol dimensions, the bake's
// per-tixel net) is thereby stratified over the union of all emitters — over a quad light made
// of two triangles as over one rectangle — instead of over each emitter separately.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/math.h"
#include "core/sampling.h"
#include "env/env.h"
#include "light/emitters.h"
#include "scene/scene.h"

namespace pl {

class Accel;

// ---- Shadow rays -------------------------------------------------------------------------

/// The point a shadow ray towards `point` on an emitter of geometric normal `normal` ends at:
/// moved off the emitter towards the receiver (wi points from the receiver to the emitter),
/// so the ray hits neither the emitter itself nor a coplanar surface right behind it.
Vec3 emitterShadowTarget(const Vec3& point, const Vec3& normal, const Vec3& wi);

/// The shadow ray from `origin` (already offset off the receiver) to `target`: unit direction,
/// tMin 0, tMax the distance. Nullopt when the two points coincide.
std::optional<Ray> shadowRayTo(const Vec3& origin, const Vec3& target);
/// The shadow ray from `origin` towards a scene light's sample (lights.h IncidentLight):
/// unbounded along wi for a light at infinity, else shadowRayTo its target.
std::optional<Ray> shadowRayTowards(const Vec3& origin, const IncidentLight& light);

/// Light travelling along shadow rays: the one place that decides what blocks them.
class ShadowRays {
 public:
  /// The scene and accel must outlive this object.
  ShadowRays(const Scene& scene, const Accel& accel);

  /// Whether some material is thin glass, which shadow rays pass (see transmittance). When
  /// false, transmittance is a plain occlusion test, and batches of rays may be tested with
  /// Accel::occludedCoherent instead.
  bool passesThinGlass() const { return hasThinGlass_; }

  /// The fraction of light that travels unscattered along `ray` (unit direction, from
  /// ray.tMin to ray.tMax): 0 when something blocks it, else the product of the straight
  /// transmittances T'(cos θ) of the thin glass sheets it crosses (bsdf.h
  /// thinSheetReflectanceTransmittance). Other glass blocks it: next-event estimation does not
  /// refract. `rays` is increased by the number of rays traced (one without thin glass).
  Rgb transmittance(Ray ray, uint64_t& rays) const;

 private:
  const Scene& scene_;
  const Accel& accel_;
  bool hasThinGlass_ = false;
};

// ---- The light sampler -------------------------------------------------------------------

/// One next-event sample of incident light at a receiver.
struct LightSample {
  Vec3 wi{0.0f};       ///< unit, from the receiver towards the light
  Rgb incident{0.0f};  ///< radiance Le (area lights, environment), or for delta lights the
                       ///< irradiance on a surface normal to wi (W·m⁻²)
  float pdf = 0.0f;    ///< solid-angle density of wi including the light's selection
                       ///< probability; for delta lights the selection probability alone
  /// A scene light (lights.h): no geometry, so a BSDF-sampled ray finds it only by asking
  /// (sphereLightAlong, sphere lights) or never (the delta lights).
  bool nextEventOnly = false;
  bool delta = false;  ///< a point, spot or directional light (lights.h isDeltaLight)
  bool infinite = false;  ///< a light at infinity or the environment: the shadow ray is unbounded
  Vec3 target{0.0f};      ///< finite lights: the point the shadow ray ends at
};

/// A point on an emissive triangle, sampled by area (the bake's first shot).
struct EmitterPoint {
  const EmissiveTriangle* triangle = nullptr;
  Vec3 point{0.0f};
  float areaPdf = 0.0f;  ///< density per unit area (m⁻²), selection included
  Rgb modulation{1.0f};  ///< the emission texture there: Le = triangle->Le(…) × modulation
};

class LightSampler {
 public:
  LightSampler() = default;
  /// The scene must outlive the sampler (textured emitters are read from it).
  explicit LightSampler(const Scene& scene);

  /// Emitters with positive power: emissive triangles + scene lights + environment.
  size_t lightCount() const { return entries_.size(); }
  size_t emissiveTriangleCount() const { return triangles_.size(); }
  const EnvironmentLight& environment() const { return environment_; }
  /// Whether the environment is one of the lights (it is lit).
  bool hasEnvironment() const { return environmentEntry_ >= 0; }

  /// Chooses a light with probability ∝ its power (only among the scene lights when
  /// nextEventOnly: the lights BSDF sampling cannot find) and a point or direction on it, for a
  /// receiver at `position`: u.x chooses the light (stretched, see the top of this file), the
  /// rest the point. Nullopt when nothing is sampled (no lights, the back of a one-sided
  /// emitter, outside a spot's cone, a zero density).
  std::optional<LightSample> sample(const Vec3& position, Vec2 u, bool nextEventOnly = false) const;

  /// The density sample() has for reaching emissive triangle `triangle` of mesh `mesh` from a
  /// receiver at `distance`, arriving at the emitter with |cos θlight| = cosLight (solid angle
  /// at the receiver: P(select) · r² / (cos θlight · A)). 0 when that triangle is no light.
  float emitterPdf(uint32_t mesh, uint32_t triangle, float distance, float cosLight) const;
  /// The density sample() has for direction `dir` (unit, towards the sky) on the environment.
  float environmentPdf(const Vec3& dir) const;

  /// A sphere light that `ray` (unit direction) enters between ray.tMin and ray.tMax.
  struct SphereCrossing {
    Rgb radiance{0.0f};  ///< its surface radiance Le = I/(π r²)
    float pdf = 0.0f;    ///< the density sample() has for ray.direction from `receiver`
  };
  /// The nearest sphere light along `ray` (sphere lights are no geometry: a caller that
  /// samples directions at `receiver` and follows them finds them this way), with the density
  /// sample() has for that direction at `receiver` (the scattering vertex the direction was
  /// sampled at; ray.origin unless a thin sheet was passed straight on the way). Nullopt when
  /// the ray enters none.
  std::optional<SphereCrossing> sphereLightAlong(const Ray& ray, const Vec3& receiver) const;
  bool hasSphereLights() const { return !sphereEntries_.empty(); }
  /// The emissive triangles' power, Σ π·A·Y(mean Le)·(2 if two-sided) (W, luminance).
  double emissiveTrianglePower() const { return triangleDistribution_.total(); }

  /// The tables sample(), emitterPdf(), environmentPdf() and sphereLightAlong() read, as they
  /// are (the GPU renderer uploads them: gpu/gpu_lights.h). Entries are in selection order:
  /// the emissive triangles, then the scene lights, then the environment.
  enum class Kind : uint8_t { Triangle, SceneLight, Environment };
  struct Entry {
    Kind kind;
    uint32_t index;  ///< into emitterTriangles() or sceneLights()
  };
  std::span<const Entry> entries() const { return entries_; }
  /// The selection over entries() (sample() without nextEventOnly).
  const Distribution1D& selection() const { return all_; }
  std::span<const EmissiveTriangle> emitterTriangles() const { return triangles_; }
  /// Those of scene.lights with positive power.
  std::span<const Light> sceneLights() const { return sceneLights_; }
  /// The entry of each triangle of the scene (numbered mesh by mesh, in order), or −1.
  std::span<const int32_t> entryOfTriangle() const { return entryOfTriangle_; }

  /// A point on the emissive triangles alone, chosen with probability ∝ their power and then
  /// uniformly by area (the bake's area-light shadow rays). Requires emissiveTriangleCount() > 0.
  EmitterPoint sampleEmitterPoint(Vec2 u) const;
  /// sampleEmitterPoint's area density on triangle `triangle` of mesh `mesh`: π·Y(mean
  /// Le)·(2 if two-sided) / Σ triangle power, the same on every triangle of an untextured
  /// material; 0 on a triangle that is no light.
  float emitterAreaPdf(uint32_t mesh, uint32_t triangle) const;

 private:
  std::optional<LightSample> sampleEntry(const Entry& entry, float selectProbability, const Vec3& position,
                                         Vec2 u) const;
  /// The emission texture at barycentrics b of e (1 when untextured).
  Rgb emitterModulation(const EmissiveTriangle& e, Vec2 barycentrics) const;

  const Scene* scene_ = nullptr;
  EnvironmentLight environment_;
  std::vector<EmissiveTriangle> triangles_;
  std::vector<Light> sceneLights_;  ///< those of scene.lights with positive power
  std::vector<Entry> entries_;
  Distribution1D all_;        ///< over entries_
  Distribution1D sceneLightDistribution_;  ///< over sceneLights_
  Distribution1D triangleDistribution_;  ///< over triangles_
  std::vector<uint32_t> meshTriangleBase_;  ///< first global triangle index of each mesh
  std::vector<int32_t> entryOfTriangle_;    ///< entry of each global triangle, or −1
  std::vector<float> areaPdf_;  ///< sampleEmitterPoint's area density, per triangles_ entry
  int32_t environmentEntry_ = -1;
  std::vector<uint32_t> sphereEntries_;  ///< the entries that are sphere lights
};

// ---- Next-event estimation ---------------------------------------------------------------

/// Which lights a next-event estimate samples, and how it weights them.
enum class NextEvent : uint8_t {
  /// Every light, MIS-weighted (power heuristic) against the BSDF's density where BSDF
  /// sampling could find the light too: emissive triangles, the environment and sphere lights
  /// (the caller finds them along its BSDF samples with LightSampler::sphereLightAlong); the
  /// delta lights in full (the path tracer's default strategy).
  Mis,
  /// Every light, full weight (the path tracer's light-only strategy).
  LightOnly,
  /// The scene lights alone, full weight (the BSDF-only strategy: the lights no BSDF-sampled
  /// ray finds).
  SceneLightsOnly,
  /// Every light but the delta ones, MIS-weighted, sphere lights too (a caller that follows
  /// the BSDF's sample finds them with LightSampler::sphereLightAlong): a sample that chooses a
  /// point, spot or directional light counts 0, for a caller that adds those another way (the
  /// light-field renderers at mirror-like lobes, lightfield/lookup.h MirrorLikeLights and
  /// PunctualHighlights).
  MisExceptDelta,
};

/// One next-event sample at a non-delta scattering vertex `position` (a ScatteringFrame and
/// its BSDF, scene.h): LightSampler::sample with the 2-D number u, the BSDF against it
/// (usableSide on both directions), a shadow ray (ShadowRays: thin glass passes, `rays` counts
/// them), weighted as `mode` says. Returns f·|cos θi|·Li·T/pdf × weight (W·sr⁻¹·m⁻²).
Rgb nextEventEstimate(const LightSampler& lights, const ShadowRays& shadows, const Vec3& position,
                      const ScatteringFrame& scattering, const Bsdf& bsdf, Vec2 u, NextEvent mode, uint64_t& rays);

}  // namespace pl
