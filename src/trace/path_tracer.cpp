// The reference path tracer (see trace.h for the conventions).
//
// Estimator. For a path x0 (camera) → x1 → x2 → ..., with throughput β_k = Π f·cos/pdf of
// the BSDF samples taken so far, the radiance is the sum over vertices x_k of
//   β_k · Le(x_k)                         emission found by the BSDF-sampled ray, weighted by
//                                         w_bsdf = p_bsdf² / (p_bsdf² + p_light²)
// + β_k · f · cos θi · Le / p_light        next-event estimation at x_k, weighted by
//                                         w_light = p_light² / (p_bsdf² + p_light²)
// (Veach's power heuristic, β = 2). Both pdfs are solid-angle densities at x_k of the same
// direction: p_light includes the probability of selecting that light. The scene's lights
// (light/lights.h: point, spot, …) are no geometry. The delta ones (point, spot, directional)
// can only be reached by NEE (weight 1). Sphere lights are MIS-weighted as emissive triangles
// are: a BSDF-sampled ray leaving a non-delta vertex that passes through one before its hit
// (LightSampler::sphereLightAlong) adds β_k · Le · w_bsdf and goes on through it, since a
// sphere light occludes nothing — without it a narrow lobe (sharp GGX) would find a small
// sphere only by NEE, as rare huge f/p_light fireflies. Camera rays and rays after delta
// bounces do not see sphere lights (lights.h: the camera and mirrors do not see the sphere).
// Delta BSDF bounces (mirrors) can only be followed by BSDF sampling, so emission seen right
// after one counts fully, as does emission seen by the camera ray.
//
// Subsurface scattering (bsdf.h SubsurfaceBsdf). A path meeting a subsurface material enters
// it — cosine-distributed about the inward normal, weight 1: the boundary is diffuse and
// index-matched — and random-walks through the homogeneous medium (trace/subsurface_walk.h) until
// it meets the mesh again. There it leaves as from a Lambertian surface of albedo 1: next-event
// estimation and the next direction are those of LambertBsdf{1} at the exit point, and the walk
// with its entry and exit counts as one scattering event (one depth). Light arriving at the
// entry point is not reflected there: all of it goes through the medium. With
// TraceSettings::subsurfaceLambertAfterDiffuse (a comparison with Cycles) a path that has
// bounced off a Lambertian surface — a Lambertian material, a subsurface exit, or a subsurface
// material already so shaded — shades subsurface materials as the SubsurfaceBsdf's BSDF,
// Lambertian of albedo A, without a walk.
//
// Light selection, the points sampled on lights, their densities and what blocks a shadow ray
// are light/light.h's (LightSampler, ShadowRays): the bake's first shot uses the same ones.
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
#include "core/cancel.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/sampler.h"
#include "core/sampling.h"
#include "light/light.h"
#include "scene/scene.h"
#include "trace/subsurface_walk.h"
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

/// Per-render counters, accumulated per tile and added atomically at the end of each tile.
struct Counters {
  uint64_t rays = 0;
};

/// The sampler dimensions of a path (core/sampler.h): the camera's film and lens positions,
/// then per bounce (scattering event) `depth` a block of kDimensionsPerBounce starting at
/// bounceDimension(depth): the light sample (2-D: light choice stretched into the point on
/// it, light.h), the BSDF sample (2-D: lobe choice stretched into the direction) and Russian
/// roulette (1-D). A decision always uses the same dimension whatever the path did before it.
constexpr uint32_t kFilmDimension = 0, kLensDimension = 1, kFirstBounceDimension = 2;
constexpr uint32_t kDimensionsPerBounce = 3;
enum BounceDimension : uint32_t { kLightSample = 0, kBsdfSample = 1, kRoulette = 2 };
uint32_t bounceDimension(int depth, BounceDimension which) {
  return kFirstBounceDimension + kDimensionsPerBounce * uint32_t(depth) + which;
}

/// A random walk (trace/subsurface_walk.h) at path depth d draws from walkDimension(d), a block
/// of kWalkDimensions per depth far above the bounces' own.
constexpr uint32_t kFirstWalkDimension = 1u << 24;
uint32_t walkDimension(int depth) { return kFirstWalkDimension + uint32_t(uint64_t(depth) * kWalkDimensions); }
static_assert(uint64_t(kFirstWalkDimension) + uint64_t(kSafetyDepth + 1) * kWalkDimensions < (uint64_t(1) << 32),
              "walk dimensions fit in 32 bits");

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

}  // namespace

// -----------------------------------------------------------------------------------------
struct PathTracer::Impl {
  const Scene& scene;
  const Accel& accel;
  LightSampler lights;
  ShadowRays shadows;

  Impl(const Scene& s, const Accel& a) : scene(s), accel(a), lights(s), shadows(s, a) {}

  Rgb directLight(const ScatteringFrame& scattering, const Vec3& position, const Bsdf& bsdf,
                  const TraceSettings& settings, int depth, Sampler& sampler, Counters& counters) const;
  Rgb radiance(Ray ray, Sampler& sampler, const TraceSettings& settings, Counters& counters) const;
  void tracePixel(const Camera& camera, const ZSobolLayout& layout, const TraceSettings& settings, int x, int y,
                  PixelAccumulator& acc, Counters& counters) const;
};

// Next-event estimation at a non-delta vertex: one light sample (light.h nextEventEstimate),
// MIS-weighted against the BSDF's density when the light could also be hit by BSDF sampling.
Rgb PathTracer::Impl::directLight(const ScatteringFrame& scattering, const Vec3& position, const Bsdf& bsdf,
                                  const TraceSettings& settings, int depth, Sampler& sampler, Counters& counters) const {
  sampler.setDimension(bounceDimension(depth, kLightSample));
  const Vec2 u = sampler.get2D();
  const NextEvent mode = settings.strategy == TraceStrategy::Mis        ? NextEvent::Mis
                         : settings.strategy == TraceStrategy::BsdfOnly ? NextEvent::SceneLightsOnly
                                                                        : NextEvent::LightOnly;
  return nextEventEstimate(lights, shadows, position, scattering, bsdf, u, mode, counters.rays);
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
  // Whether the path has bounced off a Lambertian surface (subsurfaceLambertAfterDiffuse).
  bool diffuseAncestor = false;
  const bool useMis = settings.strategy == TraceStrategy::Mis;
  const bool bsdfOnly = settings.strategy == TraceStrategy::BsdfOnly;

  const int maxDepth = settings.maxDepth == kUnboundedDepth ? kSafetyDepth : settings.maxDepth;
  for (int depth = 0;; ++depth) {
    RayHit hit;
    ++counters.rays;
    const bool found = accel.intersect(ray, hit);
    if (useMis && !countEmissionFully && lights.hasSphereLights()) {
      // A sphere light between the vertex and the hit (or the sky), weighted against NEE's
      // density for the direction at the vertex that sampled it (distanceBefore back along the
      // ray, past any thin sheets crossed straight).
      Ray segment = ray;
      segment.tMax = found ? hit.t : kInfinity;
      if (const auto sphere = lights.sphereLightAlong(segment, ray.origin - distanceBefore * ray.direction))
        result += throughput * sphere->radiance * powerHeuristic(previousBsdfPdf, sphere->pdf);
    }
    if (!found) {
      if (lights.hasEnvironment()) {
        const Rgb le = lights.environment().radiance(ray.direction);
        if (countEmissionFully) {
          result += throughput * le;
        } else if (useMis) {
          result += throughput * le * powerHeuristic(previousBsdfPdf, lights.environmentPdf(ray.direction));
        }
      }
      break;
    }

    const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
    const Material& material = scene.materials[surface.material];
    const Vec3 wo = -ray.direction;
    const float cosWoGeometric = glm::dot(surface.geometricNormal, wo);
    throughput *= interiorTransmittance(material, cosWoGeometric, hit.t);  // Beer–Lambert (scene.h)

    if (!isBlack(emittedRadiance(material, cosWoGeometric))) {  // the emission sidedness rule (scene.h)
      // Le at the hit: the emission times its texture there (scene.h emissionModulation).
      const Rgb le = material.emission * emissionModulation(scene, material, hit.mesh, hit.triangle, hit.barycentrics);
      if (countEmissionFully) {
        result += throughput * le;
      } else if (useMis) {
        // The density NEE would have had for this point, in solid angle at the previous
        // vertex (t from that vertex, through any thin glass crossed straight). A triangle
        // that is no light (zero power) has density 0: BSDF sampling alone finds it.
        const float lightPdf =
            lights.emitterPdf(hit.mesh, hit.triangle, distanceBefore + hit.t, std::abs(cosWoGeometric));
        result += throughput * le * powerHeuristic(previousBsdfPdf, lightPdf);
      }
    }
    if (depth >= maxDepth) break;

    // The sidedness rule (scene.h): reflecting BSDFs two-sided, transmitting ones unturned.
    // The albedo texture at full resolution (no mip level): the pixel's samples integrate its
    // footprint, which is what the light-field renderers' texture LOD approximates.
    Bsdf bsdf = bsdfAt(scene, surface);
    ScatteringFrame scattering = scatteringFrame(surface, wo, bsdf);
    if (!usableSide(wo, scattering.woLocal, scattering.geometricNormal, bsdf)) break;
    Vec3 position = surface.position;
    const std::optional<SubsurfaceMedium> medium = subsurfaceMedium(bsdf);
    if (medium && !(settings.subsurfaceLambertAfterDiffuse && diffuseAncestor)) {
      // Through the medium to where the walk leaves it; the exit point then scatters as a
      // white Lambertian on the mesh's outside (the side the walk's last direction points to).
      const std::optional<WalkExit> exit =
          subsurfaceWalk(scene, accel, position, scattering, *medium, throughput, sampler, walkDimension(depth), counters.rays);
      if (!exit) break;
      throughput *= exit->weight;
      bsdf = LambertBsdf{Rgb(1.0f)};
      scattering = scatteringFrame(exit->surface, exit->direction, bsdf);
      scattering.woLocal = Vec3(0.0f, 0.0f, 1.0f);  // the exit does not depend on the walk's direction
      position = exit->surface.position;
    }
    const auto& [geometricNormal, frame, woLocal] = scattering;

    if (!isDelta(bsdf)) {
      result += throughput *
                directLight(scattering, position, bsdf, settings, depth, sampler, counters);
    }

    sampler.setDimension(bounceDimension(depth, kBsdfSample));
    const Vec2 u = sampler.get2D();
    const std::optional<Scattered> scattered = scatter(scattering, bsdf, u);  // the one bounce (scene.h)
    if (!scattered) break;
    const BsdfSample& s = scattered->sample;
    const Vec3 wi = scattered->wi;
    diffuseAncestor =
        diffuseAncestor || std::holds_alternative<LambertBsdf>(bsdf) || std::holds_alternative<SubsurfaceBsdf>(bsdf);
    throughput *= s.weight;
    if (isBlack(throughput)) break;
    if (const auto* glass = std::get_if<DielectricBsdf>(&bsdf); glass && !glass->thin && woLocal.z * s.wi.z < 0.0f) {
      const float etap = woLocal.z > 0.0f ? glass->ior : 1.0f / glass->ior;  // η(wi side) / η(wo side)
      etaScale *= etap * etap;
    }
    const auto* sheet = std::get_if<DielectricBsdf>(&bsdf);
    if (sheet && sheet->thin && woLocal.z * s.wi.z < 0.0f) {
      distanceBefore += hit.t;  // straight through: the previous vertex's sample continues
    } else {
      countEmissionFully = s.delta || bsdfOnly;
      previousBsdfPdf = s.pdf;
      distanceBefore = 0.0f;
    }
    ray.origin = offsetRayOrigin(position, geometricNormal, wi);
    ray.direction = wi;
    ray.tMin = 0.0f;
    ray.tMax = kInfinity;

    // Russian roulette (unbiased): continue with probability q, divide the throughput by q.
    // q < 1 always (kRouletteMaxContinue), so every path ends with probability 1 without a
    // depth cap; written as !(u < q) so that a NaN throughput ends the path too.
    if (depth + 1 >= settings.rouletteDepth) {
      // etaScale undoes the η² radiance scaling of refractions (as pbrt-v4 does), so a path
      // that entered glass is not ended more or less often than one that left it. The square
      // root (as Cycles does) ends dim paths later than q = throughput would: a few more rays
      // per path buy less noise per ray (measured: docs/design.md, The reference path tracer).
      const float q = std::min(std::sqrt(maxComponent(throughput) * etaScale), kRouletteMaxContinue);
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
    // A pixel may take minutes at millions of samples: a cancellation point per sample (one
    // relaxed atomic load against a path's microseconds).
    throwIfCancelled();
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

size_t PathTracer::emissiveTriangleCount() const { return impl_->lights.emissiveTriangleCount(); }
size_t PathTracer::lightCount() const { return impl_->lights.lightCount(); }

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
