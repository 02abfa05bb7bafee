// Textures (texture.h): bilinear sampling and its origin, the packed palettes against the float
// texels, the mip levels' box averages and trilinear sampling across them.
#include "scene/texture.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "core/rng.h"
#include "support/expect_vec3.h"

namespace pl {
namespace {

// Float tolerance for values that went through a few float operations (products, sums of
// magnitude ≲ 10): a few ulps of float (6e-8 relative) at that scale.
constexpr float kTight = 1e-5f;

Texture twoByTwo() {
  Texture texture;
  texture.image = Image(2, 2);
  texture.image.at(0, 0) = Rgb(1, 0, 0);  // top-left
  texture.image.at(1, 0) = Rgb(0, 1, 0);  // top-right
  texture.image.at(0, 1) = Rgb(0, 0, 1);  // bottom-left
  texture.image.at(1, 1) = Rgb(1, 1, 1);  // bottom-right
  return texture;
}

TEST(Texture, BilinearWithRepeatAndBottomLeftOrigin) {
  const Texture t = twoByTwo();
  // Texel centres sit at u, v ∈ {0.25, 0.75}; v = 0.25 is the bottom row.
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.25f, 0.25f)), Rgb(0, 0, 1), kTight);
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.75f, 0.25f)), Rgb(1, 1, 1), kTight);
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.25f, 0.75f)), Rgb(1, 0, 0), kTight);
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.75f, 0.75f)), Rgb(0, 1, 0), kTight);
  // The image centre is equidistant from all four: their mean.
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.5f, 0.5f)), Rgb(0.5f, 0.5f, 0.5f), kTight);
  // Halfway between the two top texels, weights ½ each.
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.5f, 0.75f)), Rgb(0.5f, 0.5f, 0.0f), kTight);
  // A quarter of the way: weights ¾ (red) and ¼ (green).
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.375f, 0.75f)), Rgb(0.75f, 0.25f, 0.0f), kTight);
  // Repeat: whole-number shifts change nothing, and u = 0 blends the left and right
  // columns (which are neighbours across the wrap) half and half.
  EXPECT_VEC3_NEAR(t.sample(Vec2(-1.75f, 2.25f)), Rgb(0, 0, 1), kTight);
  EXPECT_VEC3_NEAR(t.sample(Vec2(0.0f, 0.75f)), Rgb(0.5f, 0.5f, 0.0f), kTight);
}

// finish() packs a texture of at most 256 distinct channel values (an 8-bit image) into 4×4
// blocks of palette indices; sample() must give exactly (bit for bit) what the float image
// gives, at texel centres, between texels, across the wrap on every side and across block
// edges of a size that is not a multiple of 4. More than 256 values: not packed.
TEST(Texture, PackedTexelsSampleBitForBitLikeTheFloatImage) {
  Texture texture;
  texture.path = "palette";
  texture.image = Image(11, 6);
  uint32_t state = 12345;
  auto next = [&] { return (state = state * 1664525u + 1013904223u) >> 24; };  // 0 … 255
  for (Rgb& texel : texture.image.pixels)
    texel = Rgb(srgbToLinear(float(next()) / 255.0f), float(next()) / 255.0f, srgbToLinear(float(next()) / 255.0f));
  texture.image.at(3, 2) = Rgb(-0.0f, 0.0f, 1.0f);  // −0 and +0: both kept exactly
  texture.finish("test");
  ASSERT_FALSE(texture.packed.empty());
  ASSERT_LE(texture.palette.size(), 256u);
  EXPECT_EQ(texture.packed.size(), 3u * 2u);  // ⌈11/4⌉ × ⌈6/4⌉ blocks
  Texture plain = texture;
  plain.packed.clear();
  plain.palette.clear();
  int compared = 0;
  for (int j = -30; j <= 30; ++j)
    for (int i = -40; i <= 40; ++i) {
      const Vec2 uv(float(i) * 0.0371f, float(j) * 0.0533f);
      const Rgb a = texture.sample(uv), b = plain.sample(uv);
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(std::bit_cast<uint32_t>(a[c]), std::bit_cast<uint32_t>(b[c])) << "uv " << uv.x << ", " << uv.y;
      ++compared;
    }
  EXPECT_EQ(compared, 61 * 81);
  // Texel centres give the texels themselves.
  EXPECT_VEC3_NEAR(texture.sample(Vec2(3.5f / 11.0f, 1.0f - 2.5f / 6.0f)), Rgb(0.0f, 0.0f, 1.0f), kTight);

  Texture wide;
  wide.path = "wide";
  wide.image = Image(300, 1);
  for (int x = 0; x < 300; ++x) wide.image.at(x, 0) = Rgb(float(x) / 300.0f);
  wide.finish("test");
  EXPECT_TRUE(wide.packed.empty());
  EXPECT_TRUE(wide.palette.empty());
  EXPECT_VEC3_NEAR(wide.sample(Vec2((10.5f) / 300.0f, 0.5f)), Rgb(10.0f / 300.0f), kTight);
}

// Mip levels are exact box averages of the level above: a 5×3 texture gives level 1 = 2×1
// (each texel covers 2.5 × 3 texels of level 0: two whole columns and half of the middle one,
// all three rows) and level 2 = 1×1 (the mean of level 1, which is the mean of the image);
// an even 4×2 level gives plain 2×2 averages. Weights written out by hand, not by the code's
// own overlap rule.
TEST(Texture, MipLevelsAreExactBoxAverages) {
  Texture texture;
  texture.path = "odd";
  texture.image = Image(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) texture.image.at(x, y) = Rgb(float(x + 5 * y), float(x * x), float(y == 1 ? 7 : 1));
  texture.finish("test");
  ASSERT_EQ(texture.mips.size(), 2u);
  const Image& level1 = texture.mips[0].image;
  ASSERT_EQ(level1.width, 2);
  ASSERT_EQ(level1.height, 1);
  auto column = [&](int x) {  // the mean of column x over the three rows
    return (texture.image.at(x, 0) + texture.image.at(x, 1) + texture.image.at(x, 2)) / 3.0f;
  };
  const Rgb left = (column(0) + column(1) + 0.5f * column(2)) / 2.5f;
  const Rgb right = (0.5f * column(2) + column(3) + column(4)) / 2.5f;
  EXPECT_VEC3_NEAR(level1.at(0, 0), left, 1e-5f);
  EXPECT_VEC3_NEAR(level1.at(1, 0), right, 1e-5f);
  const Image& level2 = texture.mips[1].image;
  ASSERT_EQ(level2.width, 1);
  ASSERT_EQ(level2.height, 1);
  EXPECT_VEC3_NEAR(level2.at(0, 0), 0.5f * (left + right), 1e-5f);
  EXPECT_VEC3_NEAR(level2.at(0, 0), texture.average, 1e-5f);

  Texture even;
  even.path = "even";
  even.image = Image(4, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) even.image.at(x, y) = Rgb(float(x), float(10 * y), float(x * y));
  even.finish("test");
  ASSERT_EQ(even.mips.size(), 2u);  // 2×1, 1×1
  for (int x = 0; x < 2; ++x) {
    const Rgb box = (even.image.at(2 * x, 0) + even.image.at(2 * x + 1, 0) + even.image.at(2 * x, 1) +
                     even.image.at(2 * x + 1, 1)) / 4.0f;
    EXPECT_VEC3_NEAR(even.mips[0].image.at(x, 0), box, 1e-6f);
  }
  // Normal maps and alpha masks are read at full resolution only: no levels.
  for (const ImageDecode decode : {ImageDecode::Data, ImageDecode::Coverage}) {
    Texture data = even;
    data.decode = decode;
    data.finish("test");
    EXPECT_TRUE(data.mips.empty());
    EXPECT_VEC3_NEAR(data.sampleLod(Vec2(0.3f, 0.6f), 1.0f), data.sample(Vec2(0.3f, 0.6f)), 0.0f);
  }
}

// sampleLod: level 0 (lod ≤ 0, NaN) is sample() to the bit; an integral lod reads that level
// bilinearly (the same uv convention: the texel centres of a 2×1 level at u = ¼, ¾); a
// fractional one blends the two levels linearly; beyond the coarsest it holds the 1×1 level.
// A level whose values allow is packed like level 0.
TEST(Texture, SampleLodIsTrilinearOverTheLevels) {
  Texture texture;
  texture.path = "levels";
  texture.image = Image(8, 4);
  Pcg32 rng(3, 9);
  for (Rgb& texel : texture.image.pixels) texel = Rgb(rng.uniform(), rng.uniform(), rng.uniform());
  texture.finish("test");
  ASSERT_EQ(texture.mips.size(), 3u);  // 4×2, 2×1, 1×1
  for (const Vec2 uv : {Vec2(0.1f, 0.2f), Vec2(0.6f, 0.9f), Vec2(-1.3f, 2.7f)}) {
    const Rgb full = texture.sample(uv);
    for (const float lod : {0.0f, -3.0f, std::nanf("")}) {
      const Rgb got = texture.sampleLod(uv, lod);
      for (int c = 0; c < 3; ++c) EXPECT_EQ(std::bit_cast<uint32_t>(got[c]), std::bit_cast<uint32_t>(full[c]));
    }
    EXPECT_VEC3_NEAR(texture.sampleLod(uv, 5.0f), texture.mips[2].image.at(0, 0), 1e-6f);
    EXPECT_VEC3_NEAR(texture.sampleLod(uv, 3.0f), texture.mips[2].image.at(0, 0), 1e-6f);
  }
  const Image& level2 = texture.mips[1].image;  // 2×1: centres at u = ¼ and ¾
  EXPECT_VEC3_NEAR(texture.sampleLod(Vec2(0.25f, 0.5f), 2.0f), level2.at(0, 0), 1e-6f);
  EXPECT_VEC3_NEAR(texture.sampleLod(Vec2(0.5f, 0.5f), 2.0f), 0.5f * (level2.at(0, 0) + level2.at(1, 0)), 1e-6f);
  const Rgb level3 = texture.mips[2].image.at(0, 0);
  EXPECT_VEC3_NEAR(texture.sampleLod(Vec2(0.25f, 0.5f), 2.25f), 0.75f * level2.at(0, 0) + 0.25f * level3, 1e-6f);

  Texture flat;  // a constant 8-bit texture: every level keeps one value and is packed
  flat.path = "flat";
  flat.image = Image(6, 6);
  for (Rgb& texel : flat.image.pixels) texel = Rgb(0.25f, 0.5f, 0.75f);
  flat.finish("test");
  ASSERT_EQ(flat.mips.size(), 2u);  // 3×3, 1×1
  for (const Texture::Level& level : flat.mips) EXPECT_FALSE(level.packed.empty());
  EXPECT_VEC3_NEAR(flat.sampleLod(Vec2(0.3f, 0.1f), 1.5f), Rgb(0.25f, 0.5f, 0.75f), 1e-7f);
}

/// One triangle (0,0,0), (1,0,0), (0,1,0): counter-clockwise seen from +z.

}  // namespace
}  // namespace pl
