// Image files: round trips per format, foreign variants (byte order, row order, grey, RLE),
// and refusal of missing, truncated, corrupt and absurd files, with the name in the message.
#include <gtest/gtest.h>

#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "image/image.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

/// A fresh directory per test, removed afterwards.
class ImageFiles : public test_support::TempDirTest {};

/// Random HDR content spanning many orders of magnitude (1e-4 .. 1e4), as radiance does.
Image randomHdrImage(int w, int h, uint64_t seed) {
  Image image(w, h);
  Pcg32 rng(seed, 1);
  for (Rgb& p : image.pixels)
    for (int c = 0; c < 3; ++c) p[c] = std::pow(10.0f, 8.0f * rng.uniform() - 4.0f);
  return image;
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}
std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Expects readImage(path) to throw pl::Error whose message names the file and contains `what`.
void expectReadError(const std::string& path, const std::string& what) {
  try {
    readImage(path);
    ADD_FAILURE() << path << ": expected an error containing '" << what << "'";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  }
}

TEST(Srgb, KnownValuesAndInverse) {
  EXPECT_EQ(linearToSrgb(0.0f), 0.0f);
  EXPECT_EQ(linearToSrgb(1.0f), 1.0f);
  EXPECT_EQ(linearToSrgb(2.0f), 1.0f);
  EXPECT_EQ(linearToSrgb(-1.0f), 0.0f);
  EXPECT_EQ(linearToSrgb(std::nanf("")), 0.0f);
  // Middle grey 0.18 encodes to ≈ 0.4613 (IEC 61966-2-1 closed form, 1e-4 = float pow rounding).
  EXPECT_NEAR(linearToSrgb(0.18f), 1.055f * std::pow(0.18f, 1.0f / 2.4f) - 0.055f, 1e-6f);
  EXPECT_NEAR(linearToSrgb(0.18f), 0.4613f, 1e-4f);
  // The two pieces meet at 0.0031308 ↔ 0.04045 (continuity within float precision).
  EXPECT_NEAR(linearToSrgb(0.0031308f), 0.04045f, 1e-5f);
  for (int i = 0; i <= 1000; ++i) {
    const float x = float(i) / 1000.0f;
    EXPECT_NEAR(srgbToLinear(linearToSrgb(x)), x, 2e-6f) << x;  // float round-off of pow
  }
}

TEST_F(ImageFiles, ExrFloatRoundTripIsExact) {
  const Image image = randomHdrImage(37, 23, 1);
  writeHdrImage(path("a.exr"), image);
  const Image back = readImage(path("a.exr"));
  ASSERT_EQ(back.width, 37);
  ASSERT_EQ(back.height, 23);
  for (size_t i = 0; i < image.pixels.size(); ++i) ASSERT_EQ(back.pixels[i], image.pixels[i]) << i;
}

TEST_F(ImageFiles, ExrHalfRoundTripWithinHalfPrecision) {
  const Image image = randomHdrImage(16, 9, 2);
  writeHdrImage(path("a.EXR"), image, {.exrHalf = true});
  const Image back = readImage(path("a.EXR"));
  ASSERT_EQ(back.pixels.size(), image.pixels.size());
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      // Half has an 11-bit significand: round-to-nearest error ≤ 2^-11 relative for normal
      // values (≥ 6.1e-5); below that (subnormal halves) the absolute step is 2^-24.
      const float x = image.pixels[i][c];
      EXPECT_NEAR(back.pixels[i][c], x, std::max(x * 0x1p-11f, 0x1p-25f)) << i;
    }
}

TEST_F(ImageFiles, RadianceHdrRoundTripWithinRgbePrecision) {
  Image image = randomHdrImage(40, 11, 3);  // width ≥ 8: the RLE scan-line encoding
  image.at(3, 4) = Rgb(0.0f);               // black is exactly representable (exponent 0)
  writeHdrImage(path("a.hdr"), image);
  const Image back = readImage(path("a.hdr"));
  ASSERT_EQ(back.width, 40);
  ASSERT_EQ(back.height, 11);
  EXPECT_EQ(back.at(3, 4), Rgb(0.0f));
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    // Shared exponent, 8-bit mantissas, encoder truncates and the decoder adds half a step:
    // error ≤ half a mantissa step (2^(e-9)) ≤ max(r,g,b)/256 per channel.
    const float bound = maxComponent(image.pixels[i]) / 256.0f;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.pixels[i][c], image.pixels[i][c], bound) << i;
  }
}

TEST_F(ImageFiles, RadianceHdrFlatBottomUpWithExposure) {
  // A 2×2 file written by hand: flat (non-RLE) pixels, "+Y" = bottom row first, and
  // EXPOSURE=2 (stored values are twice the radiance). Mantissa 128, exponent 129 encodes
  // (128 + 0.5)·2^(129−136) = 1.00390625.
  std::string file = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=2\n\n+Y 2 +X 2\n";
  const unsigned char bottom[8] = {128, 0, 0, 129, 0, 128, 0, 129};
  const unsigned char top[8] = {0, 0, 128, 129, 0, 0, 0, 0};
  file.append(reinterpret_cast<const char*>(bottom), 8).append(reinterpret_cast<const char*>(top), 8);
  writeBytes(path("flat.hdr"), file);
  const Image image = readImage(path("flat.hdr"));
  const float one = (128.0f + 0.5f) / 128.0f / 2.0f, zero = 0.5f / 128.0f / 2.0f;
  EXPECT_EQ(image.at(0, 1), Rgb(one, zero, zero));  // bottom-left: red
  EXPECT_EQ(image.at(1, 1), Rgb(zero, one, zero));
  EXPECT_EQ(image.at(0, 0), Rgb(zero, zero, one));  // top-left: blue
  EXPECT_EQ(image.at(1, 0), Rgb(0.0f));
}

TEST_F(ImageFiles, PfmRoundTripIsExactAndRowsAreBottomUp) {
  const Image image = randomHdrImage(13, 7, 4);
  writeHdrImage(path("a.pfm"), image);
  const Image back = readImage(path("a.pfm"));
  ASSERT_EQ(back.width, 13);
  for (size_t i = 0; i < image.pixels.size(); ++i) ASSERT_EQ(back.pixels[i], image.pixels[i]) << i;
  // The first float after the header belongs to the bottom-left pixel.
  const std::string bytes = readBytes(path("a.pfm"));
  const size_t header = std::string("PF\n13 7\n-1.0\n").size();
  ASSERT_EQ(bytes.substr(0, header), "PF\n13 7\n-1.0\n");
  float first;
  std::memcpy(&first, bytes.data() + header, 4);
  EXPECT_EQ(first, image.at(0, 6).r);
}

TEST_F(ImageFiles, PfmBigEndianGreyIsRead) {
  // "Pf" (one channel), positive scale = big-endian, 2×2, rows bottom to top.
  std::string file = "Pf\n2 2\n1.0\n";
  for (float v : {1.0f, 2.0f, 3.0f, 4.0f}) {
    const uint32_t bits = std::bit_cast<uint32_t>(v);
    for (int shift = 24; shift >= 0; shift -= 8) file.push_back(char((bits >> shift) & 0xff));
  }
  writeBytes(path("grey.pfm"), file);
  const Image image = readImage(path("grey.pfm"));
  EXPECT_EQ(image.at(0, 1), Rgb(1.0f));  // first stored = bottom-left
  EXPECT_EQ(image.at(1, 1), Rgb(2.0f));
  EXPECT_EQ(image.at(0, 0), Rgb(3.0f));
  EXPECT_EQ(image.at(1, 0), Rgb(4.0f));
}

TEST_F(ImageFiles, PngRoundTripOf8BitValuesIsExact) {
  Image8 image{5, 3, {}};
  for (int i = 0; i < 5 * 3 * 3; ++i) image.rgb.push_back(uint8_t((i * 37) % 256));
  writePng(path("a.Png"), image);
  const Image back = readImage(path("a.Png"));
  ASSERT_EQ(back.width, 5);
  ASSERT_EQ(back.height, 3);
  // Reading decodes sRGB to linear; re-encoding and rounding must give back the same bytes.
  for (size_t i = 0; i < back.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(int(std::lround(linearToSrgb(back.pixels[i][c]) * 255.0f)), image.rgb[3 * i + size_t(c)]) << i;
}

TEST_F(ImageFiles, TruncatedAndCorruptFilesAreRefusedWithTheirName) {
  const Image image = randomHdrImage(32, 16, 5);
  writeHdrImage(path("a.exr"), image);
  writeHdrImage(path("a.hdr"), image);
  writeHdrImage(path("a.pfm"), image);
  Image8 png{32, 16, std::vector<uint8_t>(32 * 16 * 3, 77)};
  writePng(path("a.png"), png);
  for (const char* name : {"a.exr", "a.hdr", "a.pfm", "a.png"}) {
    const std::string full = readBytes(path(name));
    const std::string cut = path(std::string("cut_") + name);
    writeBytes(cut, full.substr(0, full.size() * 2 / 3));
    expectReadError(cut, "");  // any message, but it must name the file
    const std::string garbage = path(std::string("garbage_") + name);
    writeBytes(garbage, std::string(200, 'x'));
    expectReadError(garbage, "");
    const std::string empty = path(std::string("empty_") + name);
    writeBytes(empty, "");
    expectReadError(empty, "");
  }
  expectReadError(path("cut_a.pfm"), "truncated");
  expectReadError(path("cut_a.hdr"), "truncated");
  expectReadError(path("cut_a.png"), "truncated");
}

TEST_F(ImageFiles, MissingUnknownAndAbsurdFilesAreRefused) {
  expectReadError(path("nope.exr"), "no such file");
  writeBytes(path("image.xyz"), "hello");
  expectReadError(path("image.xyz"), "unknown image extension");
  writeBytes(path("huge.pfm"), "PF\n100000 100000\n-1.0\n");
  expectReadError(path("huge.pfm"), "out of range");
  writeBytes(path("negative.pfm"), "PF\n-3 2\n-1.0\n");
  expectReadError(path("negative.pfm"), "out of range");
  writeBytes(path("huge.hdr"), "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 900000 +X 900000\n");
  expectReadError(path("huge.hdr"), "out of range");
  // In range (8192² = 67 M pixels) but holding one pixel: refused as truncated. The reader
  // decodes before allocating the image, so this costs the few bytes read, not 800 MB.
  writeBytes(path("short.hdr"), std::string("#?RADIANCE\n\n-Y 8192 +X 8192\n\x02\x02\x20\x00", 32));
  expectReadError(path("short.hdr"), "truncated");
  writeBytes(path("xyz.hdr"), "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n");
  expectReadError(path("xyz.hdr"), "unsupported");
}

TEST_F(ImageFiles, FailedWritesLeaveNoFileBehind) {
  // 1. Non-finite pixels cannot be stored in RGBE: refused, nothing created.
  Image bad(4, 4, Rgb(1.0f));
  bad.at(2, 1) = Rgb(std::nanf(""), 0.0f, 0.0f);
  EXPECT_THROW(writeHdrImage(path("bad.hdr"), bad), Error);
  EXPECT_EQ(fileCount(), 0u);
  // 2. A failed write over an existing file keeps the old file intact.
  const Image good(4, 4, Rgb(0.5f));
  writeHdrImage(path("keep.hdr"), good);
  const std::string before = readBytes(path("keep.hdr"));
  EXPECT_THROW(writeHdrImage(path("keep.hdr"), bad), Error);
  EXPECT_EQ(readBytes(path("keep.hdr")), before);
  EXPECT_EQ(fileCount(), 1u);  // no temporary left beside it
  // 3. Missing directory and unknown extension: an error naming the target.
  try {
    writeHdrImage(path("missing/dir/out.exr"), good);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out.exr"), std::string::npos) << e.what();
  }
  EXPECT_THROW(writeHdrImage(path("out.tiff"), good), Error);
  // 4. A PNG buffer that does not match its size.
  EXPECT_THROW(writePng(path("bad.png"), Image8{4, 4, std::vector<uint8_t>(10)}), Error);
  EXPECT_EQ(fileCount(), 1u);
}

}  // namespace
}  // namespace pl
