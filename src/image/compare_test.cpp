// Image comparison: zero error against itself, the expected figures for a known perturbation,
// refusal of different sizes, and the heat map.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "image/compare.h"

namespace pl {
namespace {

Image randomImage(int w, int h) {
  Image image(w, h);
  Pcg32 rng(11, 2);
  for (Rgb& p : image.pixels) p = Rgb(rng.uniform(), rng.uniform(), rng.uniform()) * 3.0f;
  return image;
}

TEST(Compare, ImageAgainstItselfHasNoError) {
  const Image image = randomImage(17, 9);
  const ImageComparison c = compareImages(image, image);
  EXPECT_EQ(c.rmse, 0.0);
  EXPECT_EQ(c.relMseAverage, 0.0);
  EXPECT_EQ(c.maxAbsError, 0.0);
  EXPECT_EQ(c.psnr, std::numeric_limits<double>::infinity());
  for (int ch = 0; ch < 3; ++ch) EXPECT_DOUBLE_EQ(c.meanRatio[size_t(ch)], 1.0);
  EXPECT_EQ(c.nonFinitePixels, 0u);
}

TEST(Compare, KnownPerturbationGivesTheExpectedFigures) {
  // Reference 0.5 everywhere; A adds 0.125 to red everywhere (exact in binary) and one pixel
  // of green is off by 1.5.
  const int w = 10, h = 10, n = w * h;
  const Image reference(w, h, Rgb(0.5f));
  Image a(w, h, Rgb(0.625f, 0.5f, 0.5f));
  a.at(3, 7).g = 2.0f;
  const ImageComparison c = compareImages(a, reference);
  const double mseR = 0.125 * 0.125, mseG = 1.5 * 1.5 / n;
  EXPECT_DOUBLE_EQ(c.mse[0], mseR);
  EXPECT_DOUBLE_EQ(c.mse[1], mseG);
  EXPECT_DOUBLE_EQ(c.mse[2], 0.0);
  // Double accumulation of 100 float-exact terms: 1e-12 relative.
  EXPECT_NEAR(c.rmse, std::sqrt((mseR + mseG) / 3.0), 1e-12);
  EXPECT_NEAR(c.relMse[0], mseR / (0.25 + 0.01), 1e-12);
  EXPECT_NEAR(c.relMse[1], mseG / (0.25 + 0.01), 1e-12);
  EXPECT_NEAR(c.relMseAverage, (mseR + mseG) / (0.26 * 3.0), 1e-12);
  EXPECT_NEAR(c.psnr, 10.0 * std::log10(1.0 / ((mseR + mseG) / 3.0)), 1e-9);
  EXPECT_NEAR(c.meanRatio[0], 1.25, 1e-12);
  EXPECT_NEAR(c.meanRatio[1], (0.5 * (n - 1) + 2.0) / (0.5 * n), 1e-12);
  EXPECT_DOUBLE_EQ(c.meanRatio[2], 1.0);
  // Mean luminance ratio: Σ w_c Σa_c / Σ w_c Σb_c with the Rec.709 weights.
  const double sumAR = 0.625 * n, sumAG = 0.5 * (n - 1) + 2.0, sumAB = 0.5 * n, sumB = 0.5 * n;
  EXPECT_NEAR(c.meanLuminanceRatio, (0.2126 * sumAR + 0.7152 * sumAG + 0.0722 * sumAB) / sumB, 1e-12);
  EXPECT_DOUBLE_EQ(c.maxAbsError, 1.5);
  EXPECT_EQ(c.maxErrorX, 3);
  EXPECT_EQ(c.maxErrorY, 7);
  // A different peak moves PSNR by 20·log10(peak).
  EXPECT_NEAR(compareImages(a, reference, 10.0).psnr, c.psnr + 20.0, 1e-9);
}

TEST(Compare, DifferentSizesAreRefusedWithBothSizes) {
  try {
    compareImages(Image(3, 2), Image(4, 2));
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("3x2"), std::string::npos) << message;
    EXPECT_NE(message.find("4x2"), std::string::npos) << message;
  }
  EXPECT_THROW(relativeErrorHeatmap(Image(3, 2), Image(2, 3)), Error);
}

TEST(Compare, MeanLuminanceRatioWeightsChannelMeansNotRatios) {
  // Reference (1, 0.25, 4): its luminance is 0.2126 + 0.7152/4 + 0.0722·4 = 0.6802. A doubles red
  // only: ratios (2, 1, 1), luminance 0.6802 + 0.2126 = 0.8928, ratio 0.8928/0.6802 ≈ 1.3126 —
  // not Σ w_c·ratio_c = 1.2126, which would ignore how bright each channel is.
  const Image reference(4, 2, Rgb(1.0f, 0.25f, 4.0f));
  const Image a(4, 2, Rgb(2.0f, 0.25f, 4.0f));
  const ImageComparison c = compareImages(a, reference);
  EXPECT_NEAR(c.meanLuminanceRatio, 0.8928 / 0.6802, 1e-9);  // exact inputs, double sums
  EXPECT_TRUE(std::isnan(compareImages(Image(2, 2, Rgb(0.0f)), Image(2, 2, Rgb(0.0f))).meanLuminanceRatio));
}

TEST(Compare, NonFinitePixelsAreCountedAndExcluded) {
  const Image reference(4, 4, Rgb(1.0f));
  Image a = reference;
  a.at(1, 1) = Rgb(std::nanf(""), 1.0f, 1.0f);
  a.at(2, 2) = Rgb(1.0f, std::numeric_limits<float>::infinity(), 1.0f);
  const ImageComparison c = compareImages(a, reference);
  EXPECT_EQ(c.nonFinitePixels, 2u);
  EXPECT_EQ(c.rmse, 0.0);
}

TEST(Compare, HeatmapShowsRelativeError) {
  const Image reference(3, 1, Rgb(1.0f));
  Image a = reference;
  a.at(1, 0) = Rgb(2.0f);  // relative error 1/sqrt(1.01) ≈ 0.995 → near the top of the map
  a.at(2, 0) = Rgb(std::nanf(""));
  const Image8 map = relativeErrorHeatmap(a, reference, 1.0f);
  // Turbo(0) is dark blue-violet (≈ 0.136, 0.091, 0.107) → (35, 23, 27); Turbo(≈1) dark red.
  EXPECT_EQ(map.rgb[0], 35);
  EXPECT_EQ(map.rgb[1], 23);
  EXPECT_EQ(map.rgb[2], 27);
  EXPECT_GT(map.rgb[3], 100);  // red dominates at the top end
  EXPECT_LT(map.rgb[5], 30);
  EXPECT_EQ(map.rgb[6], 255);  // NaN → magenta
  EXPECT_EQ(map.rgb[7], 0);
  EXPECT_EQ(map.rgb[8], 255);
}

}  // namespace
}  // namespace pl
