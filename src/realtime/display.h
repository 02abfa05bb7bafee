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
// next to a rounding boundary. Files (screenshots, render output) use the exact toneMap().
#include <cstdint>
#include <vector>

#include "image/image.h"
#include "image/tonemap.h"

namespace pl {

class DisplayEncoder {
 public:
  static constexpr int kSrgbTableSize = 16384;
  DisplayEncoder();

  /// exposed = radiance · exposureScale (kept in `exposed()` for screenshots), the tone curve
  /// resolved from it with `settings`, and 8-bit pixels written as 32-bit words
  /// 0xFFRRGGBB (SDL_PIXELFORMAT_ARGB8888 / XRGB8888) into `pixels` with `pitchBytes` per row.
  /// Non-finite pixels are magenta, as in tonemap.h.
  void encode(const Image& radiance, float exposureScale, const ToneMapSettings& settings, uint32_t* pixels,
              int pitchBytes);

  const Image& exposed() const { return exposed_; }
  const ToneMapCurve& curve() const { return curve_; }

 private:
  std::vector<uint8_t> srgbTable_;
  Image exposed_;
  ToneMapCurve curve_;
};

}  // namespace pl
