// Variance-aware comparison of two Monte Carlo images (see trace.h).
#include <fmt/format.h>

#include <cmath>

#include "core/error.h"
#include "trace/trace.h"

namespace pl {

double twoSidedNormalQuantile(double p) {
  if (!(p > 0.0 && p < 1.0)) fail("two-sided normal quantile needs 0 < p < 1 (got {})", p);
  // P(|Z| > z) = erfc(z / √2) decreases monotonically in z: bisect on [0, 40]
  // (erfc(40/√2) ≈ 1e-350 underflows to 0, below any p we accept).
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > p)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

std::string ImageZTest::summary() const {
  return fmt::format(
      "{}: max |z| = {:.3f} at ({}, {}) channel {} (limit {:.3f} over {} tests), whole-image z = {:.3f} in channel {} "
      "(limit {:.3f}), mean z² = {:.3f}",
      pass ? "consistent" : "DIFFERENT", maxAbsZ, worstX, worstY, worstChannel, pixelThreshold, tests, globalZ,
      globalChannel, globalThreshold, meanSquaredZ);
}

ImageZTest compareImagesZ(const Image& a, const Image& varianceA, const Image& b, const Image& varianceB,
                          double alpha) {
  const auto sameSize = [](const Image& x, const Image& y) { return x.width == y.width && x.height == y.height; };
  if (!sameSize(a, b) || !sameSize(a, varianceA) || !sameSize(b, varianceB))
    fail("image comparison needs equal sizes (got {}x{} vs {}x{}, variances {}x{} and {}x{})", a.width, a.height,
         b.width, b.height, varianceA.width, varianceA.height, varianceB.width, varianceB.height);
  if (a.empty()) fail("image comparison of empty images");
  if (!(alpha > 0.0 && alpha < 1.0)) fail("significance level must be in (0, 1) (got {})", alpha);

  ImageZTest r;
  r.tests = a.pixels.size() * 3;
  // Šidák: with N independent tests each at level α₁, P(no false rejection) = (1 − α₁)^N;
  // setting that to 1 − α/2 gives α₁ = 1 − (1 − α/2)^(1/N). expm1/log1p keep it accurate
  // for tiny α₁.
  const double perTest = -std::expm1(std::log1p(-0.5 * alpha) / static_cast<double>(r.tests));
  r.pixelThreshold = twoSidedNormalQuantile(perTest);
  // One whole-image test per channel (the channels of one pixel are correlated: they come
  // from the same paths, so they cannot be pooled into one sum), Bonferroni over the three.
  r.globalThreshold = twoSidedNormalQuantile(0.5 * alpha / 3.0);

  double sumSquaredZ = 0.0;
  double sumA[3] = {0.0, 0.0, 0.0}, sumB[3] = {0.0, 0.0, 0.0}, sumVariance[3] = {0.0, 0.0, 0.0};
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double va = a.at(x, y)[c], vb = b.at(x, y)[c];
        const double floor = 1e-6 * std::max(std::abs(va), std::abs(vb));
        const double variance = double(varianceA.at(x, y)[c]) + double(varianceB.at(x, y)[c]);
        const double difference = va - vb;
        const double denominator = std::sqrt(variance + floor * floor);
        // Zero variance and a real difference: infinitely significant. 0/0 (both exactly 0,
        // e.g. a pixel seeing only black background) is no evidence of a difference.
        double z = 0.0;
        if (denominator > 0.0)
          z = difference / denominator;
        else if (difference != 0.0 || std::isnan(difference))
          z = INFINITY;
        if (std::isnan(z)) z = INFINITY;  // NaN pixels are never "consistent"
        sumSquaredZ += z * z;
        if (std::abs(z) > r.maxAbsZ || r.worstX < 0) {
          r.maxAbsZ = std::abs(z);
          r.worstX = x;
          r.worstY = y;
          r.worstChannel = c;
        }
        sumA[c] += va;
        sumB[c] += vb;
        sumVariance[c] += variance;
      }
    }
  }
  r.meanSquaredZ = sumSquaredZ / static_cast<double>(r.tests);
  for (int c = 0; c < 3; ++c) {
    const double floor = 1e-6 * std::max(std::abs(sumA[c]), std::abs(sumB[c]));
    const double denominator = std::sqrt(sumVariance[c] + floor * floor);
    double z = denominator > 0.0 ? (sumA[c] - sumB[c]) / denominator : (sumA[c] == sumB[c] ? 0.0 : INFINITY);
    if (std::isnan(z)) z = INFINITY;
    if (std::abs(z) > std::abs(r.globalZ) || c == 0) {
      r.globalZ = z;
      r.globalChannel = c;
    }
  }
  r.pass = r.maxAbsZ <= r.pixelThreshold && std::abs(r.globalZ) <= r.globalThreshold;
  return r;
}

}  // namespace pl
