// The reference path tracer (see trace.h for the conventions).
//
// Estimator. For a path x0 (camera) → x1 → x2 → ..., with throughput β_k = Π f·cos/pdf of
// the BSDF samples taken so far, the radiance is the sum over vertices x_k of
//   β_k · Le(x_k)                         emission found by the BSDF-sampled ray, weighted by
//                                         w_bsdf = p_bsdf² / (p_bsdf² + p_light²)
// + β_k · f · cos θi · Le / p_light        next-event estimation at x_k, weighted by
//                                         w_light = p_light² / (p_bsdf² + p_light²)
// (Veach's power heuristic, β = 2). Both pdfs are solid-angle densities at x_k of the same
// direction: p_light includes the probability of selecting that light. Delta lights (point,
// spot, directional) can only be reached by NEE (weight 1); delta BSDF bounces (mirrors) can
// only be followed by BSDF sampling, so emission seen right after one counts fully, as does
// emission seen by the camera ray.
//
// Light selection: one discrete distribution over every emitter, proportional to an estimate
// of its emitted power (luminance):
//   emissive triangle  π · A · Y(Le)            (×2 when two-sided): exitant flux of a
//                                                Lambertian emitter of radiance Le and area A
//   point light        4π · Y(I)
//   spot light         2π · (1 − (cos θinner + cos θouter)/2) · Y(I)   (pbrt's estimate)
//   directional light  π R² · Y(E)             flux through the scene's bounding disk
//   environment        π R² · ∫ Y(Le) dω        (= 4π·πR²·Y(Le) for a constant one, as pbrt-v4's
//                                                UniformInfiniteLight::Phi)
// where R is the radius of the scene's bounding sphere. Any positive weights give an
// unbiased estimator; these make the variance small when emitters differ a lot.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <variant>
#include <vector>

#include "accel/accel.h"
#include "bsdf/bsdf.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/sampler.h"
#include "core/sampling.h"
#include "scene/scene.h"
#include "trace/trace.h"

namespace pl {

const char* strategyName(TraceStrategy strategy) {
  switch (strategy) {
    case TraceStrategy::Mis: return "mis";
    case TraceStrategy::NeeOnly: return "nee";
    case TraceStrategy::BsdfOnly: return "bsdf";
  }
  return "?";
}

TraceStrategy parseStrategy(const std::string& name) {
  if (name == "mis") return TraceStrategy::Mis;
  if (name == "nee") return TraceStrategy::NeeOnly;
  if (name == "bsdf") return TraceStrategy::BsdfOnly;
  fail("unknown strategy '{}' (expected mis, nee or bsdf)", name);
}

namespace {

// The environment (constant + optional importance-sampled map) is env/env.h's
// EnvironmentLight: radiance(), sample() and pdf() are its only uses here, so a better
// environment sampler changes nothing in this file.

enum class LightKind : uint8_t { Triangle, Punctual, Environment };
struct LightEntry {
  LightKind kind;
  uint32_t index;  ///< into triangles_ or punctual_
};

/// Per-render counters, accumulated per tile and added atomically at the end of each tile.
struct Counters {
  uint64_t rays = 0;
};

/// The sampler dimensions of a path (core/sampler.h): the camera's film and lens positions,
/// then per bounce (scattering event) `depth` a block of kDimensionsPerBounce starting at
/// bounceDimension(depth): light selection (1-D), the point on the light (2-D), the BSDF
/// sample (2-D: lobe choice stretched into the direction) and Russian roulette (1-D). A
/// decision always uses the same dimension whatever the path did before it.
constexpr uint32_t kFilmDimension = 0, kLensDimension = 1, kFirstBounceDimension = 2;
constexpr uint32_t kDimensionsPerBounce = 4;
enum BounceDimension : uint32_t { kLightSelect = 0, kLightPoint = 1, kBsdfSample = 2, kRoulette = 3 };
uint32_t bounceDimension(int depth, BounceDimension which) {
  return kFirstBounceDimension + kDimensionsPerBounce * uint32_t(depth) + which;
}

/// Running sums of one pixel's samples in double precision.
struct PixelAccumulator {
  DVec3 sum{0.0}, sumSquares{0.0};
  uint64_t samples = 0, nanSamples = 0;
  uint64_t firstNanSample = 0;

  void add(const Rgb& value, uint64_t sampleIndex) {
    if (!isFinite(value)) {
      if (nanSamples++ == 0) firstNanSample = sampleIndex;
      return;
    }
    const DVec3 v(value);
    sum += v;
    sumSquares += v * v;
    ++samples;
  }
  RadianceEstimate estimate() const {
    RadianceEstimate e;
    e.samples = samples;
    e.nanSamples = nanSamples;
    if (samples == 0) return e;
    const double n = static_cast<double>(samples);
    const DVec3 mean = sum / n;
    e.mean = Rgb(mean);
    if (samples > 1) {
      // Unbiased sample variance s² = (Σx² − n·mean²)/(n − 1); variance of the mean = s²/n.
      const DVec3 s2 = glm::max(DVec3(0.0), (sumSquares - n * mean * mean) / (n - 1.0));
      e.varianceOfMean = Rgb(s2 / n);
    }
    return e;
  }
};

/// Light-selection weights only need to be positive and finite: clamp absurdly bright
/// emitters (whose estimated power overflows float) to the largest float instead of letting
/// an infinity turn the whole distribution into NaNs.
float selectionWeight(float power) { return std::min(power, std::numeric_limits<float>::max()); }

}  // namespace

// -----------------------------------------------------------------------------------------
struct PathTracer::Impl {
  const Scene& scene;
  const Accel& accel;
  EnvironmentLight environment;
  std::vector<EmissiveTriangle> triangles;
  std::vector<PunctualLight> punctual;
  std::vector<LightEntry> entries;
  Distribution1D allLights;          ///< over entries
  Distribution1D punctualLights;     ///< over punctual (used by the Bsdf strategy)
  std::vector<uint32_t> meshTriangleBase;  ///< first global triangle index of each mesh
  std::vector<int32_t> entryOfTriangle;    ///< light entry of each global triangle, or −1
  int32_t environmentEntry = -1;
  bool hasThinGlass = false;  ///< shadow rays pass thin glass sheets (shadowTransmittance)

  Impl(const Scene& s, const Accel& a);

  float selectionProbability(int32_t entry) const {
    return entry >= 0 ? allLights.probability(static_cast<size_t>(entry)) : 0.0f;
  }

  bool occluded(const Vec3& origin, const Vec3& direction, float tMax, Counters& counters) const {
    ++counters.rays;
    Ray shadow;
    shadow.origin = origin;
    shadow.direction = direction;
    shadow.tMin = 0.0f;
    shadow.tMax = tMax;
    return accel.occluded(shadow);
  }

  /// The fraction of light that travels unscattered from origin along `direction` for tMax:
  /// 0 when something blocks it, else the product of the straight transmittances T' of the
  /// thin glass sheets it crosses (bsdf.h). Other glass blocks it (next-event estimation does
  /// not refract). Scenes without thin glass take one occlusion ray.
  Rgb shadowTransmittance(Vec3 origin, const Vec3& direction, float tMax, Counters& counters) const {
    if (!hasThinGlass) return occluded(origin, direction, tMax, counters) ? Rgb(0.0f) : Rgb(1.0f);
    Rgb transmittance(1.0f);
    for (;;) {
      ++counters.rays;
      Ray shadow{origin, direction, 0.0f, tMax};
      RayHit hit;
      if (!accel.intersect(shadow, hit)) return transmittance;
      const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
      const auto* sheet = std::get_if<DielectricBsdf>(&scene.materials[surface.material].bsdf);
      if (!sheet || !sheet->thin) return Rgb(0.0f);
      Rgb reflectance, straight;
      thinSheetReflectanceTransmittance(*sheet, glm::dot(surface.shadingNormal, direction), reflectance, straight);
      transmittance *= straight;
      if (isBlack(transmittance)) return transmittance;
      origin = offsetRayOrigin(surface.position, surface.geometricNormal, direction);
      tMax = std::isfinite(tMax) ? tMax - glm::dot(origin - shadow.origin, direction) : tMax;
      if (!(tMax > 0.0f)) return transmittance;
    }
  }

  Rgb directLight(const Vec3& position, const Vec3& geometricNormal, const Frame& frame, const Vec3& woLocal,
                  const Bsdf& bsdf, const TraceSettings& settings, int depth, Sampler& sampler,
                  Counters& counters) const;
  Rgb radiance(Ray ray, Sampler& sampler, const TraceSettings& settings, Counters& counters) const;
  void tracePixel(const Camera& camera, const ZSobolLayout& layout, const TraceSettings& settings, int x, int y,
                  PixelAccumulator& acc, Counters& counters) const;
};

PathTracer::Impl::Impl(const Scene& s, const Accel& a) : scene(s), accel(a) {
  environment = EnvironmentLight(scene.environment.constant, scene.environment.map);
  for (const Material& m : scene.materials)
    if (const auto* glass = std::get_if<DielectricBsdf>(&m.bsdf); glass && glass->thin) hasThinGlass = true;
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const float sceneRadius = std::max(0.5f * glm::length(hi - lo), 1e-6f);

  std::vector<float> weights;
  uint32_t base = 0;
  for (const Mesh& mesh : scene.meshes) {
    meshTriangleBase.push_back(base);
    base += static_cast<uint32_t>(mesh.triangles.size());
  }
  entryOfTriangle.assign(base, -1);
  for (const EmissiveTriangle& e : emissiveTriangles(scene)) {
    const float power = kPi * e.area * luminance(e.radiance) * (e.twoSided ? 2.0f : 1.0f);
    if (!(power > 0.0f)) continue;
    entryOfTriangle[meshTriangleBase[e.mesh] + e.triangle] = static_cast<int32_t>(entries.size());
    entries.push_back({LightKind::Triangle, static_cast<uint32_t>(triangles.size())});
    triangles.push_back(e);
    weights.push_back(selectionWeight(power));
  }

  std::vector<float> punctualWeights;
  for (const Light& light : scene.lights) {
    const PunctualLight p = PunctualLight::from(light);
    float power = 0.0f;
    switch (p.kind) {
      case PunctualLight::Kind::Point: power = 4.0f * kPi * luminance(p.intensity); break;
      case PunctualLight::Kind::Spot:
        power = 2.0f * kPi * (1.0f - 0.5f * (p.cosInner + p.cosOuter)) * luminance(p.intensity);
        break;
      case PunctualLight::Kind::Directional: power = kPi * sceneRadius * sceneRadius * luminance(p.intensity); break;
    }
    if (!(power > 0.0f)) continue;
    entries.push_back({LightKind::Punctual, static_cast<uint32_t>(punctual.size())});
    punctual.push_back(p);
    weights.push_back(selectionWeight(power));
    punctualWeights.push_back(selectionWeight(power));
  }

  if (!environment.isBlack()) {
    const float power =
        static_cast<float>(kPiD * double(sceneRadius) * double(sceneRadius) * environment.integratedLuminance());
    if (power > 0.0f) {
      environmentEntry = static_cast<int32_t>(entries.size());
      entries.push_back({LightKind::Environment, 0});
      weights.push_back(selectionWeight(power));
    }
  }
  if (!weights.empty()) allLights = Distribution1D(weights);
  if (!punctualWeights.empty()) punctualLights = Distribution1D(punctualWeights);
}

// Next-event estimation at a non-delta vertex: one light sample, MIS-weighted against the
// BSDF's density when the light could also be hit by BSDF sampling.
Rgb PathTracer::Impl::directLight(const Vec3& position, const Vec3& geometricNormal, const Frame& frame,
                                  const Vec3& woLocal, const Bsdf& bsdf, const TraceSettings& settings, int depth,
                                  Sampler& sampler, Counters& counters) const {
  // Always draw the same three numbers, from this bounce's light dimensions, whichever light
  // is picked: the independent stream's layout then does not depend on the choice either.
  sampler.setDimension(bounceDimension(depth, kLightSelect));
  const float uSelect = sampler.get1D();
  sampler.setDimension(bounceDimension(depth, kLightPoint));
  const Vec2 u = sampler.get2D();

  const bool punctualOnly = settings.strategy == TraceStrategy::BsdfOnly;
  const Distribution1D& distribution = punctualOnly ? punctualLights : allLights;
  if (distribution.size() == 0) return Rgb(0.0f);
  const size_t chosen = distribution.sample(uSelect);
  const float selectProbability = distribution.probability(chosen);
  if (!(selectProbability > 0.0f)) return Rgb(0.0f);
  const LightEntry entry = punctualOnly ? LightEntry{LightKind::Punctual, static_cast<uint32_t>(chosen)}
                                        : entries[chosen];

  Vec3 wi;                  // towards the light, world space
  Rgb incident(0.0f);       // radiance (area/environment) or irradiance-like term (punctual)
  float lightPdf = 0.0f;    // solid angle density including selection (area/environment)
  bool isDeltaLight = false;
  Vec3 shadowTarget(0.0f);  // finite lights: the point the shadow ray must reach
  bool infinite = false;

  switch (entry.kind) {
    case LightKind::Triangle: {
      const EmissiveTriangle& e = triangles[entry.index];
      const Vec2 b = sampleUniformTriangle(u);
      const Vec3 point = e.p0 + b.x * e.edge1 + b.y * e.edge2;
      const Vec3 toLight = point - position;
      const float distanceSquared = glm::dot(toLight, toLight);
      if (!(distanceSquared > 0.0f)) return Rgb(0.0f);
      wi = toLight / std::sqrt(distanceSquared);
      float cosLight = -glm::dot(e.normal, wi);
      if (e.twoSided) cosLight = std::abs(cosLight);
      if (!(cosLight > 0.0f)) return Rgb(0.0f);  // the back of a one-sided emitter
      // Area density 1/A converted to solid angle at `position`: dA = r² dω / cos θlight.
      lightPdf = selectProbability * distanceSquared / (cosLight * e.area);
      incident = e.radiance;
      // Offset the target off the emitter towards the shading point so the shadow ray does
      // not hit the emitter itself (nor a coplanar ceiling right behind it).
      shadowTarget = offsetRayOrigin(point, e.normal, -wi);
      break;
    }
    case LightKind::Environment: {
      const EnvironmentSample e = environment.sample(u);
      if (!(e.pdf > 0.0f)) return Rgb(0.0f);
      wi = e.direction;
      lightPdf = selectProbability * e.pdf;
      incident = e.radiance;
      infinite = true;
      break;
    }
    case LightKind::Punctual: {
      const PunctualLight& p = punctual[entry.index];
      isDeltaLight = true;
      lightPdf = selectProbability;  // a discrete choice; the direction is fixed
      float distance;
      if (!p.incidentAt(position, wi, distance, incident)) return Rgb(0.0f);  // irradiance normal to wi
      infinite = p.kind == PunctualLight::Kind::Directional;
      shadowTarget = p.position;
      break;
    }
  }

  // A reflecting BSDF receives light only from above the geometric surface (this also stops
  // light leaking through when shading normals bend over the horizon); a transmitting one
  // from the side where the shading frame puts wi (both normals agree on it).
  const Vec3 wiLocal = frame.toLocal(wi);
  if (!usableSide(wi, wiLocal, geometricNormal, bsdf)) return Rgb(0.0f);
  const Rgb f = eval(bsdf, woLocal, wiLocal);
  const float cosIn = std::abs(wiLocal.z);
  if (isBlack(f) || !(cosIn > 0.0f)) return Rgb(0.0f);

  const Vec3 origin = offsetRayOrigin(position, geometricNormal, wi);
  Rgb visible;
  if (infinite) {
    visible = shadowTransmittance(origin, wi, kInfinity, counters);
  } else {
    const Vec3 toTarget = shadowTarget - origin;
    const float distance = glm::length(toTarget);
    if (!(distance > 0.0f)) return Rgb(0.0f);
    visible = shadowTransmittance(origin, toTarget / distance, distance, counters);
  }
  if (isBlack(visible)) return Rgb(0.0f);

  const Rgb unweighted = visible * f * cosIn * incident / lightPdf;
  if (isDeltaLight || settings.strategy != TraceStrategy::Mis) return unweighted;
  return unweighted * powerHeuristic(lightPdf, pdf(bsdf, woLocal, wiLocal));
}

Rgb PathTracer::Impl::radiance(Ray ray, Sampler& sampler, const TraceSettings& settings, Counters& counters) const {
  Rgb result(0.0f);
  Rgb throughput(1.0f);
  // Whether emission found by the current ray counts with full weight: true for the camera
  // ray, after a delta bounce, and always with the Bsdf strategy.
  bool countEmissionFully = true;
  float previousBsdfPdf = 0.0f;  // solid-angle density with which the current ray was sampled
  // Distance travelled since the vertex that sampled the current direction: straight passes
  // through thin glass keep the direction (and that vertex's MIS weights, since next-event
  // estimation there sees through the sheets too), so an emitter's density is measured from it.
  float distanceBefore = 0.0f;
  // Product of η'² over the refractions so far: the throughput's radiance scaling across
  // interfaces (bsdf.h), which Russian roulette must not mistake for absorption (pbrt-v4's
  // etaScale). After entering glass the throughput is 1/η² of what it will be on leaving.
  float etaScale = 1.0f;
  const bool useMis = settings.strategy == TraceStrategy::Mis;
  const bool bsdfOnly = settings.strategy == TraceStrategy::BsdfOnly;

  const int maxDepth = settings.maxDepth == kUnboundedDepth ? kSafetyDepth : settings.maxDepth;
  for (int depth = 0;; ++depth) {
    RayHit hit;
    ++counters.rays;
    if (!accel.intersect(ray, hit)) {
      if (environmentEntry >= 0) {
        const Rgb le = environment.radiance(ray.direction);
        if (countEmissionFully) {
          result += throughput * le;
        } else if (useMis) {
          const float lightPdf = selectionProbability(environmentEntry) * environment.pdf(ray.direction);
          result += throughput * le * powerHeuristic(previousBsdfPdf, lightPdf);
        }
      }
      break;
    }

    const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
    const Material& material = scene.materials[surface.material];
    const Vec3 wo = -ray.direction;
    const float cosWoGeometric = glm::dot(surface.geometricNormal, wo);
    // Beer–Lambert: a segment that ends on the inside (back) of a dielectric ran through its
    // interior (the front side of a closed mesh is its outside), losing exp(−σa t).
    if (const auto* glass = std::get_if<DielectricBsdf>(&material.bsdf); glass && cosWoGeometric < 0.0f) {
      if (!isBlack(glass->absorption)) throughput *= glm::exp(-glass->absorption * hit.t);
    }

    if (!isBlack(emittedRadiance(material, cosWoGeometric))) {  // the emission sidedness rule (scene.h)
      if (countEmissionFully) {
        result += throughput * material.emission;
      } else if (useMis) {
        const int32_t entry = entryOfTriangle[meshTriangleBase[hit.mesh] + hit.triangle];
        if (entry >= 0) {
          const EmissiveTriangle& e = triangles[entries[static_cast<size_t>(entry)].index];
          // The density NEE would have had for this point, in solid angle at the previous
          // vertex: P(select) · (1/A) · t² / |cos θlight| (t from that vertex, through any
          // thin glass crossed straight).
          const float cosLight = std::abs(cosWoGeometric);
          const float distance = distanceBefore + hit.t;
          const float lightPdf = cosLight > 0.0f
                                     ? selectionProbability(entry) * distance * distance / (cosLight * e.area)
                                     : 0.0f;
          result += throughput * material.emission * powerHeuristic(previousBsdfPdf, lightPdf);
        }
      }
    }
    if (depth >= maxDepth) break;

    // The sidedness rule (scene.h): reflecting BSDFs two-sided, transmitting ones unturned.
    const Bsdf bsdf = bsdfAt(scene, surface);
    const auto [geometricNormal, frame, woLocal] = scatteringFrame(surface, wo, bsdf);
    if (!usableSide(wo, woLocal, geometricNormal, bsdf)) break;

    if (!isDelta(bsdf)) {
      result += throughput *
                directLight(surface.position, geometricNormal, frame, woLocal, bsdf, settings, depth, sampler, counters);
    }

    sampler.setDimension(bounceDimension(depth, kBsdfSample));
    const Vec2 u = sampler.get2D();
    const std::optional<BsdfSample> s = sample(bsdf, woLocal, u);
    if (!s) break;
    const Vec3 wi = frame.toWorld(s->wi);
    if (!usableSide(wi, s->wi, geometricNormal, bsdf)) break;  // see directLight
    throughput *= s->weight;
    if (isBlack(throughput)) break;
    if (const auto* glass = std::get_if<DielectricBsdf>(&bsdf); glass && !glass->thin && woLocal.z * s->wi.z < 0.0f) {
      const float etap = woLocal.z > 0.0f ? glass->ior : 1.0f / glass->ior;  // η(wi side) / η(wo side)
      etaScale *= etap * etap;
    }
    const auto* sheet = std::get_if<DielectricBsdf>(&bsdf);
    if (sheet && sheet->thin && woLocal.z * s->wi.z < 0.0f) {
      distanceBefore += hit.t;  // straight through: the previous vertex's sample continues
    } else {
      countEmissionFully = s->delta || bsdfOnly;
      previousBsdfPdf = s->pdf;
      distanceBefore = 0.0f;
    }
    ray.origin = offsetRayOrigin(surface.position, geometricNormal, wi);
    ray.direction = wi;
    ray.tMin = 0.0f;
    ray.tMax = kInfinity;

    // Russian roulette (unbiased): continue with probability q, divide the throughput by q.
    // q < 1 always (kRouletteMaxContinue), so every path ends with probability 1 without a
    // depth cap; written as !(u < q) so that a NaN throughput ends the path too.
    if (depth + 1 >= settings.rouletteDepth) {
      // etaScale undoes the η² radiance scaling of refractions (as pbrt-v4 does), so a path
      // that entered glass is not ended more or less often than one that left it.
      const float q = std::min(maxComponent(throughput) * etaScale, kRouletteMaxContinue);
      sampler.setDimension(bounceDimension(depth, kRoulette));
      if (!(sampler.get1D() < q)) break;
      throughput /= q;
    }
  }
  return result;
}

void PathTracer::Impl::tracePixel(const Camera& camera, const ZSobolLayout& layout, const TraceSettings& settings,
                                  int x, int y, PixelAccumulator& acc, Counters& counters) const {
  const uint64_t pixelIndex = static_cast<uint64_t>(y) * static_cast<uint64_t>(camera.width()) + static_cast<uint64_t>(x);
  for (int i = 0; i < settings.spp; ++i) {
    Sampler sampler =
        Sampler::make(settings.sampler, layout, pixelIndex, x, y, static_cast<uint64_t>(i), settings.seed);
    sampler.setDimension(kFilmDimension);
    const Vec2 film = Vec2(static_cast<float>(x), static_cast<float>(y)) + sampler.get2D();
    sampler.setDimension(kLensDimension);
    const Vec2 lens = sampler.get2D();
    const Camera::Sample cameraSample = camera.generateRay(film, lens);
    Rgb value(0.0f);
    if (cameraSample.weight > 0.0f)
      value = cameraSample.weight * radiance(cameraSample.ray, sampler, settings, counters);
    acc.add(value, static_cast<uint64_t>(i));
  }
}

// -----------------------------------------------------------------------------------------
PathTracer::PathTracer(const Scene& scene, const Accel& accel) : impl_(std::make_unique<Impl>(scene, accel)) {}
PathTracer::~PathTracer() = default;

size_t PathTracer::emissiveTriangleCount() const { return impl_->triangles.size(); }
size_t PathTracer::lightCount() const { return impl_->entries.size(); }

namespace {
void checkSettings(const TraceSettings& settings) {
  if (settings.spp < 1) fail("samples per pixel must be at least 1 (got {})", settings.spp);
  if (settings.maxDepth < 0 && settings.maxDepth != kUnboundedDepth)
    fail("maximum depth must be at least 0, or {} for no cap (got {})", kUnboundedDepth, settings.maxDepth);
  if (settings.tileSize < 1) fail("tile size must be at least 1 (got {})", settings.tileSize);
}
}  // namespace

TraceResult PathTracer::render(const Camera& camera, const TraceSettings& settings) const {
  checkSettings(settings);
  const int width = camera.width(), height = camera.height();
  if (width < 1 || height < 1) fail("image size {}x{} is empty", width, height);

  TraceResult result;
  result.radiance = Image(width, height);
  result.variance = Image(width, height);

  const ZSobolLayout layout(width, height, settings.spp, settings.seed);
  const int tile = settings.tileSize;
  const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
  const uint64_t tileCount = static_cast<uint64_t>(tilesX) * static_cast<uint64_t>(tilesY);

  std::atomic<uint64_t> totalRays{0}, totalNans{0};
  std::mutex nanMutex;
  uint64_t firstNanPixel = ~0ull, firstNanSample = 0;

  std::optional<Progress> progress;
  if (settings.showProgress) progress.emplace("tracing", tileCount);
  const auto start = std::chrono::steady_clock::now();

  parallelForRange(tileCount, 1, [&](uint64_t begin, uint64_t end) {
    for (uint64_t t = begin; t < end; ++t) {
      const int x0 = static_cast<int>(t % static_cast<uint64_t>(tilesX)) * tile;
      const int y0 = static_cast<int>(t / static_cast<uint64_t>(tilesX)) * tile;
      const int x1 = std::min(x0 + tile, width), y1 = std::min(y0 + tile, height);
      Counters counters;
      uint64_t nans = 0;
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          PixelAccumulator acc;
          impl_->tracePixel(camera, layout, settings, x, y, acc, counters);
          const RadianceEstimate e = acc.estimate();
          result.radiance.at(x, y) = e.mean;
          result.variance.at(x, y) = e.varianceOfMean;
          if (acc.nanSamples > 0) {
            nans += acc.nanSamples;
            // Keep the first offending pixel in scan order, so the report does not depend
            // on the thread schedule.
            const uint64_t pixel = static_cast<uint64_t>(y) * static_cast<uint64_t>(width) + static_cast<uint64_t>(x);
            std::lock_guard lock(nanMutex);
            if (pixel < firstNanPixel) {
              firstNanPixel = pixel;
              firstNanSample = acc.firstNanSample;
            }
          }
        }
      }
      totalRays += counters.rays;
      totalNans += nans;
      if (progress) progress->advance();
    }
  });
  if (progress) progress->finish();

  TraceStats& stats = result.stats;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats.paths = static_cast<uint64_t>(width) * static_cast<uint64_t>(height) * static_cast<uint64_t>(settings.spp);
  stats.rays = totalRays.load();
  stats.nanSamples = totalNans.load();
  if (stats.nanSamples > 0) {
    stats.firstNanX = static_cast<int>(firstNanPixel % static_cast<uint64_t>(width));
    stats.firstNanY = static_cast<int>(firstNanPixel / static_cast<uint64_t>(width));
    stats.firstNanSample = firstNanSample;
  }
  return result;
}

RadianceEstimate PathTracer::renderPixel(const Camera& camera, const TraceSettings& settings, int x, int y) const {
  checkSettings(settings);
  if (x < 0 || y < 0 || x >= camera.width() || y >= camera.height())
    fail("pixel ({}, {}) is outside the {}x{} image", x, y, camera.width(), camera.height());
  PixelAccumulator acc;
  Counters counters;
  impl_->tracePixel(camera, ZSobolLayout(camera.width(), camera.height(), settings.spp, settings.seed), settings, x, y,
                    acc, counters);
  return acc.estimate();
}

RadianceEstimate PathTracer::estimateRadiance(const Ray& ray, const TraceSettings& settings, uint64_t key) const {
  checkSettings(settings);
  PixelAccumulator acc;
  Counters counters;
  const ZSobolLayout layout = ZSobolLayout::forKey(key, settings.spp, settings.seed);
  for (int i = 0; i < settings.spp; ++i) {
    Sampler sampler = Sampler::make(settings.sampler, layout, key, 0, 0, static_cast<uint64_t>(i), settings.seed);
    // The camera's dimensions are unused here: the bounces keep their usual dimensions.
    acc.add(impl_->radiance(ray, sampler, settings, counters), static_cast<uint64_t>(i));
  }
  return acc.estimate();
}

}  // namespace pl
