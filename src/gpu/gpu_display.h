#pragma once
// The viewer's display pass on the GPU: the radiance image of a frame turned into the 8-bit
// words a window shows, where it was rendered, so that the viewer reads back 4 bytes per pixel
// (instead of 12 of float radiance) and spends no CPU time on tone mapping.
//
// DisplayEncoder (image/display.h) stays the one definition of what a pixel becomes: the
// curve is resolved there, on the CPU (resolveToneMap), from the statistics of the frame's
// radiance subsample (every kStatisticsStride-th pixel per axis). Reinhard's key needs only
// the subsample's log-average (eq. 1): the log sum program sums its terms per run of 64
// subsample pixels along a row, and only those partial sums come back (8 bytes per run,
// 17 KiB at 1920 × 1080, where the subsample is 2 MB), to be added in double and resolved on
// the CPU; the automatic key's percentiles need every luminance, so there the statistics
// program's subsample comes back whole (16 bytes per subsample pixel); linear, clamp and
// Reinhard without a key read nothing. The GLSL below is DisplayEncoder::word statement for
// statement — ToneMapCurve::apply (tonemap.cpp: Reinhard through Rec.709 YUV, linear, the
// hue-preserving clamp), the non-finite check (magenta), the table index round(v·(N−1)) and
// DisplayEncoder's sRGB table, uploaded as it is — and logLuminanceTerm.
// GpuRenderer::displayWords and logLuminanceTerms run that GLSL on given pixels
// (kDisplayQueriesCompute), and gpu_test holds them to DisplayEncoder::word and tonemap.h's
// logLuminanceTerm on random inputs (NaN, ±∞ and values far outside [0, 1] among them).
#include <cstdint>
#include <string>

#include "image/tonemap.h"

namespace pl::gpu {

/// Shader storage bindings of the display programs: the words written, DisplayEncoder's
/// table (one uint per entry), the radiance subsample (vec4 per pixel).
inline constexpr uint32_t kDisplayWordsBinding = 26, kSrgbTableBinding = 27, kDisplayStatisticsBinding = 28;
/// The image unit of the accumulated frames (the refinement of a still view; the frame's
/// radiance is at the renderer's radiance unit).
inline constexpr uint32_t kAccumulationImageUnit = 2;

/// The log sum's runs: one invocation sums kLogSumRun subsample pixels of a row.
inline constexpr int kLogSumRun = 64;
/// The partial sums of eq. 1 (tonemap.h) of one run, as the statistics buffer holds them
/// (std430): the sum of logLuminanceTerm over its finite pixels, and their count.
struct LogSum {
  float sum;
  uint32_t count;
};
/// The runs over a frame of `width` × `height` (its subsample: statisticsSize per axis).
int logSumRuns(int width, int height);

/// Texture units of the present pass: the frame's words (as RGBA8), the overlay (the HUD).
inline constexpr uint32_t kPresentFrameUnit = 2, kPresentOverlayUnit = 3;

/// The #defines and constants the display GLSL needs (bindings, the radiance image unit, the
/// table size and stride, the operators' numbers, the non-finite word).
std::string displayGlslConstants(uint32_t radianceImageUnit);

/// GLSL: uniforms toneOperator, luminanceScale, whiteScaled, whiteInfinite; the SRGB table;
///   vec3 toneCurve(vec3 exposed) — ToneMapCurve::apply for finite input;
///   uint displayWord(vec3 exposed) — DisplayEncoder::word;
///   float logLuminanceTerm(vec3 exposed) — tonemap.h's, in float, for a finite pixel.
extern const char* const kDisplayGlsl;
/// Compute programs (8 × 8 groups) over a frame of uniform `size`, reading the image at the
/// radiance unit — a frame's radiance, or the sum of several (accumulate) — as shown = image ·
/// weight (1, or 1 / the frames summed, as the viewer averages its refinement batches):
///   statistics: shown at every stride-th pixel into the statistics buffer (row-major,
///     statisticsSize(width) per row): what the automatic key's percentiles are taken from;
///   log sum (64 invocations to a group; one per run of kLogSumRun subsample pixels along a
///     row): the LogSum of each run's shown · exposureScale into the statistics buffer (runs
///     row-major): what Reinhard's key needs, summed on the CPU in double (8 bytes read back
///     per run, no pixel);
///   encode: displayWord(shown · exposureScale) of every pixel into the words buffer, row y
///     at y · width (the image's rows, top first, as render() reads them back);
///   accumulate: the accumulation image = the frame (restart) or itself + the frame.
extern const char* const kDisplayStatisticsCompute;
extern const char* const kDisplayLogSumCompute;
extern const char* const kDisplayEncodeCompute;
extern const char* const kAccumulateCompute;
/// A query program's body (after the renderer's query head): for each query's exposed colour
/// (vec4 in) two uints out, its displayWord and the bits of its logLuminanceTerm (NaN for a
/// non-finite colour, which the log sum leaves out).
extern const char* const kDisplayQueriesCompute;

/// The present pass (GpuRenderer::present), a full-screen triangle drawn into the window:
///   vertex: the triangle from gl_VertexID alone (no vertex buffer);
///   fragment: window pixel p (row 0 at the top, as the frame's and the overlay's rows) shows
///     the frame's word p where the frame is the window's size — read from the display pass's
///     words buffer where it is that frame (wordsInBuffer: no copy), else the frame texture's
///     texel (texelFetch) — and else the frame texture stretched over the window, bilinear (as
///     SDL's renderer with SDL_HINT_RENDER_SCALE_QUALITY "linear" shows a frame rendered below
///     the window's size);
///     and over it, where p is inside the overlay (its top-left corner at the window's), the
///     overlay's texel blended by its alpha, c = o·a + c·(1 − a) (SDL_BLENDMODE_BLEND).
/// Uniforms: windowSize, frameSize, overlaySize (0 × 0: none), wordsInBuffer.
extern const char* const kPresentVertex;
extern const char* const kPresentFragment;

/// Sets `program`'s curve uniforms from `curve`.
void setToneCurveUniforms(uint32_t program, const ToneMapCurve& curve);

}  // namespace pl::gpu
