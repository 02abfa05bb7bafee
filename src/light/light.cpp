// The light sampler and shadow rays (see light.h).
#include "light/light.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "accel/accel.h"
#include "bsdf/bsdf.h"

namespace pl {

namespace {
/// Light-selection weights only need to be positive and finite: clamp absurdly bright
/// emitters (whose estimated power overflows float) to the largest float instead of letting
/// an infinity turn the whole distribution into NaNs.
float selectionWeight(float power) { return std::min(power, std::numeric_limits<float>::max()); }
}  // namespace

// ---- Shadow rays -------------------------------------------------------------------------

Vec3 emitterShadowTarget(const Vec3& point, const Vec3& normal, const Vec3& wi) {
  return offsetRayOrigin(point, normal, -wi);
}

std::optional<Ray> shadowRayTo(const Vec3& origin, const Vec3& target) {
  const Vec3 toTarget = target - origin;
  const float distance = glm::length(toTarget);
  if (!(distance > 0.0f)) return std::nullopt;
  return Ray{origin, toTarget / distance, 0.0f, distance};
}

std::optional<Ray> shadowRayTowards(const Vec3& origin, const IncidentLight& light) {
  return std::isfinite(light.distance) ? shadowRayTo(origin, light.target)
                                       : std::optional<Ray>(Ray{origin, light.wi, 0.0f, kInfinity});
}

ShadowRays::ShadowRays(const Scene& scene, const Accel& accel)
    : scene_(scene), accel_(accel), hasThinGlass_(scene.hasThinGlass()) {}

Rgb ShadowRays::transmittance(Ray ray, uint64_t& rays) const {
  ++rays;
  if (!hasThinGlass_) return accel_.occluded(ray) ? Rgb(0.0f) : Rgb(1.0f);
  Rgb transmittance(1.0f);
  const Vec3 start = ray.origin;
  const float tEnd = ray.tMax;
  for (;;) {
    RayHit hit;
    if (!accel_.intersect(ray, hit)) return transmittance;
    const SurfaceHit surface = surfaceAt(scene_, hit.mesh, hit.triangle, hit.barycentrics);
    const auto* sheet = std::get_if<DielectricBsdf>(&scene_.materials[surface.material].bsdf);
    if (!sheet || !sheet->thin) return Rgb(0.0f);
    Rgb reflectance, straight;
    thinSheetReflectanceTransmittance(*sheet, glm::dot(surface.shadingNormal, ray.direction), reflectance, straight);
    transmittance *= straight;
    if (isBlack(transmittance)) return transmittance;
    // Continue from just past the sheet; the remaining length is measured from the start.
    ray.origin = offsetRayOrigin(surface.position, surface.geometricNormal, ray.direction);
    ray.tMin = 0.0f;
    ray.tMax = std::isfinite(tEnd) ? tEnd - glm::dot(ray.origin - start, ray.direction) : tEnd;
    if (!(ray.tMax > 0.0f)) return transmittance;
    ++rays;
  }
}

// ---- The light sampler -------------------------------------------------------------------

LightSampler::LightSampler(const Scene& scene) : scene_(&scene) {
  environment_ = EnvironmentLight(scene.environment.constant, scene.environment.map);
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const float sceneRadius = std::max(0.5f * glm::length(hi - lo), 1e-6f);

  std::vector<float> weights, triangleWeights, sceneLightWeights;
  uint32_t base = 0;
  for (const Mesh& mesh : scene.meshes) {
    meshTriangleBase_.push_back(base);
    base += static_cast<uint32_t>(mesh.triangles.size());
  }
  entryOfTriangle_.assign(base, -1);
  for (const EmissiveTriangle& e : emissiveTriangles(scene)) {
    const float power = e.power();
    if (!(power > 0.0f)) continue;
    entryOfTriangle_[meshTriangleBase_[e.mesh] + e.triangle] = static_cast<int32_t>(entries_.size());
    entries_.push_back({Kind::Triangle, static_cast<uint32_t>(triangles_.size())});
    triangles_.push_back(e);
    weights.push_back(selectionWeight(power));
    triangleWeights.push_back(selectionWeight(power));
  }

  for (const Light& light : scene.lights) {
    const float power = lightPower(light, sceneRadius);
    if (!(power > 0.0f)) continue;
    if (std::holds_alternative<SphereLight>(light)) sphereEntries_.push_back(static_cast<uint32_t>(entries_.size()));
    entries_.push_back({Kind::SceneLight, static_cast<uint32_t>(sceneLights_.size())});
    sceneLights_.push_back(light);
    weights.push_back(selectionWeight(power));
    sceneLightWeights.push_back(selectionWeight(power));
  }

  if (!environment_.isBlack()) {
    const auto power = static_cast<float>(environment_.power(sceneRadius));
    if (power > 0.0f) {
      environmentEntry_ = static_cast<int32_t>(entries_.size());
      entries_.push_back({Kind::Environment, 0});
      weights.push_back(selectionWeight(power));
    }
  }
  if (!weights.empty()) all_ = Distribution1D(weights);
  if (!sceneLightWeights.empty()) sceneLightDistribution_ = Distribution1D(sceneLightWeights);
  if (!triangleWeights.empty()) triangleDistribution_ = Distribution1D(triangleWeights);

  // Area density of sampleEmitterPoint: P(triangle)/A = (π·A·Y·s/Σ)/A = π·Y·s/Σ with Y the
  // luminance of the triangle's mean Le (s = 2 when two-sided): the same for every triangle of
  // an untextured material. Σ is in double, as the distribution's.
  areaPdf_.assign(triangles_.size(), 0.0f);
  if (triangleDistribution_.total() > 0.0)
    for (size_t t = 0; t < triangles_.size(); ++t) {
      const EmissiveTriangle& e = triangles_[t];
      const double power = kPiD * luminance(e.radiance * e.meanModulation) * (e.twoSided ? 2.0 : 1.0);
      areaPdf_[t] = power > 0.0 ? static_cast<float>(power / triangleDistribution_.total()) : 0.0f;
    }
}

Rgb LightSampler::emitterModulation(const EmissiveTriangle& e, Vec2 barycentrics) const {
  if (!e.textured) return Rgb(1.0f);
  return emissionModulation(*scene_, scene_->materials[e.material], e.mesh, e.triangle, barycentrics);
}

std::optional<LightSample> LightSampler::sample(const Vec3& position, Vec2 u, bool nextEventOnly) const {
  const Distribution1D& distribution = nextEventOnly ? sceneLightDistribution_ : all_;
  if (distribution.size() == 0) return std::nullopt;
  float remapped = 0.0f;
  const size_t chosen = distribution.sample(u.x, &remapped);
  const float selectProbability = distribution.probability(chosen);
  if (!(selectProbability > 0.0f)) return std::nullopt;
  const Entry entry = nextEventOnly ? Entry{Kind::SceneLight, static_cast<uint32_t>(chosen)} : entries_[chosen];
  return sampleEntry(entry, selectProbability, position, Vec2(remapped, u.y));
}

std::optional<LightSample> LightSampler::sampleEntry(const Entry& entry, float selectProbability, const Vec3& position,
                                                     Vec2 u) const {
  LightSample s;
  switch (entry.kind) {
    case Kind::Triangle: {
      const EmissiveTriangle& e = triangles_[entry.index];
      const Vec2 b = e.barycentricsAt(u);
      const Vec3 point = e.pointAt(b);
      const Vec3 toLight = point - position;
      const float distanceSquared = glm::dot(toLight, toLight);
      if (!(distanceSquared > 0.0f)) return std::nullopt;
      s.wi = toLight / std::sqrt(distanceSquared);
      const float cosFront = -glm::dot(e.normal, s.wi);
      s.incident = e.Le(cosFront);
      if (e.textured) s.incident *= emitterModulation(e, b);
      const float cosLight = std::abs(cosFront);
      if (isBlack(s.incident) || !(cosLight > 0.0f)) return std::nullopt;  // the back of a one-sided emitter
      // Area density 1/A converted to solid angle at `position`: dA = r² dω / cos θlight.
      s.pdf = selectProbability * distanceSquared / (cosLight * e.area);
      s.target = emitterShadowTarget(point, e.normal, s.wi);
      break;
    }
    case Kind::Environment: {
      const EnvironmentSample e = environment_.sample(u);
      if (!(e.pdf > 0.0f)) return std::nullopt;
      s.wi = e.direction;
      s.pdf = selectProbability * e.pdf;
      s.incident = e.radiance;
      s.infinite = true;
      break;
    }
    case Kind::SceneLight: {
      const Light& light = sceneLights_[entry.index];
      const std::optional<IncidentLight> in = sampleLight(light, position, u);
      if (!in) return std::nullopt;
      s.wi = in->wi;
      s.incident = in->incident;
      s.pdf = selectProbability * in->pdf;  // a delta light's pdf is 1: the selection alone
      s.nextEventOnly = true;
      s.delta = isDeltaLight(light);
      s.infinite = isAtInfinity(light);
      s.target = in->target;
      break;
    }
  }
  if (!(s.pdf > 0.0f)) return std::nullopt;
  return s;
}

float LightSampler::emitterPdf(uint32_t mesh, uint32_t triangle, float distance, float cosLight) const {
  if (mesh >= meshTriangleBase_.size()) return 0.0f;
  const int32_t entry = entryOfTriangle_[meshTriangleBase_[mesh] + triangle];
  if (entry < 0 || !(cosLight > 0.0f)) return 0.0f;
  const EmissiveTriangle& e = triangles_[entries_[static_cast<size_t>(entry)].index];
  return all_.probability(static_cast<size_t>(entry)) * distance * distance / (cosLight * e.area);
}

std::optional<LightSampler::SphereCrossing> LightSampler::sphereLightAlong(const Ray& ray, const Vec3& receiver) const {
  std::optional<SphereCrossing> nearest;
  float nearestT = ray.tMax;
  for (const uint32_t entry : sphereEntries_) {
    const SphereLight& sphere = std::get<SphereLight>(sceneLights_[entries_[entry].index]);
    // The near root of |o + t·d − c|² = r²: t = b − √(b² − |c − o|² + r²), b = d·(c − o).
    const Vec3 toCentre = sphere.position - ray.origin;
    const float b = glm::dot(toCentre, ray.direction), r2 = sphere.radius * sphere.radius;
    const float discriminant = b * b - (glm::dot(toCentre, toCentre) - r2);
    if (!(discriminant >= 0.0f)) continue;
    const float t = b - std::sqrt(discriminant);
    if (!(t > ray.tMin && t < nearestT)) continue;  // behind, past the hit, or the origin inside it
    nearestT = t;
    nearest = SphereCrossing{sphere.intensity / (kPi * r2), all_.probability(entry) * sphere.pdf(receiver, ray.direction)};
  }
  return nearest;
}

float LightSampler::environmentPdf(const Vec3& dir) const {
  if (environmentEntry_ < 0) return 0.0f;
  return all_.probability(static_cast<size_t>(environmentEntry_)) * environment_.pdf(dir);
}

EmitterPoint LightSampler::sampleEmitterPoint(Vec2 u) const {
  float remapped = 0.0f;
  const size_t chosen = triangleDistribution_.sample(u.x, &remapped);
  const EmissiveTriangle& e = triangles_[chosen];
  const Vec2 b = e.barycentricsAt(Vec2(remapped, u.y));
  return {&e, e.pointAt(b), areaPdf_[chosen], emitterModulation(e, b)};
}

float LightSampler::emitterAreaPdf(uint32_t mesh, uint32_t triangle) const {
  if (mesh >= meshTriangleBase_.size()) return 0.0f;
  const int32_t entry = entryOfTriangle_[meshTriangleBase_[mesh] + triangle];
  return entry < 0 ? 0.0f : areaPdf_[entries_[static_cast<size_t>(entry)].index];
}

Rgb nextEventEstimate(const LightSampler& lights, const ShadowRays& shadows, const Vec3& position,
                      const ScatteringFrame& scattering, const Bsdf& bsdf, Vec2 u, NextEvent mode, uint64_t& rays) {
  const std::optional<LightSample> light = lights.sample(position, u, /*nextEventOnly=*/mode == NextEvent::SceneLightsOnly);
  if (!light || (mode == NextEvent::MisExceptDelta && light->delta)) return Rgb(0.0f);
  const Vec3& wi = light->wi;  // towards the light, world space
  const auto& [geometricNormal, frame, woLocal] = scattering;

  // A reflecting BSDF receives light only from above the geometric surface (this also stops
  // light leaking through when shading normals bend over the horizon); a transmitting one
  // from the side where the shading frame puts wi (both normals agree on it).
  const Vec3 wiLocal = frame.toLocal(wi);
  if (!usableSide(wi, wiLocal, geometricNormal, bsdf)) return Rgb(0.0f);
  const Rgb f = eval(bsdf, woLocal, wiLocal);
  const float cosIn = std::abs(wiLocal.z);
  if (isBlack(f) || !(cosIn > 0.0f)) return Rgb(0.0f);

  const Vec3 origin = offsetRayOrigin(position, geometricNormal, wi);
  const std::optional<Ray> shadow =
      light->infinite ? std::optional<Ray>(Ray{origin, wi, 0.0f, kInfinity}) : shadowRayTo(origin, light->target);
  if (!shadow) return Rgb(0.0f);
  const Rgb visible = shadows.transmittance(*shadow, rays);
  if (isBlack(visible)) return Rgb(0.0f);

  const Rgb unweighted = visible * f * cosIn * light->incident / light->pdf;
  const bool mis = mode == NextEvent::Mis || mode == NextEvent::MisExceptDelta;
  // Delta lights, which no BSDF-sampled ray finds, count in full; sphere lights, which the
  // callers of Mis and MisExceptDelta find along their BSDF samples (sphereLightAlong), are
  // MIS-weighted as emitters are.
  if (!mis || light->delta) return unweighted;
  return unweighted * powerHeuristic(light->pdf, pdf(bsdf, woLocal, wiLocal));
}

}  // namespace pl
