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
#include <cstdint>
#include <vector>

#include "image/image.h"
#include "image/tonemap.h"

namespace pl {

class DisplayEncoder {
 public:
  static constexpr int kSrgbTableSize = 16384;
  static constexpr int kStatisticsStride = 4;
  DisplayEncoder();

  /// exposed = radiance · exposureScale, the tone curve resolved from its subsample with
  /// `settings`, and 8-bit pixels written as 32-bit words
  /// 0xFFRRGGBB (SDL_PIXELFORMAT_ARGB8888 / XRGB8888) into `pixels` with `pitchBytes` per row.
  /// Non-finite pixels are magenta, as in tonemap.h.
  void encode(const Image& radiance, float exposureScale, const ToneMapSettings& settings, uint32_t* pixels,
              int pitchBytes);

  const ToneMapCurve& curve() const { return curve_; }

 private:
  std::vector<uint8_t> srgbTable_;
  Image statistics_;  ///< the exposed subsample the curve is resolved from
  ToneMapCurve curve_;
};

}  // namespace pl
