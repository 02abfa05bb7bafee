#pragma once
// Turning a radiance frame into display pixels every frame: exposure (camera/exposure.h
// gives the scale), the shared tone-mapping curve (image/tonemap.h: resolveToneMap +
// ToneMapCurve::apply) and sRGB encoding, in parallel over rows.
//
// The sRGB step goes through a table of kSrgbTableSize entries of linearToSrgb (the shared
// transfer function) instead of a pow() per channel: display value v ∈ [0, 1] is looked up
// at round(v·(N−1)). The steepest part of the sRGB curve (slope 12.92 below 0.0031308) moves
// by 12.92·255/(N−1) ≈ 0.2 of an 8-bit level per table step for N = 16384, so a displayed
// pixel differs from encodeSrgb8 by at most one level, and only where the exact value sits
// next to a rounding boundary.
//
// The tone curve's statistics (Reinhard's log-average, the automatic key's percentiles) are
// computed by the shared resolveToneMap on every kStatisticsStride-th pixel in x and y (1/16
// of the pixels): for the smooth images of a light field the log-average of the subsample is
// within about 1 % of the full one, invisible on screen, and it keeps the single-threaded
// statistics pass off the frame time. Files (screenshots, render output) use the exact
// toneMap() on the full image.
//
// The GPU renderer's display pass (gpu/gpu_display.h) does the per-pixel part on the GPU: the
// subsample's log-average summed there (or, for the automatic key, the subsample read back),
// the curve resolved here (resolveCurve), then word() for every pixel in GLSL with this table,
// so that the viewer reads back at most 4 bytes per pixel and tone-maps nothing.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "image/image.h"
#include "image/tonemap.h"

namespace pl {

class DisplayEncoder {
 public:
  static constexpr int kSrgbTableSize = 16384;
  static constexpr int kStatisticsStride = 4;
  /// The words of a non-finite pixel: magenta, as encodeSrgb8.
  static constexpr uint32_t kNonFiniteWord = 0xFFFF00FFu;
  DisplayEncoder();

  /// exposed = radiance · exposureScale, the tone curve resolved from its subsample with
  /// `settings` (resolveCurve), and 8-bit pixels written as 32-bit words
  /// 0xFFRRGGBB (SDL_PIXELFORMAT_ARGB8888 / XRGB8888) into `pixels` with `pitchBytes` per row
  /// (word()). Non-finite pixels are magenta, as in tonemap.h.
  void encode(const Image& radiance, float exposureScale, const ToneMapSettings& settings, uint32_t* pixels,
              int pitchBytes);

  /// The subsample the curve is resolved from, per axis: ceil(size / kStatisticsStride) pixels,
  /// the radiance at (x·kStatisticsStride, y·kStatisticsStride).
  static int statisticsSize(int size) { return (size + kStatisticsStride - 1) / kStatisticsStride; }
  /// The curve of a frame from its radiance subsample (statisticsSize × statisticsSize of the
  /// frame, unexposed) and the exposure: what encode() applies, and what the GPU renderer's
  /// display pass takes (GpuRenderer::encodeDisplay).
  const ToneMapCurve& resolveCurve(const Image& radianceSubsample, float exposureScale, const ToneMapSettings& settings);
  /// The same from the exposed subsample's log-average luminance, for settings that need no
  /// more (toneMapStatistics; unused where they need none): the GPU's display pass sums it
  /// where the frame is and reads back only its partial sums.
  const ToneMapCurve& resolveCurve(float exposedLogAverage, const ToneMapSettings& settings) {
    curve_ = resolveToneMap(exposedLogAverage, settings);
    return curve_;
  }

  /// One exposed pixel's word through `curve`, the table and the rounding above.
  uint32_t word(const ToneMapCurve& curve, const Rgb& exposed) const {
    const Rgb d = curve.apply(exposed);
    if (!isFinite(d)) return kNonFiniteWord;
    return 0xFF000000u | (channel(d.r) << 16) | (channel(d.g) << 8) | channel(d.b);
  }
  /// The display value v ∈ [0, 1] (clamped) → its table index round(v·(N−1)).
  static uint32_t tableIndex(float v) { return uint32_t(std::clamp(v, 0.0f, 1.0f) * float(kSrgbTableSize - 1) + 0.5f); }
  /// The 8-bit sRGB levels of the table's entries.
  const std::vector<uint8_t>& srgbTable() const { return srgbTable_; }

  const ToneMapCurve& curve() const { return curve_; }

 private:
  uint32_t channel(float v) const { return srgbTable_[tableIndex(v)]; }

  std::vector<uint8_t> srgbTable_;
  Image subsample_;    ///< encode()'s radiance subsample (kept: one allocation per frame size)
  Image statistics_;  ///< the exposed subsample the curve is resolved from
  ToneMapCurve curve_;
};

}  // namespace pl
