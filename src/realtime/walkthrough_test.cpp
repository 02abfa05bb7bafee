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
