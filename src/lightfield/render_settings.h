#pragma once
// What a light-field renderer is asked to do, and the two rules that turn a request into
// numbers: samples per pixel and mirror depth. Shared by the reference renderer (render/), the
// fast renderer (realtime/), the viewer and the library jobs (jobs/), which must all agree: one
// home for both rules.
#include <cmath>
#include <cstdint>

#include "core/error.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/sampler.h"

namespace pl {

struct Environment;
struct LightField;

struct RenderSettings {
  /// Camera samples per pixel; 0 = automatic: 1 (pixel centre) for a pinhole camera,
  /// kThinLensSamples for a thin lens (its defocus blur needs several aperture samples).
  int samplesPerPixel = 0;
  static constexpr int kThinLensSamples = 16;
  static constexpr int kMaxSamplesPerPixel = 1 << 16;  ///< upper bound the commands accept
  /// Mirror reflections followed; -1 = the bake's own BakeSettings::mirrorDepth, so the
  /// render sees exactly the chains the propagation accounted for.
  int mirrorDepth = -1;
  static constexpr int kMaxMirrorDepth = 1000;  ///< upper bound the commands accept
  uint64_t seed = 0;
  int tileSize = 16;  ///< square tiles rendered in parallel
  bool showProgress = false;  ///< progress bar (for single large renders, not timing loops)
  /// Texture level of detail: diffuse albedo textures are read at the mip level of each
  /// sample's ray cone (lookup.h albedoTextureLod, textureConeSpread below) instead of at full
  /// resolution. `render`/`view` --texture-lod on|off.
  bool textureLod = true;
};

/// What both renderers refuse before allocating anything: samples per pixel outside
/// 0..kMaxSamplesPerPixel, a mirror depth outside −1..kMaxMirrorDepth, a tile size below 1
/// (the commands' flag ranges, so a library caller gets the same bounds).
inline void checkRenderSettings(const RenderSettings& settings) {
  if (settings.samplesPerPixel < 0 || settings.samplesPerPixel > RenderSettings::kMaxSamplesPerPixel)
    failUsage("render: {} samples per pixel is out of range (0..{})", settings.samplesPerPixel,
         RenderSettings::kMaxSamplesPerPixel);
  if (settings.mirrorDepth < -1 || settings.mirrorDepth > RenderSettings::kMaxMirrorDepth)
    failUsage("render: mirror depth {} is out of range (-1..{})", settings.mirrorDepth, RenderSettings::kMaxMirrorDepth);
  if (settings.tileSize < 1) failUsage("render: tile size must be ≥ 1, got {}", settings.tileSize);
}

/// The samples-per-pixel rule: settings.samplesPerPixel when > 0, else kThinLensSamples for a
/// thin-lens camera and 1 (the pixel centre) for a pinhole.
inline int effectiveSamplesPerPixel(const RenderSettings& settings, bool thinLens) {
  return settings.samplesPerPixel > 0 ? settings.samplesPerPixel : thinLens ? RenderSettings::kThinLensSamples : 1;
}

/// The film and lens points of the light-field renderers' camera samples when a pixel has
/// several: a ZSobol sequence (core/sampler.h) over the whole image — layout
/// ZSobolLayout(width, height, spp, seed) — the film point from dimension 0 and the lens point
/// from dimension 1, as the path tracer draws its own (trace/path_tracer.cpp kFilmDimension,
/// kLensDimension). A pixel's 2^k samples are therefore stratified over its area and over the
/// aperture (every elementary interval of area 2^-k holds one), so a 16-sample render of a
/// small bright emitter — seen directly or through mirrors and glass, whose chains are a
/// deterministic function of the film point — converges as the path tracer's does instead of
/// with the 1/√n noise of independent points. pixelSample is sample k (< 2^layout.log2Spp())
/// of pixel (x, y): film in pixel units, lens in [0, 1)². The reference and the fast renderer
/// take their samples from here; the GPU renderer's shader is a GLSL copy (gpu_renderer.cpp
/// "ZSobol"), checked against them by gpu_test.
inline void pixelSample(const ZSobolLayout& layout, int x, int y, int k, Vec2& film, Vec2& lens) {
  Sampler sampler = Sampler::sobol(layout, x, y, uint64_t(k));
  sampler.setDimension(0);
  film = Vec2(float(x), float(y)) + sampler.get2D();
  sampler.setDimension(1);
  lens = sampler.get2D();
}

/// The mirror-depth rule: settings.mirrorDepth when ≥ 0, else the bake's own
/// (bakeMirrorDepth = LightField::settings.mirrorDepth).
inline uint32_t effectiveMirrorDepth(const RenderSettings& settings, uint32_t bakeMirrorDepth) {
  return settings.mirrorDepth >= 0 ? uint32_t(settings.mirrorDepth) : bakeMirrorDepth;
}

/// The ray-cone spread of a camera sample (Ray Tracing Gems ch. 20): the cone's width, in
/// scene units, at distance t along the ray (summed over the segments of a mirror/glass chain)
/// is textureConeSpread × t. pixelSpread is the camera's (Camera::pixelSpread: a pixel's height
/// on the image plane at unit distance, 2·tan(fovY/2) / height — exactly a pixel's footprint at
/// the image centre). spp samples per pixel share a pixel's area, so each cone is 1/√spp of the
/// pixel wide (the samples integrate the rest of the footprint). Planar mirrors and glass
/// keep the spread (the width grows with the total distance); the curvature of curved
/// mirrors or glass, which would widen or narrow the cone, is not modelled. 0 with
/// textureLod off: every level is then −∞, i.e. full resolution.
inline float textureConeSpread(const RenderSettings& settings, float pixelSpread, int spp) {
  return settings.textureLod ? pixelSpread / std::sqrt(float(spp)) : 0.0f;
}

/// Radiance from infinity towards −direction for a ray leaving the scene along `direction`.
/// The only place the renderers read the environment (an environment map plugs in here).
Rgb backgroundRadiance(const Environment& environment, const Vec3& direction);

}  // namespace pl
