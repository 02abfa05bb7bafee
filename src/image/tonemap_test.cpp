// Tone mapping against Reinhard's closed forms: monotone, white point → 1, chromaticity kept,
// key normalisation by the log-average, the automatic key, and the 8-bit sRGB encoding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "image/tonemap.h"

namespace pl {
namespace {

Image greyRamp(float lo, float hi, int n) {
  Image image(n, 1);
  for (int i = 0; i < n; ++i) image.at(i, 0) = Rgb(lo * std::pow(hi / lo, float(i) / float(n - 1)));
  return image;
}

TEST(Reinhard, IsMonotoneAndBelowOne) {
  const Image image = greyRamp(1e-3f, 1e4f, 500);
  for (std::optional<float> white : {std::optional<float>(), std::optional<float>(50.0f)}) {
    ToneMapSettings settings;
    settings.white = white;
    const ToneMapCurve curve = resolveToneMap(image, settings);
    float previous = -1.0f;
    for (const Rgb& p : image.pixels) {
      const float y = luminance(curve.apply(p));
      EXPECT_GE(y, previous);  // monotone (ties only where the white point clips at 1)
      EXPECT_GE(y, 0.0f);
      EXPECT_LE(y, 1.0f);
      previous = y;
    }
    // Without a white point eq. 3 is strictly increasing and never reaches 1.
    if (!white) {
      EXPECT_LT(luminance(curve.apply(image.pixels.back())), 1.0f);
    }
  }
}

TEST(Reinhard, MapsTheWhitePointToOne) {
  const Image image = greyRamp(0.01f, 100.0f, 64);
  for (float white : {0.5f, 3.0f, 80.0f}) {
    ToneMapSettings withKey;
    withKey.white = white;
    ToneMapSettings withoutKey = withKey;
    withoutKey.key.reset();
    for (const ToneMapSettings& s : {withKey, withoutKey}) {
      const ToneMapCurve curve = resolveToneMap(image, s);
      // Float rounding of L·(1 + L/Lw²)/(1 + L) at L = Lw: a few ulps.
      EXPECT_NEAR(luminance(curve.apply(Rgb(white))), 1.0f, 1e-5f) << white;
      EXPECT_LT(luminance(curve.apply(Rgb(0.9f * white))), 1.0f);
    }
  }
}

TEST(Reinhard, KeepsChromaticity) {
  Pcg32 rng(7, 1);
  Image image(200, 1);
  for (Rgb& p : image.pixels) p = Rgb(rng.uniform(), rng.uniform(), rng.uniform()) * std::pow(10.0f, 4.0f * rng.uniform() - 2.0f);
  const ToneMapCurve curve = resolveToneMap(image, ToneMapSettings{});
  int checked = 0;
  for (const Rgb& p : image.pixels) {
    const Rgb out = curve.apply(p);
    if (maxComponent(out) >= 1.0f || luminance(p) <= 0.0f) continue;  // clipped channels change ratios
    // r:g:b kept: out = s · in for one s. 1e-5 relative: float rounding through YUV and back.
    const float s = luminance(out) / luminance(p);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], s * p[c], 1e-5f * maxComponent(out) + 1e-7f);
    ++checked;
  }
  EXPECT_GT(checked, 150);
}

TEST(Reinhard, KeyMapsTheLogAverageAndFollowsEquationThree) {
  // Eq. 1: half the pixels at a, half at b → L̄w = sqrt((δ + a)(δ + b)).
  Image two(2, 1);
  two.at(0, 0) = Rgb(0.5f);
  two.at(1, 0) = Rgb(8.0f);
  EXPECT_NEAR(logAverageLuminance(two), std::sqrt((1e-4 + 0.5) * (1e-4 + 8.0)), 1e-5);
  // A uniform image of luminance Y is scaled to the key a, then Ld = a/(1 + a) (eq. 3).
  const Image uniform(4, 4, Rgb(37.0f));
  for (float key : {0.09f, 0.18f, 0.72f}) {
    ToneMapSettings s;
    s.key = key;
    const ToneMapCurve curve = resolveToneMap(uniform, s);
    // δ = 1e-4 inside the log shifts L̄w by 1e-4/37 relative.
    EXPECT_NEAR(luminance(curve.apply(Rgb(37.0f))), key / (1.0f + key), 1e-5f);
  }
  // No key: the exposed value is used as it is.
  ToneMapSettings noKey;
  noKey.key.reset();
  EXPECT_NEAR(luminance(resolveToneMap(uniform, noKey).apply(Rgb(3.0f))), 0.75f, 1e-6f);
}

TEST(Reinhard, AutomaticKeyFollowsReinhard2002) {
  EXPECT_NEAR(automaticKey(Image(8, 8, Rgb(5.0f))), 0.18f, 1e-7f);  // one luminance: default key
  // 90 % of pixels at 1, 10 % at 16: Lmin = 1, Lmax = 16 (1st / 99th percentiles), and
  // log2 L̄w = 0.1 · log2 16 = 0.4, so a = 0.18 · 4^((0.8 − 0 − 4)/4) = 0.18 · 4^−0.8.
  Image image(100, 1, Rgb(1.0f));
  for (int i = 0; i < 10; ++i) image.at(i * 10, 0) = Rgb(16.0f);
  // 1e-4 relative: δ in eq. 1.
  EXPECT_NEAR(automaticKey(image), 0.18f * std::pow(4.0f, -0.8f), 1e-4f);
  ToneMapSettings s;
  s.autoKey = true;
  EXPECT_NEAR(resolveToneMap(image, s).luminanceScale, automaticKey(image) / logAverageLuminance(image), 1e-6f);
}

// The curve from a log-average computed elsewhere (the GPU's display pass sums eq. 1 where the
// frame is) is the image's own for every setting that needs no more; the statistics each
// setting reads; the automatic key refused without its percentiles.
TEST(ToneMap, ResolvesFromTheLogAverageAlone) {
  Pcg32 rng(3, 8);
  Image image(50, 20);
  for (Rgb& p : image.pixels) p = Rgb(rng.uniform(), rng.uniform(), rng.uniform()) * std::pow(10.0f, 3.0f * rng.uniform() - 1.0f);
  image.at(3, 4) = Rgb(std::nanf(""));  // left out of eq. 1 both ways
  ToneMapSettings withWhite;
  withWhite.white = 6.0f;
  ToneMapSettings noKey;
  noKey.key.reset();
  ToneMapSettings linear{ToneMapOperator::Linear, {}, false, 4.0f};
  ToneMapSettings clamp{ToneMapOperator::Clamp, {}, false, {}};
  const float logAverage = logAverageLuminance(image);
  for (const ToneMapSettings& s : {ToneMapSettings{}, withWhite, noKey, linear, clamp}) {
    const ToneMapCurve fromImage = resolveToneMap(image, s), fromAverage = resolveToneMap(logAverage, s);
    EXPECT_EQ(fromAverage.op, fromImage.op);
    EXPECT_EQ(fromAverage.luminanceScale, fromImage.luminanceScale);
    EXPECT_EQ(fromAverage.whiteScaled, fromImage.whiteScaled);
  }
  EXPECT_EQ(toneMapStatistics(ToneMapSettings{}), ToneMapStatistics::LogAverage);
  EXPECT_EQ(toneMapStatistics(withWhite), ToneMapStatistics::LogAverage);
  EXPECT_EQ(toneMapStatistics(noKey), ToneMapStatistics::None);
  EXPECT_EQ(toneMapStatistics(linear), ToneMapStatistics::None);
  EXPECT_EQ(toneMapStatistics(clamp), ToneMapStatistics::None);
  ToneMapSettings autoKey;
  autoKey.autoKey = true;
  EXPECT_EQ(toneMapStatistics(autoKey), ToneMapStatistics::Percentiles);
  EXPECT_THROW(resolveToneMap(logAverage, autoKey), Error);
  // An image without a finite pixel: log-average 0, the scale left at 1.
  EXPECT_EQ(resolveToneMap(0.0f, ToneMapSettings{}).luminanceScale, 1.0f);
}

TEST(ToneMap, LinearAndClamp) {
  ToneMapSettings linear{ToneMapOperator::Linear, {}, false, 4.0f};
  const ToneMapCurve l = resolveToneMap(Image(1, 1), linear);
  EXPECT_EQ(l.apply(Rgb(1.0f, 2.0f, 8.0f)), Rgb(0.25f, 0.5f, 1.0f));  // exposed/white, clipped
  ToneMapSettings clamp{ToneMapOperator::Clamp, {}, false, {}};
  const ToneMapCurve c = resolveToneMap(Image(1, 1), clamp);
  EXPECT_EQ(c.apply(Rgb(0.2f, 0.5f, 0.1f)), Rgb(0.2f, 0.5f, 0.1f));
  EXPECT_EQ(c.apply(Rgb(1.0f, 4.0f, 2.0f)), Rgb(0.25f, 1.0f, 0.5f));  // hue kept
  EXPECT_EQ(parseToneMapOperator("clamp"), ToneMapOperator::Clamp);
  EXPECT_THROW(parseToneMapOperator("aces"), Error);
  ToneMapSettings badWhite;
  badWhite.white = -1.0f;
  EXPECT_THROW(resolveToneMap(Image(1, 1), badWhite), Error);
}

TEST(ToneMap, EncodesSrgbAndShowsNonFinitePixels) {
  Image display(4, 1);
  display.at(0, 0) = Rgb(0.0f);
  display.at(1, 0) = Rgb(1.0f);
  display.at(2, 0) = Rgb(0.18f);
  display.at(3, 0) = Rgb(std::nanf(""), 0.5f, 0.5f);
  const Image8 out = encodeSrgb8(display);
  EXPECT_EQ(out.rgb[0], 0);
  EXPECT_EQ(out.rgb[3], 255);
  EXPECT_EQ(out.rgb[6], 118);  // 0.18 → 0.4613 · 255 = 117.6
  EXPECT_EQ(out.rgb[9], 255);  // magenta
  EXPECT_EQ(out.rgb[10], 0);
  EXPECT_EQ(out.rgb[11], 255);
  // The whole pipeline keeps NaN visible too, and the statistics ignore it.
  Image exposed(2, 1, Rgb(1.0f));
  exposed.at(1, 0) = Rgb(std::nanf(""));
  EXPECT_NEAR(logAverageLuminance(exposed), 1.0f + 1e-4f, 1e-6f);  // δ + 1: the NaN pixel is left out
  const Image8 mapped = toneMap(exposed, ToneMapSettings{});
  EXPECT_EQ(mapped.rgb[3], 255);
  EXPECT_EQ(mapped.rgb[4], 0);
}

}  // namespace
}  // namespace pl
