#pragma once
// The viewer's display pass on the GPU: the radiance image of a frame turned into the 8-bit
// words a window shows, where it was rendered, so that the viewer reads back 4 bytes per pixel
// (instead of 12 of float radiance) and spends no CPU time on tone mapping.
//
// DisplayEncoder (image/display.h) stays the one definition of what a pixel becomes: the
// curve is resolved there, on the CPU, from the frame's radiance subsample (every
// kStatisticsStride-th pixel per axis, read back by the statistics program), and the GLSL
// below is DisplayEncoder::word statement for statement — ToneMapCurve::apply (tonemap.cpp:
// Reinhard through Rec.709 YUV, linear, the hue-preserving clamp), the non-finite check
// (magenta), the table index round(v·(N−1)) and DisplayEncoder's sRGB table, uploaded as it
// is. GpuRenderer::displayWords runs that GLSL on given pixels, and gpu_test holds it to
// DisplayEncoder::word on random inputs (NaN, ±∞ and values far outside [0, 1] among them).
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

/// Texture units of the present pass: the frame's words (as RGBA8), the overlay (the HUD).
inline constexpr uint32_t kPresentFrameUnit = 2, kPresentOverlayUnit = 3;

/// The #defines and constants the display GLSL needs (bindings, the radiance image unit, the
/// table size and stride, the operators' numbers, the non-finite word).
std::string displayGlslConstants(uint32_t radianceImageUnit);

/// GLSL: uniforms toneOperator, luminanceScale, whiteScaled, whiteInfinite; the SRGB table;
///   vec3 toneCurve(vec3 exposed) — ToneMapCurve::apply for finite input;
///   uint displayWord(vec3 exposed) — DisplayEncoder::word.
extern const char* const kDisplayGlsl;
/// Compute programs (8 × 8 groups) over a frame of uniform `size`, reading the image at the
/// radiance unit — a frame's radiance, or the sum of several (accumulate) — as shown = image ·
/// weight (1, or 1 / the frames summed, as the viewer averages its refinement batches):
///   statistics: shown at every stride-th pixel into the statistics buffer (row-major,
///     statisticsSize(width) per row);
///   encode: displayWord(shown · exposureScale) of every pixel into the words buffer, row y
///     at y · width (the image's rows, top first, as render() reads them back);
///   accumulate: the accumulation image = the frame (restart) or itself + the frame.
extern const char* const kDisplayStatisticsCompute;
extern const char* const kDisplayEncodeCompute;
extern const char* const kAccumulateCompute;
/// A query program's body (after the renderer's query head): displayWord of each query's
/// exposed colour (vec4 in, one uint out).
extern const char* const kDisplayWordsCompute;

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
