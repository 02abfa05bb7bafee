// The per-frame display encoder against the exact file path (toneMap + encodeSrgb8).
#include "image/display.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

#include "core/parallel.h"
#include "core/rng.h"

namespace pl {
namespace {

/// Largest difference in 8-bit levels between the encoder's 0xFFRRGGBB words and toneMap().
int maxLevelDifference(const Image& radiance, float exposureScale, const ToneMapSettings& settings) {
  DisplayEncoder encoder;
  std::vector<uint32_t> words(radiance.pixels.size());
  encoder.encode(radiance, exposureScale, settings, words.data(), radiance.width * 4);
  Image exposed = radiance;
  for (Rgb& p : exposed.pixels) p *= exposureScale;
  const Image8 exact = toneMap(exposed, settings);
  int worst = 0;
  for (size_t i = 0; i < words.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const int shown = int((words[i] >> (16 - 8 * c)) & 0xFFu);
      worst = std::max(worst, std::abs(shown - int(exact.rgb[3 * i + size_t(c)])));
    }
  return worst;
}

/// An image constant on 4×4 blocks (so the encoder's 1-in-16 subsample has exactly the full
/// image's statistics) with radiance spread over four decades.
Image blockImage(int width, int height) {
  Image image(width, height);
  Pcg32 rng(5, 1);
  for (int by = 0; by < height; by += 4)
    for (int bx = 0; bx < width; bx += 4) {
      const Rgb value(std::pow(10.0f, 4.0f * rng.uniform() - 2.0f), std::pow(10.0f, 4.0f * rng.uniform() - 2.0f),
                      std::pow(10.0f, 4.0f * rng.uniform() - 2.0f));
      for (int y = by; y < std::min(by + 4, height); ++y)
        for (int x = bx; x < std::min(bx + 4, width); ++x) image.at(x, y) = value;
    }
  return image;
}

TEST(DisplayEncoder, MatchesTheExactToneMappingWithinOneLevel) {
  ThreadPool pool(2);
  const Image image = blockImage(64, 48);
  // At most one 8-bit level: the sRGB table's step (see display.h) moves a value by ≤ 0.2
  // of a level, which can cross one rounding boundary, never two.
  ToneMapSettings reinhard;
  EXPECT_LE(maxLevelDifference(image, 1.0f, reinhard), 1);
  ToneMapSettings linear;
  linear.op = ToneMapOperator::Linear;
  EXPECT_LE(maxLevelDifference(image, 0.5f, linear), 1);
  ToneMapSettings clamp;
  clamp.op = ToneMapOperator::Clamp;
  EXPECT_LE(maxLevelDifference(image, 2.0f, clamp), 1);
  // (The automatic key is left out: its 1st/99th percentiles pick order statistics by index,
  // which land on different blocks in a 1/16 subsample even for this block image.)
}

TEST(DisplayEncoder, NonFinitePixelsAreMagenta) {
  ThreadPool pool(1);
  Image image(8, 8, Rgb(0.5f));
  image.at(3, 2) = Rgb(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);
  DisplayEncoder encoder;
  std::vector<uint32_t> words(64);
  ToneMapSettings clamp;
  clamp.op = ToneMapOperator::Clamp;
  encoder.encode(image, 1.0f, clamp, words.data(), 8 * 4);
  EXPECT_EQ(words[2 * 8 + 3], 0xFFFF00FFu);
  EXPECT_NE(words[0], 0xFFFF00FFu);
}

}  // namespace
}  // namespace pl
