// renderWalkthrough and orbitPath: frame count and times, files, errors.
#include "realtime/walkthrough.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "camera/camera.h"
#include "core/error.h"
#include "support/temp_dir_test.h"
#include "core/progress.h"

namespace pl {
namespace {

CameraDesc baseCamera() {
  CameraDesc d;
  d.eye = {0, 0, 5};
  d.target = {0, 0, 0};
  d.fovYDegrees = 30.0f;
  return d;
}

TEST(Walkthrough, OrbitKeepsDistanceAndReturnsToTheStart) {
  const CameraPath path = orbitPath(baseCamera(), 2.0, 10.0, 30.0f);
  ASSERT_EQ(path.keyframes.size(), 5u);
  EXPECT_EQ(path.frameCount(), 21);
  // 1e-5: float rounding of the rotation (sin, cos and products) on coordinates of size 5.
  for (const CameraKeyframe& k : path.keyframes) EXPECT_NEAR(glm::length(k.eye - k.target), 5.0f, 1e-5f);
  // Keyframe 1 is rotated by +30° about +y: x = 5·sin 30° = 2.5 (right-handed, counter-clockwise from above).
  EXPECT_NEAR(path.keyframes[1].eye.x, 2.5f, 1e-5f);
  EXPECT_NEAR(glm::length(path.keyframes[4].eye - baseCamera().eye), 0.0f, 1e-5f);
  EXPECT_THROW(orbitPath(baseCamera(), 0.0), Error);
}

/// Frames go into a fresh directory per test.
class WalkthroughFiles : public test_support::TempDirTest {};

TEST_F(WalkthroughFiles, RendersEveryFrameAtItsTimeAndWritesFiles) {
  Progress::setEnabled(false);
  const std::filesystem::path dir = dir_;
  const CameraPath path = orbitPath(baseCamera(), 1.0, 4.0, 20.0f);  // 5 frames
  WalkthroughOptions options;
  options.output = (dir / "sub" / "f%02d.pfm").string();  // the directory is created
  options.width = 8;
  options.height = 6;
  options.exposureScale = 2.0f;
  options.showProgress = false;
  std::vector<Vec3> eyes;
  const WalkthroughResult result = renderWalkthrough(path, baseCamera(), options, [&](const Camera& camera, Image& image) {
    eyes.push_back(camera.eye());
    image = Image(camera.width(), camera.height(), Rgb(float(eyes.size())));
  });
  EXPECT_EQ(result.frames, 5);
  ASSERT_EQ(eyes.size(), 5u);
  // 1e-5: the camera is built from the same pose; only float rounding in Camera separates them.
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(glm::length(eyes[size_t(k)] - path.at(path.frameTime(k)).eye), 0.0f, 1e-5f);
  // HDR frames hold radiance × exposure: frame 2 (third) rendered value 3 → 6.
  const Image third = readImage((dir / "sub" / "f02.pfm").string());
  EXPECT_EQ(third.at(0, 0), Rgb(6.0f));
  EXPECT_FALSE(std::filesystem::exists(dir / "sub" / "f05.pfm"));
  EXPECT_EQ(result.frameMs.size(), 5u);

  options.output = (dir / "single.png").string();
  EXPECT_THROW(renderWalkthrough(path, baseCamera(), options, [](const Camera&, Image&) {}), Error);
  options.output = (dir / "f%02d.jpg").string();
  EXPECT_THROW(renderWalkthrough(path, baseCamera(), options, [](const Camera&, Image&) {}), Error);
}

}  // namespace
}  // namespace pl
