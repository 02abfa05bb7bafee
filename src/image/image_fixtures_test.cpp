// Reading files written by other software: OpenEXR fixtures (tests/data/image/README.md)
// and a Radiance .hdr environment map as distributed by Poly Haven (tests/data/envmaps).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "core/error.h"
#include "image/image.h"

namespace pl {
namespace {

const std::string kData = std::string(PLENOPTIC_TEST_DATA_DIR) + "/image/";

TEST(ImageFixtures, ExrWithOffsetDataWindowAndHalfRgba) {
  const Image image = readImage(kData + "window_half_rgba.exr");
  ASSERT_EQ(image.width, 4);
  ASSERT_EQ(image.height, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) {
      // All values are exact in half precision (small integers, quarters; 100..123 < 2048).
      EXPECT_EQ(image.at(x, y), Rgb(float(x) + 0.25f, 2.0f * float(y), 100.0f + float(x) + 10.0f * float(y)))
          << x << "," << y;
    }
}

TEST(ImageFixtures, ExrLuminanceOnlyBecomesGrey) {
  const Image image = readImage(kData + "luminance_y.exr");
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 2);
  EXPECT_EQ(image.at(1, 0), Rgb(1.0f));
  EXPECT_EQ(image.at(2, 1), Rgb(1e6f));
}

TEST(ImageFixtures, TiledExr) {
  const Image image = readImage(kData + "tiled_rgb.exr");
  ASSERT_EQ(image.width, 5);
  ASSERT_EQ(image.height, 4);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(image.pixels[size_t(i)], Rgb(float(i), 0.5f, -1.0f)) << i;
}

TEST(ImageFixtures, ExrHeaderAttributeLargerThanTheFileIsRefusedBeforeAllocating) {
  // Found by fuzzing (tests/data/fuzz/exr/): a 209-byte file whose header attribute claims
  // 1.8 GB, which OpenEXR would allocate before finding the file ends.
  const std::string path = std::string(PLENOPTIC_TEST_DATA_DIR) + "/fuzz/exr/attribute-claims-1.8GB.exr";
  try {
    readImage(path);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("attribute-claims-1.8GB.exr: corrupt OpenEXR header: attribute"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("needs 1851877475 bytes, the file has 209"), std::string::npos) << e.what();
  }
}

TEST(ImageFixtures, RadianceHdrFromPolyHaven) {
  const std::string path = std::string(PLENOPTIC_TEST_DATA_DIR) + "/envmaps/venice_sunset_1k.hdr";
  const Image image = readImage(path);
  ASSERT_EQ(image.width, 1024);
  ASSERT_EQ(image.height, 512);
  for (const Rgb& p : image.pixels) {
    ASSERT_TRUE(isFinite(p));
    ASSERT_GE(std::min(p.r, std::min(p.g, p.b)), 0.0f);
  }
  // Orientation ("-Y 512 +X 1024": top row first): the upper half of this lat-long map is
  // the sunset sky, the lower half the ground, several times darker.
  double upper = 0.0, lower = 0.0;
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 1024; ++x) (y < 256 ? upper : lower) += luminance(image.at(x, y));
  EXPECT_GT(upper, 2.0 * lower);
}

TEST(ImageFixtures, RealHdrContentSurvivesOurWriters) {
  const Image image = readImage(std::string(PLENOPTIC_TEST_DATA_DIR) + "/envmaps/venice_sunset_1k.hdr");
  const std::string dir = ::testing::TempDir();
  writeHdrImage(dir + "pl_venice.exr", image);
  writeHdrImage(dir + "pl_venice.hdr", image);
  const Image exr = readImage(dir + "pl_venice.exr");
  const Image hdr = readImage(dir + "pl_venice.hdr");
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    ASSERT_EQ(exr.pixels[i], image.pixels[i]) << i;  // float EXR is lossless
    // Re-encoding RGBE: within half a mantissa step of the largest component (image_test.cpp).
    const float bound = maxComponent(image.pixels[i]) / 256.0f;
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(hdr.pixels[i][c], image.pixels[i][c], bound) << i;
  }
  std::remove((dir + "pl_venice.exr").c_str());
  std::remove((dir + "pl_venice.hdr").c_str());
}

}  // namespace
}  // namespace pl
