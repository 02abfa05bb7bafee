// The camera through the whole renderer: `plenoptic trace` of a uniform emitter facing the
// camera (tests/data/image/emissive_wall.json: a black Lambertian wall of emitted radiance 2
// filling the view, nothing else) must give pixel = exposure · cos⁴θ · 2 with --vignetting and
// exposure · 2 without. Emission seen directly carries no Monte Carlo noise; what varies
// within a pixel is only cos⁴θ over its footprint.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "image/image.h"
#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 201, kHeight = 101;
constexpr float kFovY = 40.0f, kRadiance = 2.0f;

/// Traces the wall with extra flags and returns the EXR.
Image traceWall(const std::string& flags) {
  const std::string out = (fs::path(::testing::TempDir()) / ("pl_wall_" + std::to_string(::getpid()) + ".exr")).string();
  const cli_test::CommandResult result =
      cli_test::runPlenopticCombined(fmt::format("trace {}/image/emissive_wall.json -o {} --width {} --height {} --spp 16 {}",
                                                 PLENOPTIC_TEST_DATA_DIR, out, kWidth, kHeight, flags));
  EXPECT_EQ(result.exitCode, 0) << result.output;
  Image image = result.exitCode == 0 ? readImage(out) : Image();
  fs::remove(out);
  return image;
}

/// cos θ at the centre of pixel (x, y), from the fov alone (square pixels, camera.h).
float cosTheta(int x, int y) {
  const float tanHalf = std::tan(kFovY * 3.14159265f / 360.0f), aspect = float(kWidth) / float(kHeight);
  const float sx = (2.0f * (float(x) + 0.5f) / float(kWidth) - 1.0f) * tanHalf * aspect;
  const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(kHeight)) * tanHalf;
  return 1.0f / std::sqrt(1.0f + sx * sx + sy * sy);
}

void expectCosFourth(const Image& image, float scale) {
  ASSERT_EQ(image.width, kWidth);
  ASSERT_EQ(image.height, kHeight);
  const float centre = image.at(kWidth / 2, kHeight / 2).g;
  EXPECT_NEAR(centre, scale * kRadiance, 1e-3f * scale * kRadiance);  // θ ≈ 0 within the pixel
  for (int y = 0; y < kHeight; y += 10)
    for (int x = 0; x < kWidth; x += 10) {
      const float expected = std::pow(cosTheta(x, y), 4.0f);
      // 1 %: the tracer averages cos⁴ over 16 random film positions in the pixel; across a
      // corner pixel cos⁴ changes by ≈ 2 %, so the mean's spread is ≈ 0.15 % (1 % ≈ 7σ).
      EXPECT_NEAR(image.at(x, y).g / centre, expected, 0.01f * expected) << x << "," << y;
    }
}

TEST(CameraTrace, UniformEmitterFollowsCosFourthWithVignetting) {
  expectCosFourth(traceWall("--vignetting"), 1.0f);
}

TEST(CameraTrace, ThinLensKeepsTheCosFourthLaw) {
  expectCosFourth(traceWall("--vignetting --aperture 2 --focus-distance 3"), 1.0f);
}

TEST(CameraTrace, WithoutVignettingEveryPixelIsTheRadianceTimesExposure) {
  const Image plain = traceWall("");
  ASSERT_EQ(plain.width, kWidth);
  for (const Rgb& p : plain.pixels) ASSERT_EQ(p, Rgb(kRadiance));  // weight 1, exact
  // f/4, 1/50 s, ISO 200: EV100 = log2(16 · 50 · 100/200) = log2(400), H = 1/(1.2 · 400).
  const Image exposed = traceWall("--fstop 4 --shutter 1/50 --iso 200");
  ASSERT_EQ(exposed.width, kWidth);
  for (const Rgb& p : exposed.pixels) ASSERT_NEAR(p.g, kRadiance / 480.0f, 1e-6f * kRadiance / 480.0f);
}

}  // namespace
}  // namespace pl
