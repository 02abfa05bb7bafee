// The fast light-field renderer (see realtime.h).
#include <algorithm>
#include <cstddef>
#include <new>
#include <optional>

#include "accel/accel.h"
#include "bsdf/bsdf.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "realtime/realtime.h"
#include "scene/scene.h"

namespace pl {

/// Per-thread buffers of one tile, reused across tiles and frames (grown, never shrunk).
struct FastRenderer::Scratch {
  // Camera samples of the tile, in packet order.
  std::vector<Ray> rays;
  std::vector<RayHit> hits;
  std::vector<Rgb> radiance;       ///< radiance along each camera ray
  std::vector<float> weight;       ///< camera weight (cos⁴θ or 1)
  std::vector<uint32_t> pixel;     ///< per pixel of the tile (spp samples each): y·width + x
  std::vector<uint32_t> chart;     ///< per sample, after the prefetch pass: the chart record it sees
  // Per sample on a textured diffuse chart, after the prefetch pass: the hit's uv and albedo mip level.
  std::vector<AlbedoPoint> albedo;
  // The mirror wavefront: reflected rays, their sample and accumulated reflectance.
  std::vector<Ray> mirrorRays, nextRays;
  std::vector<RayHit> mirrorHits;
  std::vector<uint32_t> mirrorSlot, nextSlot;
  std::vector<Rgb> mirrorThroughput, nextThroughput;
  std::vector<float> mirrorDistance, nextDistance;  ///< length of the chain so far (scene units; ray cones)
  std::vector<LobeChain> mirrorChain, nextChain;    ///< the MIS state at mirror-like lobes (render.cpp's `chain`)
  std::vector<uint32_t> reflectedSamples;  ///< camera samples that hit a mirror (one sample per pixel)
};

/// A one-sample pixel: weight × radiance, or 0 for a sample of zero weight (as the reference).
inline Rgb pixelValue(float weight, const Rgb& radiance) { return weight > 0.0f ? weight * radiance : Rgb(0.0f); }

namespace {
/// Issues prefetches for the cache lines of [p, p + bytes) (bytes ≤ 128: at most 3 lines).
inline void prefetchBytes(const void* p, size_t bytes) {
  const char* c = static_cast<const char*>(p);
  __builtin_prefetch(c);
  __builtin_prefetch(c + bytes - 1);
  if (bytes > 64) __builtin_prefetch(c + 64);
}
}  // namespace

FastRenderer::FastRenderer(const LightField& lightField, const Accel& accel, uint64_t prefetchLookupBytes)
    : lightField_(lightField), accel_(accel), sun_(sunLightsOf(lightField)), highlights_(lightField, accel), lobeLights_(lightField, accel) {
  const Scene& scene = lightField.scene;
  paddedValues_.reserve(lightField.values.size());
  for (const Rgb& v : lightField.values) paddedValues_.push_back(lanes4(v));
  shading_.reserve(lightField.charts.size());
  for (const Chart& c : lightField.charts) {
    if (c.material >= scene.materials.size()) fail("fast renderer: chart material {} out of range", c.material);
    shading_.push_back(chartShading(lightField, uint32_t(shading_.size()), sun_));
    anyTexturedChart_ = anyTexturedChart_ || shading_.back().needsUv;
  }
  if (lightField.triangleChart.size() != scene.meshes.size())
    fail("fast renderer: triangle → chart map has {} meshes, the scene {}", lightField.triangleChart.size(), scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (lightField.triangleChart[m].size() != scene.meshes[m].triangles.size())
      fail("fast renderer: mesh {} has {} triangles but {} chart entries", m, scene.meshes[m].triangles.size(),
           lightField.triangleChart[m].size());
    meshFirstTriangle_.push_back(uint32_t(triangleChart_.size()));
    for (uint32_t chart : lightField.triangleChart[m]) {
      if (chart >= lightField.charts.size()) fail("fast renderer: mesh {}: chart index {} out of range", m, chart);
      triangleChart_.push_back(chart);
    }
  }
  const uint64_t lookupBytes = uint64_t(paddedValues_.size()) * sizeof(Lanes4) +
                               uint64_t(lightField.charts.size()) * (sizeof(Chart) + sizeof(ChartShading));
  prefetchLookups_ = lookupBytes > prefetchLookupBytes;
}

size_t FastRenderer::tileCameraRays(const Camera& camera, int spp, uint64_t seed, int x0, int y0, int x1, int y1,
                                    Ray* rays, float* weight, uint32_t* pixelIndex) {
  // Camera::generateRay returns its Sample through memory. Copying it out right after the
  // call reads it with 16-byte loads that the callee's narrower stores cannot forward (a
  // store-forwarding stall per ray, measured at a quarter of this loop's time), so the
  // samples are constructed in place in a small batch (guaranteed copy elision: the callee
  // writes straight into batch[j]) and copied out 16 calls later, from the cache.
  constexpr size_t kBatch = 16;
  alignas(64) std::byte storage[kBatch * sizeof(Camera::Sample)];
  Camera::Sample* batch = reinterpret_cast<Camera::Sample*>(storage);
  size_t pending = 0, n = 0, p = 0;
  auto flush = [&] {
    for (size_t j = 0; j < pending; ++j, ++n) {
      rays[n] = batch[j].ray;
      weight[n] = batch[j].weight;
    }
    pending = 0;
  };
  const int width = camera.width();
  if (spp == 1) {
    // One sample per pixel (the walk-through case): pixel and lens centre.
    for (int by = y0; by < y1; by += 4)
      for (int bx = x0; bx < x1; bx += 4)
        for (int y = by; y < std::min(by + 4, y1); ++y)
          for (int x = bx; x < std::min(bx + 4, x1); ++x) {
            pixelIndex[p++] = uint32_t(uint64_t(y) * uint64_t(width) + uint64_t(x));
            if (pending == kBatch) flush();
            ::new (static_cast<void*>(batch + pending))
                Camera::Sample(camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f), Vec2(0.5f)));
            ++pending;
          }
    flush();
    return n;
  }
  const ZSobolLayout samples(width, camera.height(), spp, seed);  // pixelSample
  for (int by = y0; by < y1; by += 4)
    for (int bx = x0; bx < x1; bx += 4)
      for (int y = by; y < std::min(by + 4, y1); ++y)
        for (int x = bx; x < std::min(bx + 4, x1); ++x) {
          pixelIndex[p++] = uint32_t(uint64_t(y) * uint64_t(width) + uint64_t(x));
          for (int k = 0; k < spp; ++k) {
            // Exactly the reference's sample positions (render.cpp).
            Vec2 film, lens;
            pixelSample(samples, x, y, k, film, lens);
            if (pending == kBatch) flush();
            ::new (static_cast<void*>(batch + pending)) Camera::Sample(camera.generateRay(film, lens));
            ++pending;
          }
        }
  flush();
  return n;
}

size_t FastRenderer::tilePrimaryHits(const Camera& camera, int spp, uint64_t seed, int x0, int y0, int x1, int y1,
                                     Scratch& s) const {
  const size_t pixels = size_t(x1 - x0) * size_t(y1 - y0);
  const size_t samples = pixels * size_t(spp);
  s.rays.resize(samples);
  s.hits.resize(samples);
  s.weight.resize(samples);
  s.pixel.resize(pixels);
  const size_t n = tileCameraRays(camera, spp, seed, x0, y0, x1, y1, s.rays.data(), s.weight.data(), s.pixel.data());
  accel_.intersectCoherent(std::span<const Ray>(s.rays.data(), n), std::span<RayHit>(s.hits.data(), n));
  return n;
}

void FastRenderer::renderTile(const Camera& camera, int spp, uint32_t mirrorDepth, float coneSpread, uint64_t seed, int x0,
                              int y0, int x1, int y1, Scratch& s, Image& image) const {
  const Scene& scene = lightField_.scene;
  const Chart* charts = lightField_.charts.data();
  const ChartShading* shading = shading_.data();
  const PaddedValues values{paddedValues_.data()};
  const size_t pixels = size_t(x1 - x0) * size_t(y1 - y0);
  s.radiance.resize(pixels * size_t(spp));

  // 1. Camera rays in 4×4-pixel blocks (see tileCameraRays).
  const size_t n = tilePrimaryHits(camera, spp, seed, x0, y0, x1, y1, s);

  // 2. Shade the camera hits; mirror hits start the reflection wavefront. With one sample
  // per pixel, a pixel that needs no reflection is written as soon as it is shaded, and four
  // consecutive samples on the same diffuse chart (most of a frame) are looked up together
  // (exitantRadianceDiffuse4: the same values as one at a time).
  s.mirrorRays.clear();
  s.mirrorSlot.clear();
  s.mirrorThroughput.clear();
  s.mirrorDistance.clear();
  s.mirrorChain.clear();
  Rgb* out = image.pixels.data();
  // The chart record sample i sees: its triangle's chart, turned to the side facing the camera
  // (kNoChartRecord behind a one-sided curved record: viewedChart).
  auto viewedChartOf = [&](size_t i) {
    const RayHit& hit = s.hits[i];
    return viewedChart(charts, triangleChart_[meshFirstTriangle_[hit.mesh] + hit.triangle], -s.rays[i].direction,
                       scene.meshes[hit.mesh], hit.triangle);
  };
  // A lookup is a chain of dependent loads — the hit's chart index, its chart record, the
  // record's shading, two rows of values, texels — each a cache (and, on 4 KiB pages, TLB)
  // miss once the light field outgrows the caches; one pixel at a time the processor can
  // overlap only a few such chains. So on large light fields (prefetchLookups_) and textured
  // ones the tile's lookups are first walked in two passes that only prefetch: (a) every
  // hit's chart index, prefetching its record; (b) with the records arriving, the facing
  // record (kept for the shading below), its shading, the two value rows the diffuse
  // interpolation reads, and the texels (Texture::prefetch; the uv and mip level are kept for
  // the shading). (Without textures on a small
  // light field everything is cached and the passes alone cost 10–15 % of the Cornell box's
  // frame: skipped.)
  const bool prefetched = prefetchLookups_ || anyTexturedChart_;
  auto chartOf = [&](size_t i) { return prefetched ? s.chart[i] : viewedChartOf(i); };
  if (prefetched) {
    s.chart.resize(n);
    if (anyTexturedChart_) s.albedo.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const RayHit& hit = s.hits[i];
      if (!hit.hit()) continue;
      s.chart[i] = triangleChart_[meshFirstTriangle_[hit.mesh] + hit.triangle];
      if (prefetchLookups_) prefetchBytes(charts + s.chart[i], sizeof(Chart));
    }
    for (size_t i = 0; i < n; ++i) {
      const RayHit& hit = s.hits[i];
      if (!hit.hit()) continue;
      const uint32_t chart = viewedChart(charts, s.chart[i], -s.rays[i].direction, scene.meshes[hit.mesh], hit.triangle);
      s.chart[i] = chart;
      if (chart == kNoChartRecord) continue;
      const Chart& c = charts[chart];
      if (prefetchLookups_) {
        prefetchBytes(shading + chart, sizeof(ChartShading));
        if (c.kind == ChartKind::Diffuse) {
          // The rows interpolateLanes' diffuse branch reads (the grid from the chart's own
          // tixel size; a prefetch need not round like the lookup).
          const Vec2 grid = tixelGridCoordinates(c, s.rays[i].origin + hit.t * s.rays[i].direction);
          const LinearTap tu = linearTap(grid.x, c.resU), tv = linearTap(grid.y, c.resV);
          __builtin_prefetch(paddedValues_.data() + c.valueIndex(tu.i0, tv.i0));
          __builtin_prefetch(paddedValues_.data() + c.valueIndex(tu.i1, tv.i1));
          // The sun masks the lookup reads (sunVisibility: the tixel's and, across a tixel
          // edge, a neighbour's; the first is the common case).
          if (sun_.count > 0)
            __builtin_prefetch(lightField_.sunMasks.data() + (c.firstTixel + uint64_t(tv.i0) * c.resU + tu.i0) * sun_.count);
        }
      }
      // shading[chart].needsUv, from the (small, cached) material array: the shading record
      // prefetched above is still on its way (waiting for it here took 8 % of renderTile).
      const Material& material = scene.materials[c.material];
      if (c.kind != ChartKind::Diffuse || !(material.modelVaries() || material.emissionTexture >= 0)) continue;
      // lookupInputs' albedo point for this hit (the same functions: the same bits).
      s.albedo[i] = albedoPointAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
      if (material.albedoTexture < 0) continue;
      const Texture& albedo = scene.textures[size_t(material.albedoTexture)];
      s.albedo[i].lod = albedoTextureLod(scene.meshes[hit.mesh], hit.triangle, albedo, material.albedoMapping,
                                         s.rays[i].direction, coneSpread * hit.t);
      albedo.prefetch(s.albedo[i].uv, s.albedo[i].lod);
    }
  }
  // Whether samples i … i+3 all hit one diffuse chart record (→ *chart).
  auto sameDiffuseChart = [&](size_t i, uint32_t* chart) {
    for (size_t k = i; k < i + 4; ++k)
      if (!(s.weight[k] > 0.0f) || !s.hits[k].hit()) return false;
    *chart = chartOf(i);
    if (*chart == kNoChartRecord || charts[*chart].kind != ChartKind::Diffuse || charts[*chart].directionalIrradiance)
      return false;
    for (size_t k = i + 1; k < i + 4; ++k)
      if (chartOf(k) != *chart) return false;
    return true;
  };
  RaysSoA4 four;
  AlbedoPoint fourAlbedo[4];
  Vec3 fourNormal[4];
  F4 fourRadiance[4];
  for (size_t i = 0; i < n;) {
    uint32_t chart = 0;
    if (spp == 1 && i + 4 <= n && sameDiffuseChart(i, &chart)) {
      for (int k = 0; k < 4; ++k) {
        const Ray& ray = s.rays[i + k];
        four.ox[k] = ray.origin.x, four.oy[k] = ray.origin.y, four.oz[k] = ray.origin.z;
        four.dx[k] = ray.direction.x, four.dy[k] = ray.direction.y, four.dz[k] = ray.direction.z;
        four.t[k] = s.hits[i + k].t;
      }
      // A separate loop: a call inside the one above keeps the compiler from merging its stores
      // into vectors, and the lookup's 16-byte loads of them then stall (measured on Cornell).
      // A textured chart: the uvs and levels of the prefetch pass (anyTexturedChart_ ran it).
      if (shading[chart].needsUv)
        for (int k = 0; k < 4; ++k) fourAlbedo[k] = s.albedo[i + k];
      // A curved chart with sun masks: the normals the masked lights shine on (lookupInputs').
      const bool normals = needsInterpolatedNormal(charts[chart], shading[chart]);
      if (normals)
        for (int k = 0; k < 4; ++k)
          fourNormal[k] = lookupNormalAt(scene, charts[chart], shading[chart], s.hits[i + k].mesh, s.hits[i + k].triangle,
                                         s.hits[i + k].barycentrics);
      exitantRadianceDiffuse4(scene, charts[chart], shading[chart], paddedValues_.data(), four, fourAlbedo,
                              fourRadiance, normals ? fourNormal : nullptr);
      for (int k = 0; k < 4; ++k) f4StoreRgb(out + s.pixel[i + k], f4Mul(f4Splat(s.weight[i + k]), fourRadiance[k]));
      i += 4;
      continue;
    }
    const Ray& ray = s.rays[i];
    const RayHit& hit = s.hits[i];
    Rgb radiance(0.0f);
    if (!(s.weight[i] > 0.0f)) {
      // The reference skips samples of zero weight.
    } else if (!hit.hit()) {
      radiance = backgroundRadiance(scene.environment, ray.direction);
    } else if (chart = chartOf(i); chart == kNoChartRecord) {
      // Inside a closed smooth mesh: nothing reflected, nothing emitted (viewedChart).
    } else {
      const Chart& c = charts[chart];
      if (c.kind != ChartKind::Specular) {
        AlbedoPoint albedo;
        Vec3 lookupNormal, mappedNormal;
        lookupInputs(scene, c, shading[chart], hit, -ray.direction, coneSpread * hit.t, albedo, lookupNormal, mappedNormal);
        F4 lanes = exitantRadianceLanes(scene, c, shading[chart], values, ray.origin + hit.t * ray.direction, -ray.direction,
                                        lookupNormal, mappedNormal, albedo);
        if (c.kind == ChartKind::Glossy && highlights_.active())  // lightfield.h "Punctual highlights"
          lanes = f4Add(lanes, f4FromRgb(highlights_.radiance(chart, hit, -ray.direction)));
        if (spp == 1) {
          // The pixel, straight from the lanes (weight > 0 here): pixelValue's weight × radiance.
          f4StoreRgb(out + s.pixel[i], f4Mul(f4Splat(s.weight[i]), lanes));
          ++i;
          continue;
        }
        radiance = f4Rgb(lanes);
      } else {
        // The view ray's first hit: several lobe samples on a mirror-like lobe
        // (firstHitLobeSamples), in the reference renderer's order of sums (render.cpp).
        const uint32_t samples = firstHitLobeSamples(lightField_, chart);
        const float share = 1.0f / float(samples);
        for (uint32_t k = 0; k < samples; ++k) {
          Ray reflected;
          Rgb reflectance, emitted;
          SpecularStep step;
          const bool more = followSpecular(scene, ray, hit, 0, mirrorDepth, emitted, reflected, reflectance, &step, k);
          if (k == 0) {
            radiance = emitted;
            if (highlights_.active()) radiance += highlights_.radiance(chart, hit, -ray.direction);  // mirror-like lobes
          }
          if (lobeLights_.active()) radiance += share * lobeLights_.radiance(chart, ray, hit, k);
          if (more) {
            s.mirrorRays.push_back(reflected);
            s.mirrorSlot.push_back(uint32_t(i));
            s.mirrorThroughput.push_back(share * reflectance);
            s.mirrorDistance.push_back(hit.t);
            s.mirrorChain.push_back(LobeChain{}.after(step, hit.t));
          }
        }
      }
    }
    s.radiance[i] = radiance;
    if (spp == 1) out[s.pixel[i]] = pixelValue(s.weight[i], radiance);
    ++i;
  }
  // The samples whose pixels the reflections below complete (one sample per pixel).
  if (spp == 1) {
    s.reflectedSamples.assign(s.mirrorSlot.begin(), s.mirrorSlot.end());  // a split's rays are adjacent
    s.reflectedSamples.erase(std::unique(s.reflectedSamples.begin(), s.reflectedSamples.end()), s.reflectedSamples.end());
  }

  // 3. Reflection wavefronts, intersected as packets (a planar mirror keeps them coherent).
  for (uint32_t reflections = 1; !s.mirrorRays.empty(); ++reflections) {
    const size_t active = s.mirrorRays.size();
    s.mirrorHits.resize(active);
    accel_.intersectCoherent(s.mirrorRays, s.mirrorHits);
    s.nextRays.clear();
    s.nextSlot.clear();
    s.nextThroughput.clear();
    s.nextDistance.clear();
    s.nextChain.clear();
    for (size_t i = 0; i < active; ++i) {
      const Ray& ray = s.mirrorRays[i];
      const RayHit& hit = s.mirrorHits[i];
      const uint32_t slot = s.mirrorSlot[i];
      const Rgb throughput = s.mirrorThroughput[i];
      const float distance = s.mirrorDistance[i] + hit.t;  // the reference's running sum (render.cpp)
      const LobeChain& chain = s.mirrorChain[i];
      s.radiance[slot] += throughput * lobeLights_.sphereEmission(ray, hit.hit() ? hit.t : kInfinity, chain);  // render.cpp's order
      if (!hit.hit()) {
        s.radiance[slot] +=
            throughput * lobeLights_.environmentWeight(ray.direction, chain) * backgroundRadiance(scene.environment, ray.direction);
        continue;
      }
      const uint32_t chart = viewedChart(charts, triangleChart_[meshFirstTriangle_[hit.mesh] + hit.triangle], -ray.direction,
                                         scene.meshes[hit.mesh], hit.triangle);
      if (chart == kNoChartRecord) continue;  // inside a closed smooth mesh: nothing seen
      const Chart& c = charts[chart];
      if (c.kind != ChartKind::Specular) {
        AlbedoPoint albedo;
        Vec3 lookupNormal, mappedNormal;
        lookupInputs(scene, c, shading[chart], hit, -ray.direction, coneSpread * distance, albedo, lookupNormal,
                     mappedNormal);
        s.radiance[slot] += throughput * (exitantRadiance(scene, c, shading[chart], values, ray.origin + hit.t * ray.direction,
                                                          -ray.direction, lookupNormal, mappedNormal, albedo) -
                                          lobeLights_.overcountedEmission(ray, hit, chain));
        if (c.kind == ChartKind::Glossy && highlights_.active())
          s.radiance[slot] += throughput * highlights_.radiance(chart, hit, -ray.direction);
        continue;
      }
      Rgb emitted;
      Ray reflected;
      Rgb reflectance;
      SpecularStep step;
      const bool more = followSpecular(scene, ray, hit, reflections, mirrorDepth, emitted, reflected, reflectance, &step);
      s.radiance[slot] += throughput * lobeLights_.emissionWeight(ray, hit, chain) * emitted;
      if (highlights_.active()) s.radiance[slot] += throughput * highlights_.radiance(chart, hit, -ray.direction);
      if (lobeLights_.active()) s.radiance[slot] += throughput * lobeLights_.radiance(chart, ray, hit);
      if (more) {
        s.nextRays.push_back(reflected);
        s.nextSlot.push_back(slot);
        s.nextThroughput.push_back(throughput * reflectance);
        s.nextDistance.push_back(distance);
        s.nextChain.push_back(chain.after(step, hit.t));
      }
    }
    std::swap(s.mirrorRays, s.nextRays);
    std::swap(s.mirrorSlot, s.nextSlot);
    std::swap(s.mirrorThroughput, s.nextThroughput);
    std::swap(s.mirrorDistance, s.nextDistance);
    std::swap(s.mirrorChain, s.nextChain);
  }

  // Pixel = mean over its samples of weight × radiance (the reference's order of sums).
  if (spp == 1) {
    for (uint32_t i : s.reflectedSamples) out[s.pixel[i]] = pixelValue(s.weight[i], s.radiance[i]);
    return;
  }
  for (size_t q = 0; q < pixels; ++q) {
    Rgb sum(0.0f);
    for (size_t k = q * size_t(spp); k < (q + 1) * size_t(spp); ++k)
      if (s.weight[k] > 0.0f) sum += s.weight[k] * s.radiance[k];
    out[s.pixel[q]] = sum / float(spp);
  }
}


template <typename Tile>
void FastRenderer::forEachTile(const Camera& camera, const RenderSettings& settings, Tile&& tile) const {
  const int width = camera.width(), height = camera.height();
  const int size = settings.tileSize;
  const int tilesX = (width + size - 1) / size, tilesY = (height + size - 1) / size;
  parallelForRange(uint64_t(tilesX) * uint64_t(tilesY), 1, [&](uint64_t begin, uint64_t end) {
    static thread_local Scratch scratch;
    for (uint64_t t = begin; t < end; ++t) {
      const int x0 = int(t % uint64_t(tilesX)) * size, y0 = int(t / uint64_t(tilesX)) * size;
      tile(x0, y0, std::min(x0 + size, width), std::min(y0 + size, height), scratch);
    }
  });
}

void FastRenderer::render(const Camera& camera, const RenderSettings& settings, Image& image) const {
  checkRenderSettings(settings);
  const int spp = effectiveSamplesPerPixel(settings, camera.isThinLens());
  const uint32_t mirrorDepth = effectiveMirrorDepth(settings, lightField_.settings.mirrorDepth);
  const float coneSpread = textureConeSpread(settings, camera.pixelSpread(), spp);
  if (image.width != camera.width() || image.height != camera.height()) image = Image(camera.width(), camera.height());
  forEachTile(camera, settings, [&](int x0, int y0, int x1, int y1, Scratch& scratch) {
    renderTile(camera, spp, mirrorDepth, coneSpread, settings.seed, x0, y0, x1, y1, scratch, image);
  });
}

void FastRenderer::castPrimaryRays(const Camera& camera, const RenderSettings& settings, std::vector<float>& depth) const {
  checkRenderSettings(settings);
  const int spp = effectiveSamplesPerPixel(settings, camera.isThinLens());
  depth.resize(size_t(camera.width()) * size_t(camera.height()));
  forEachTile(camera, settings, [&](int x0, int y0, int x1, int y1, Scratch& s) {
    const size_t n = tilePrimaryHits(camera, spp, settings.seed, x0, y0, x1, y1, s);
    for (size_t i = 0; i < n; ++i) depth[s.pixel[i / size_t(spp)]] = s.hits[i].t;
  });
}

Image FastRenderer::render(const Camera& camera, const RenderSettings& settings) const {
  Image image;
  render(camera, settings, image);
  return image;
}

}  // namespace pl
