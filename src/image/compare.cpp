// Image comparison metrics and the relative-error heat map (definitions in compare.h).
#include "image/compare.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace pl {
namespace {

void checkSameSize(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    fail("image sizes differ: A is {}x{}, B (reference) is {}x{}", a.width, a.height, b.width, b.height);
}

/// Google's Turbo colour map (Mikhailov 2019), the published degree-5 polynomial fit; t ∈ [0,1].
/// Returns sRGB-encoded components in [0, 1].
Rgb turbo(float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  const float t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  const float r = 0.13572138f + 4.61539260f * t - 42.66032258f * t2 + 132.13108234f * t3 - 152.94239396f * t4 +
                  59.28637943f * t5;
  const float g = 0.09140261f + 2.19418839f * t + 4.84296658f * t2 - 14.18503333f * t3 + 4.27729857f * t4 +
                  2.82956604f * t5;
  const float b = 0.10667330f + 12.64194608f * t - 60.58204836f * t2 + 110.36276771f * t3 - 89.90310912f * t4 +
                  27.34824973f * t5;
  return glm::clamp(Rgb(r, g, b), Rgb(0.0f), Rgb(1.0f));
}

}  // namespace

ImageComparison compareImages(const Image& a, const Image& reference, double peak) {
  checkSameSize(a, reference);
  if (!(peak > 0.0)) fail("PSNR peak {} must be positive", peak);
  ImageComparison result;
  result.width = a.width;
  result.height = a.height;
  result.peak = peak;
  std::array<double, 3> sumSq{}, sumRel{}, sumA{}, sumB{};
  size_t n = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const Rgb& pa = a.at(x, y);
      const Rgb& pb = reference.at(x, y);
      if (!isFinite(pa) || !isFinite(pb)) {
        ++result.nonFinitePixels;
        continue;
      }
      ++n;
      for (int c = 0; c < 3; ++c) {
        const double d = double(pa[c]) - double(pb[c]);
        sumSq[size_t(c)] += d * d;
        sumRel[size_t(c)] += d * d / (double(pb[c]) * double(pb[c]) + kRelMseEpsilon);
        sumA[size_t(c)] += pa[c];
        sumB[size_t(c)] += pb[c];
        if (std::abs(d) > result.maxAbsError) {
          result.maxAbsError = std::abs(d);
          result.maxErrorX = x;
          result.maxErrorY = y;
        }
      }
    }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double mseAll = 0.0, relAll = 0.0;
  for (size_t c = 0; c < 3; ++c) {
    result.mse[c] = n ? sumSq[c] / double(n) : nan;
    result.relMse[c] = n ? sumRel[c] / double(n) : nan;
    result.meanRatio[c] = n ? sumA[c] / sumB[c] : nan;  // x/0 → ±∞ or NaN, reported as such
    mseAll += result.mse[c] / 3.0;
    relAll += result.relMse[c] / 3.0;
  }
  // Rec.709 weights, as luminance() in core/math.h, applied to the per-channel sums.
  const double weights[3] = {0.2126, 0.7152, 0.0722};
  double lumA = 0.0, lumB = 0.0;
  for (size_t c = 0; c < 3; ++c) {
    lumA += weights[c] * sumA[c];
    lumB += weights[c] * sumB[c];
  }
  result.meanLuminanceRatio = n ? lumA / lumB : nan;
  result.rmse = std::sqrt(mseAll);
  result.relMseAverage = relAll;
  result.psnr = mseAll > 0.0 ? 10.0 * std::log10(peak * peak / mseAll)
                             : (n ? std::numeric_limits<double>::infinity() : nan);
  return result;
}

Image8 relativeErrorHeatmap(const Image& a, const Image& reference, float maxError) {
  checkSameSize(a, reference);
  if (!(maxError > 0.0f)) fail("heat map scale {} must be positive", maxError);
  Image8 out{a.width, a.height, std::vector<uint8_t>(a.pixels.size() * 3)};
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const Rgb& pa = a.pixels[i];
    const Rgb& pb = reference.pixels[i];
    uint8_t* dst = &out.rgb[3 * i];
    if (!isFinite(pa) || !isFinite(pb)) {
      dst[0] = 255, dst[1] = 0, dst[2] = 255;
      continue;
    }
    double rel = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double d = double(pa[c]) - double(pb[c]);
      rel += d * d / (double(pb[c]) * double(pb[c]) + kRelMseEpsilon) / 3.0;
    }
    const Rgb colour = turbo(float(std::sqrt(rel)) / maxError);
    for (int c = 0; c < 3; ++c) dst[c] = uint8_t(std::lround(colour[c] * 255.0f));
  }
  return out;
}

std::string comparisonJson(const ImageComparison& c) {
  // nlohmann::json writes NaN and ±∞ as null.
  nlohmann::json j;
  j["width"] = c.width;
  j["height"] = c.height;
  j["rmse"] = c.rmse;
  j["relmse"] = c.relMseAverage;
  j["relmse_rgb"] = c.relMse;
  j["mse_rgb"] = c.mse;
  j["psnr"] = c.psnr;
  j["psnr_peak"] = c.peak;
  j["identical"] = c.rmse == 0.0 && c.nonFinitePixels == 0;
  j["mean_ratio_rgb"] = c.meanRatio;
  j["mean_luminance_ratio"] = c.meanLuminanceRatio;  // Rec.709 Y, mean A / mean B
  j["max_abs_error"] = c.maxAbsError;
  j["max_abs_error_pixel"] = {c.maxErrorX, c.maxErrorY};
  j["nonfinite_pixels"] = c.nonFinitePixels;
  return j.dump();
}

}  // namespace pl
