#pragma once
// Error figures between a test image A and a reference image B (same size), over the finite
// pixels of both (pixels where either is NaN/Inf are counted in nonFinitePixels and left out
// of every figure, so one NaN does not hide the rest; a non-zero count is itself a failure
// sign). With n = number of finite pixels and c ∈ {R, G, B}:
//
//   mse_c     = mean (a − b)²                       rmse = sqrt(mean over c of mse_c)
//   relMse_c  = mean (a − b)² / (b² + 0.01)         relMse = mean over c of relMse_c
//   psnr      = 10 · log10(peak² / mean over c of mse_c), in dB; +∞ when the images agree.
//               The peak is 1.0 by default for HDR images (radiance has no natural maximum;
//               1 is "white" after exposure), settable.
//   meanRatio_c = mean a_c / mean b_c (1 = same average brightness; ∞ or NaN if mean b_c = 0)
//   meanLuminanceRatio = mean Y(a) / mean Y(b), Y = 0.2126 R + 0.7152 G + 0.0722 B (Rec.709
//               relative luminance, core/math.h); luminance is linear, so this equals
//               Σ_c w_c·mean a_c / Σ_c w_c·mean b_c (not the weighted sum of the ratios)
//   maxAbsError = max |a − b| over pixels and channels, at maxErrorX/Y
// relMse's 0.01 keeps the figure finite where the reference is black (Rousselle et al. 2011).
#include <array>
#include <string>

#include "image/image.h"

namespace pl {

struct ImageComparison {
  int width = 0, height = 0;
  size_t nonFinitePixels = 0;
  std::array<double, 3> mse{}, relMse{}, meanRatio{};
  double meanLuminanceRatio = 0.0;
  double rmse = 0.0, relMseAverage = 0.0, psnr = 0.0, peak = 1.0;
  double maxAbsError = 0.0;
  int maxErrorX = 0, maxErrorY = 0;
};

inline constexpr double kRelMseEpsilon = 0.01;

/// Throws pl::Error "image sizes differ: A is W×H, B (reference) is W×H" on a size mismatch
/// (the caller prefixes file names).
ImageComparison compareImages(const Image& a, const Image& reference, double peak = 1.0);

/// The figures as the text of a JSON object — their one naming, which `plenoptic compare
/// --json` prints (adding the file names "a" and "b") and the Python module's compare()
/// returns as a dict: width, height, rmse, relmse, relmse_rgb, mse_rgb, psnr, psnr_peak,
/// identical, mean_ratio_rgb, mean_luminance_ratio, max_abs_error, max_abs_error_pixel
/// ([x, y]), nonfinite_pixels. JSON has no infinity: an infinite or undefined figure (the PSNR
/// of identical images, a ratio against a black channel) is null.
std::string comparisonJson(const ImageComparison& c);

/// Per-pixel relative RMS error e = sqrt(mean over c of (a − b)²/(b² + 0.01)) as a false-colour
/// image (Google "Turbo" colour map: dark blue = 0, green ≈ max/2, dark red = max; values at
/// or above `maxError` saturate); pixels non-finite in either image are magenta.
Image8 relativeErrorHeatmap(const Image& a, const Image& reference, float maxError = 1.0f);

}  // namespace pl
