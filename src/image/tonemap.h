#pragma once
// Tone mapping: exposed linear radiance (Image) → display values in [0, 1] → 8-bit sRGB.
//
// Input is what the camera recorded: radiance × exposure scale (camera/exposure.h). Three
// global operators, chosen by name:
//
//  reinhard  Reinhard et al. 2002, "Photographic Tone Reproduction for Digital Images",
//            applied to luminance Y (Rec.709 weights) through YUV:
//              L̄w = exp(mean(log(δ + Lw)))                          (eq. 1, δ = 1e-4)
//              L  = (a / L̄w) · Lw          when a key a is set        (eq. 2)
//              L  = Lw                      when no key is set (exposure already chosen)
//              Ld = L · (1 + L / Lwhite²) / (1 + L)                   (eq. 4; eq. 3 if no white)
//            where Lwhite is the white point expressed on the same scale as L, so the input
//            luminance `white` maps exactly to Ld = 1. The pixel goes RGB → YUV; Y is replaced
//            by Ld and U, V are scaled by the same factor Ld/Y so the chromaticity (U/Y, V/Y,
//            hence the ratios r:g:b) is unchanged; then YUV → RGB. Channels that still exceed 1
//            (saturated colours) are clipped by the 8-bit encoding.
//  linear    display = exposed / white (white defaults to 1), clipped per channel to [0, 1].
//  clamp     hue-preserving clamp: the exposed colour, divided by its largest component when
//            that exceeds 1 (so r:g:b is kept), negatives set to 0. No key, no white.
//
// Automatic key (Reinhard 2002, "Parameter Estimation for Photographic Tone Reproduction",
// JGT 7(1), eq. 1; also Reinhard et al. 2006 "HDR Imaging" §8.1.2):
//     a = 0.18 · 4^((2·log2 L̄w − log2 Lmin − log2 Lmax) / (log2 Lmax − log2 Lmin))
// with Lmin, Lmax the 1st and 99th percentiles of the non-zero luminances (robust against
// a few hot or black pixels); a = 0.18 for an image of a single luminance.
//
// Non-finite pixels (NaN, ±Inf) are never silently hidden: they are excluded from the image
// statistics and drawn magenta (255, 0, 255) in 8-bit output.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "image/image.h"

namespace pl {

enum class ToneMapOperator { Reinhard, Linear, Clamp };

/// "reinhard" | "linear" | "clamp" → operator; throws pl::Error listing the names otherwise.
ToneMapOperator parseToneMapOperator(const std::string& name);
const char* toneMapOperatorName(ToneMapOperator op);

inline constexpr float kDefaultKey = 0.18f;  ///< middle grey (Reinhard's "normal key")

struct ToneMapSettings {
  ToneMapOperator op = ToneMapOperator::Reinhard;
  /// Reinhard key a: when set, the image's log-average luminance is mapped to a (eq. 2).
  /// Unset: the input luminance is used as it is (the exposure was set by the camera).
  std::optional<float> key = kDefaultKey;
  bool autoKey = false;        ///< Reinhard: estimate a from the image (overrides key)
  std::optional<float> white;  ///< input luminance mapped to 1 (reinhard, linear)
};

/// The global operator resolved for one image (statistics computed), applicable to any pixel
/// (e.g. every radiance texture of a light field with the same curve).
struct ToneMapCurve {
  ToneMapOperator op = ToneMapOperator::Reinhard;
  float luminanceScale = 1.0f;  ///< reinhard: a / L̄w, or 1 without key; linear: 1/white
  float whiteScaled = kInfinity;  ///< reinhard: Lwhite on the scaled axis (∞ = eq. 3)

  /// Display value of one exposed pixel, linear, components in [0, 1] for finite input
  /// (reinhard may leave a saturated channel above 1 before clipping; this clips it).
  /// Non-finite input returns NaN components.
  Rgb apply(const Rgb& exposed) const;
};

/// Reinhard's δ in eq. 1 (absorbs black pixels).
inline constexpr float kLogAverageDelta = 1e-4f;
/// One finite pixel's term of eq. 1, ln(δ + max(0, Y)) (Y: luminance(), Rec.709 weights).
inline double logLuminanceTerm(const Rgb& exposed) {
  return std::log(double(kLogAverageDelta) + std::max(0.0, double(luminance(exposed))));
}
/// Reinhard eq. 1: exp(mean logLuminanceTerm) over finite pixels; 0 for an image without one.
float logAverageLuminance(const Image& image);
/// The automatic key estimate described above.
float automaticKey(const Image& image);

/// What resolveToneMap reads of the image for `settings`: nothing (linear, clamp, Reinhard
/// without a key), its log-average luminance (Reinhard with a key), or also its luminances'
/// percentiles (the automatic key).
enum class ToneMapStatistics { None, LogAverage, Percentiles };
ToneMapStatistics toneMapStatistics(const ToneMapSettings& settings);
/// Computes the statistics `settings` needs from `exposed` and returns the curve.
ToneMapCurve resolveToneMap(const Image& exposed, const ToneMapSettings& settings);
/// The same curve from the statistics already computed, for settings that need at most the
/// log-average (toneMapStatistics): `logAverage` is the exposed image's logAverageLuminance,
/// unused where none is needed. (The GPU's display pass sums eq. 1 where the frame is.)
ToneMapCurve resolveToneMap(float logAverage, const ToneMapSettings& settings);

/// Display values in [0, 1] → 8-bit sRGB (rounded to nearest). NaN components → magenta.
Image8 encodeSrgb8(const Image& display);
/// resolveToneMap + apply + encodeSrgb8.
Image8 toneMap(const Image& exposed, const ToneMapSettings& settings);

}  // namespace pl
