#pragma once
// The fast light-field renderer: the same image as the straightforward renderer
// (render/render.h, the reference), built for frame rates.
//
// Per frame the image is cut into square tiles rendered in parallel (pl::parallelForRange).
// Per tile:
//   1. camera rays for all samples of the tile, ordered in 4×4-pixel blocks so that each
//      16-ray Embree packet (Accel::intersectCoherent) covers a compact footprint;
//   1b. on light fields larger than kPrefetchLookupBytes and on textured ones, two passes over
//      the tile's hits that only prefetch — chart records, then each hit's facing record (kept
//      for step 2), its shading, the two value rows and the sun mask of a diffuse lookup and the texels it will
//      read (Texture::prefetch, at the mip level of the sample's ray cone) — so that their cache misses overlap across the tile;
//   2. shading of every hit without building a SurfaceHit: the hit point is ray.origin +
//      t·ray.direction, the chart comes from LightField::triangleChart, and the radiance from
//      exitantRadianceLanes() of lightfield/lookup.h with the chart's ChartShading precomputed
//      once (the one 16-neighbour formula the reference also runs, in four SSE lanes;
//      diffuse charts whose albedo varies interpolate the hit's albedo point alone, albedoPointAt, and only normal-mapped
//      glossy charts build the SurfaceHit; curved glossy charts interpolate the hit's vertex
//      normal alone, chartShadingNormalAt, to read their maps around it). With one sample per pixel, four consecutive
//      samples on one diffuse chart go through exitantRadianceDiffuse4 together
//      (bit-identical), and a pixel is written from the lanes as soon as it is shaded;
//   3. mirrors as a wavefront of reflection rays: all samples of the tile that hit an
//      ideal-specular chart spawn their reflected ray (same steps as the reference: shading
//      normal frame, the BSDF's delta sample with its Fresnel weight, offset origin), and
//      the wavefront is intersected again as packets, up to mirrorDepth reflections.
// The light-field values are copied once, padded to 16 bytes (Lanes4: one aligned load per
// tap), in LightField::values' tixel-major order (all direction texels of a tixel
// contiguous), so a glossy lookup touches two cache lines per tixel and a diffuse lookup four
// values of one or two rows.
//
// Sampling, camera weights, mirror depth, background and the pixel value are exactly those
// of renderLightField (RenderSettings has the same meaning); results differ from the
// reference only by float rounding (the hit point is computed from the ray, not from the
// barycentrics). Scratch buffers are per thread and reused from frame to frame: after the
// first frame of a given size no allocation happens while rendering.
#include <cstdint>
#include <vector>

#include "image/image.h"
#include "lightfield/lightfield.h"
#include "lightfield/lookup.h"
#include "lightfield/render_settings.h"

namespace pl {

class Accel;
class Camera;

class FastRenderer {
 public:
  /// Beyond this many bytes of values and chart records a light field's lookups miss the
  /// caches (this machine's L2 is 1 MiB per core; the L3 is shared with everything else
  /// running), and render() prefetches each tile's chart records and value rows before
  /// shading it (renderTile).
  static constexpr uint64_t kPrefetchLookupBytes = uint64_t(4) << 20;

  /// Precomputes the per-chart shading table. `lightField` and `accel` (built over
  /// lightField.scene) must outlive the renderer. `prefetchLookupBytes`: the size from which
  /// tiles prefetch their lookups (tests pass 0 to run that path on small scenes; the image
  /// is the same either way).
  FastRenderer(const LightField& lightField, const Accel& accel, uint64_t prefetchLookupBytes = kPrefetchLookupBytes);

  /// Renders camera.width() × camera.height() pixels of radiance (W·sr⁻¹·m⁻², camera weight
  /// included, no exposure) into `image`, which is resized only when its size differs.
  /// settings.showProgress is ignored (a frame takes milliseconds).
  void render(const Camera& camera, const RenderSettings& settings, Image& image) const;
  Image render(const Camera& camera, const RenderSettings& settings) const;

  /// The first pass of a tile, also what realtime_bench times as "primary rays alone": the
  /// camera rays of every sample of pixels [x0, x1) × [y0, y1), in 4×4-pixel blocks (all
  /// samples of a pixel consecutive) so that each 16-ray packet covers a compact footprint,
  /// with the reference's sample positions (pixel and lens centre for spp = 1, else
  /// Pcg32::forKey(pixel, k, seed)). Writes rays[n], weight[n] (camera weight) and, per
  /// pixel, pixel[q] = y·width + x; returns the number of samples n. The arrays must hold
  /// (x1 − x0)·(y1 − y0)·spp samples.
  static size_t tileCameraRays(const Camera& camera, int spp, uint64_t seed, int x0, int y0, int x1, int y1, Ray* rays,
                               float* weight, uint32_t* pixel);

  /// Primary rays alone: exactly render()'s first pass — the same tiles in parallel, the same
  /// per-thread scratch, tileCameraRays and Accel::intersectCoherent — and no shading. Writes
  /// the hit distance of each pixel's last sample (∞ for a miss) to depth[y·width + x] so that
  /// nothing is optimised away. This is the floor of the design (the renderer casts these rays,
  /// then looks the light field up): `render --stats` (primary_ms_median) and realtime_bench
  /// time it next to render().
  void castPrimaryRays(const Camera& camera, const RenderSettings& settings, std::vector<float>& depth) const;

  const LightField& lightField() const { return lightField_; }
  const Accel& accel() const { return accel_; }

 private:
  struct Scratch;
  /// The camera rays of the tile's samples into scratch.rays/weight/pixel and their hits into
  /// scratch.hits (buffers sized for the tile); returns the number of samples.
  size_t tilePrimaryHits(const Camera& camera, int spp, uint64_t seed, int x0, int y0, int x1, int y1,
                         Scratch& scratch) const;
  /// render()'s tiling: tile(x0, y0, x1, y1, scratch) for every settings.tileSize tile of the
  /// image, tiles in parallel, each thread with its own Scratch.
  template <typename Tile>
  void forEachTile(const Camera& camera, const RenderSettings& settings, Tile&& tile) const;
  /// coneSpread: textureConeSpread of the camera and settings (0 = albedo at full resolution).
  void renderTile(const Camera& camera, int spp, uint32_t mirrorDepth, float coneSpread, uint64_t seed, int x0, int y0,
                  int x1, int y1, Scratch& scratch, Image& image) const;

  const LightField& lightField_;
  const Accel& accel_;
  SunLights sun_;                      ///< the sun masks' lights (the shading points at it)
  PunctualHighlights highlights_;      ///< the punctual lights' highlights on glossy charts (lightfield.h)
  MirrorLikeLights lobeLights_;        ///< the emitters sampled at mirror-like lobes (lookup.h)
  std::vector<ChartShading> shading_;  ///< per chart
  bool anyTexturedChart_ = false;      ///< some chart's shading needsUv: renderTile prefetches texels
  /// Values and chart records take more than the constructor's prefetchLookupBytes:
  /// renderTile prefetches each tile's chart records and value rows before shading it.
  bool prefetchLookups_ = false;
  /// The light field's values padded to 16 bytes (PaddedValues): one aligned load per tap.
  std::vector<Lanes4> paddedValues_;
  /// LightField::triangleChart flattened: chart of triangle t of mesh m at
  /// triangleChart_[meshFirstTriangle_[m] + t] (one dependent load less per pixel).
  std::vector<uint32_t> meshFirstTriangle_, triangleChart_;
};

}  // namespace pl
