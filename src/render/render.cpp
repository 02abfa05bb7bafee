// The straightforward light-field renderer (see render.h).
#include "render/render.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "accel/accel.h"
#include "bsdf/bsdf.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "lightfield/lookup.h"
#include "scene/scene.h"

namespace pl {

namespace {

/// Radiance along `ray` whose closest hit is `hit` (hit.hit() false: it left the scene).
/// Mirrors and glass are followed as a chain of reflections/refractions with the weights multiplied in
/// (`throughput`); the first non-specular chart ends it with the light-field lookup, its
/// albedo texture read at the level of the ray cone (coneSpread × the chain's length so far,
/// textureConeSpread). At mirror-like lobes the emitters are sampled too (MirrorLikeLights),
/// and the emission the lobe's sampled ray finds is weighted against that (`chain`). A view
/// ray's first hit on a mirror-like lobe is split (firstHitLobeSamples): each sample's chain is
/// this function again from reflection 1 on, `throughput`, `distance` and `chain` the state it
/// begins with.
Rgb radianceFromHit(const LightField& lf, const Accel& accel, const PunctualHighlights& highlights,
                    const MirrorLikeLights& lobeLights, Ray ray, RayHit hit, uint32_t mirrorDepth, float coneSpread,
                    Rgb throughput = Rgb(1.0f), float distance = 0.0f, LobeChain chain = {},
                    uint32_t firstReflection = 0) {
  const Scene& scene = lf.scene;
  Rgb result(0.0f);
  for (uint32_t reflections = firstReflection;; ++reflections) {
    result += throughput * lobeLights.sphereEmission(ray, hit.hit() ? hit.t : kInfinity, chain);  // after a lobe
    if (!hit.hit())
      return result + throughput * lobeLights.environmentWeight(ray.direction, chain) *
                          backgroundRadiance(scene.environment, ray.direction);
    distance += hit.t;
    const Chart& chart = lf.charts[lf.triangleChart[hit.mesh][hit.triangle]];
    if (chart.kind != ChartKind::Specular) {
      Rgb seen = exitantRadiance(lf, hit, positionAt(scene.meshes[hit.mesh], hit.triangle, hit.barycentrics), -ray.direction,
                                 coneSpread * distance);
      if (highlights.active() && chart.kind == ChartKind::Glossy) {
        // The punctual lights' highlights the maps leave out (lightfield.h "Punctual highlights").
        const uint32_t viewed = viewedChart(lf.charts.data(), lf.triangleChart[hit.mesh][hit.triangle], -ray.direction,
                                            scene.meshes[hit.mesh], hit.triangle);
        if (viewed != kNoChartRecord) seen += highlights.radiance(viewed, hit, -ray.direction);
      }
      return result + throughput * (seen - lobeLights.overcountedEmission(ray, hit, chain));
    }

    // An ideal mirror or glass: its own emission (if any) plus the branch weight times what
    // the reflected or refracted direction sees.
    Rgb emitted, reflectance;
    Ray reflected;
    SpecularStep step;
    const bool more = followSpecular(scene, ray, hit, reflections, mirrorDepth, emitted, reflected, reflectance, &step);
    result += throughput * lobeLights.emissionWeight(ray, hit, chain) * emitted;
    const uint32_t record = lf.triangleChart[hit.mesh][hit.triangle];
    if (highlights.active())  // a mirror-like lobe's (lightfield/lookup.h PunctualHighlights)
      result += throughput * highlights.radiance(record, hit, -ray.direction);
    const uint32_t samples = reflections == 0 ? firstHitLobeSamples(lf, record) : 1;
    if (samples > 1) {
      // The view ray's first hit on a mirror-like lobe: every sample's light sample, then every
      // sample's chain (the fast renderer's order).
      const float share = 1.0f / float(samples);
      for (uint32_t k = 0; k < samples; ++k) result += throughput * (share * lobeLights.radiance(record, ray, hit, k));
      for (uint32_t k = 0; k < samples; ++k) {
        Rgb unused;
        if (k == 0 ? !more
                   : !followSpecular(scene, ray, hit, reflections, mirrorDepth, unused, reflected, reflectance, &step, k))
          continue;
        RayHit next;
        accel.intersect(reflected, next);
        result += radianceFromHit(lf, accel, highlights, lobeLights, reflected, next, mirrorDepth, coneSpread,
                                  throughput * (share * reflectance), distance, chain.after(step, hit.t), reflections + 1);
      }
      return result;
    }
    if (lobeLights.active()) result += throughput * lobeLights.radiance(record, ray, hit);
    if (!more) return result;
    throughput *= reflectance;
    chain = chain.after(step, hit.t);
    ray = reflected;
    hit = RayHit{};
    accel.intersect(ray, hit);
  }
}

}  // namespace

Image renderLightField(const LightField& lf, const Accel& accel, const Camera& camera, const RenderSettings& settings) {
  checkRenderSettings(settings);
  const int spp = effectiveSamplesPerPixel(settings, camera.isThinLens());
  const uint32_t mirrorDepth = effectiveMirrorDepth(settings, lf.settings.mirrorDepth);
  const float coneSpread = textureConeSpread(settings, camera.pixelSpread(), spp);
  const int width = camera.width(), height = camera.height();
  const int tile = settings.tileSize;
  const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
  Image image(width, height);
  const ZSobolLayout samples(width, height, spp, settings.seed);  // pixelSample
  const PunctualHighlights highlights(lf, accel);
  const MirrorLikeLights lobeLights(lf, accel);

  std::unique_ptr<Progress> progress;
  if (settings.showProgress) progress = std::make_unique<Progress>("rendering", uint64_t(tilesX) * uint64_t(tilesY));
  parallelForRange(uint64_t(tilesX) * uint64_t(tilesY), 1, [&](uint64_t begin, uint64_t end) {
    std::vector<Ray> rays;
    std::vector<float> weights;
    std::vector<RayHit> hits;
    for (uint64_t t = begin; t < end; ++t) {
      const int x0 = int(t % uint64_t(tilesX)) * tile, y0 = int(t / uint64_t(tilesX)) * tile;
      const int x1 = std::min(x0 + tile, width), y1 = std::min(y0 + tile, height);
      // All camera rays of the tile first, then one coherent (packet) intersection.
      rays.clear();
      weights.clear();
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          for (int k = 0; k < spp; ++k) {
            Vec2 film(float(x) + 0.5f, float(y) + 0.5f), lens(0.5f);
            if (spp > 1) pixelSample(samples, x, y, k, film, lens);
            const Camera::Sample cs = camera.generateRay(film, lens);
            rays.push_back(cs.ray);
            weights.push_back(cs.weight);
          }
        }
      hits.assign(rays.size(), RayHit{});
      accel.intersectCoherent(rays, hits);
      size_t i = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          Rgb sum(0.0f);
          for (int k = 0; k < spp; ++k, ++i)
            if (weights[i] > 0.0f) sum += weights[i] * radianceFromHit(lf, accel, highlights, lobeLights, rays[i], hits[i], mirrorDepth, coneSpread);
          image.at(x, y) = sum / float(spp);
        }
      if (progress) progress->advance();
    }
  });
  return image;
}

}  // namespace pl
