// The viewer's fly camera: exact start pose, movement in the horizontal frame, pitch limits.
#include "viewer/fly_camera.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace pl {
namespace {

CameraDesc startCamera() {
  CameraDesc d;
  d.name = "start";
  d.eye = {0, 1, 5};
  d.target = {0, 0, 0};  // looking down at ≈ 11.3°
  d.up = {0, 1, 0};
  d.fovYDegrees = 45.0f;
  d.fNumber = 2.8f;
  return d;
}

TEST(FlyCamera, StartsExactlyAtTheGivenCamera) {
  const FlyCamera fly(startCamera(), 2.0f);
  const CameraDesc d = fly.desc();
  EXPECT_EQ(d.eye, startCamera().eye);
  EXPECT_EQ(d.target, startCamera().target);
  EXPECT_EQ(d.fNumber, 2.8f);  // the lens is kept
  // forward() agrees with the start direction (yaw/pitch decomposition), to float rounding.
  EXPECT_NEAR(glm::length(fly.forward() - glm::normalize(startCamera().target - startCamera().eye)), 0.0f, 1e-6f);
}

TEST(FlyCamera, MovesInTheHorizontalFrameAtItsSpeed) {
  FlyCamera fly(startCamera(), 2.0f);
  fly.move(Vec3(0, 0, 1), 0.5f);  // forward for 0.5 s at 2 units/s: 1 unit along −z, level
  EXPECT_NEAR(fly.eye().x, 0.0f, 1e-6f);
  EXPECT_NEAR(fly.eye().y, 1.0f, 1e-6f);
  EXPECT_NEAR(fly.eye().z, 4.0f, 1e-6f);
  fly.move(Vec3(1, 0, 0), 1.0f, 4.0f);  // right, 4× faster: +x by 8
  EXPECT_NEAR(fly.eye().x, 8.0f, 1e-5f);
  fly.move(Vec3(0, 1, 0), 0.25f);  // up along the world up
  EXPECT_NEAR(fly.eye().y, 1.5f, 1e-6f);
  // The target keeps its distance in front of the eye.
  const CameraDesc d = fly.desc();
  EXPECT_NEAR(glm::length(d.target - d.eye), glm::length(startCamera().target - startCamera().eye), 1e-5f);
}

TEST(FlyCamera, TurnsLeftAndClampsPitch) {
  FlyCamera fly(startCamera(), 1.0f);
  fly.turn(kPi / 2.0f, 0.0f);  // yaw 90° left: from looking along −z to looking along −x
  EXPECT_LT(fly.forward().x, -0.9f);
  fly.turn(0.0f, 10.0f);  // far past straight up: held at 89°
  EXPECT_NEAR(std::asin(fly.forward().y) * 180.0f / kPi, FlyCamera::kMaxPitchDegrees, 1e-3f);
  fly.turn(0.0f, -20.0f);
  EXPECT_NEAR(std::asin(fly.forward().y) * 180.0f / kPi, -FlyCamera::kMaxPitchDegrees, 1e-3f);
}

TEST(FlyCamera, RefusesDegenerateCameras) {
  CameraDesc d = startCamera();
  d.target = d.eye;
  EXPECT_THROW(FlyCamera(d, 1.0f), Error);
  d = startCamera();
  d.target = d.eye + Vec3(0, -1, 0);  // looking straight down its up vector
  EXPECT_THROW(FlyCamera(d, 1.0f), Error);
}

}  // namespace
}  // namespace pl

#include <cstdlib>

#include "viewer/viewer.h"

namespace pl {
namespace {

TEST(Viewer, HeadlessDriversAreNoDisplay) {
  // Under SDL's dummy driver (as ctest runs us) a window can be made, but nobody sees it:
  // `make demo` must render a walk-through to files instead of opening the viewer.
  ::setenv("SDL_VIDEODRIVER", "dummy", 1);
  EXPECT_FALSE(displayAvailable());
}

}  // namespace
}  // namespace pl

namespace pl {
namespace {

TEST(PathRecorder, RecordsKeyframesAtTheIntervalAndRoundTrips) {
  CameraDesc camera;
  camera.eye = {0, 0, 5};
  camera.target = {0, 0, 0};
  camera.fovYDegrees = 50.0f;
  FlyCamera fly(camera, 1.0f);
  PathRecorder recorder(0.25);
  EXPECT_FALSE(recorder.recording());
  recorder.start(10.0, fly.desc());  // any clock: times become relative to the start
  EXPECT_TRUE(recorder.recording());
  // 60 Hz frames for one second, moving right at 1 unit/s.
  for (int frame = 1; frame <= 60; ++frame) {
    fly.move(Vec3(1, 0, 0), 1.0f / 60.0f);
    recorder.sample(10.0 + frame / 60.0, fly.desc());
  }
  const CameraPath path = recorder.stop(11.05, fly.desc());
  EXPECT_FALSE(recorder.recording());
  // Keyframes at 0, then the first frames at or after 0.25, 0.5, 0.75, 1.0, and the end.
  ASSERT_EQ(path.keyframes.size(), 6u);
  EXPECT_EQ(path.keyframes.front().time, 0.0);
  EXPECT_NEAR(path.keyframes.back().time, 1.05, 1e-9);
  EXPECT_NEAR(path.keyframes[4].eye.x, 1.0f, 1e-4f);  // sampled at t = 1 s
  EXPECT_EQ(*path.keyframes[2].fovYDegrees, 50.0f);
  // It is a valid path file: the JSON parses back with the same keyframes.
  const CameraPath back = parseCameraPath(cameraPathToJson(path), "recorded");
  ASSERT_EQ(back.keyframes.size(), path.keyframes.size());
  for (size_t i = 0; i < path.keyframes.size(); ++i) EXPECT_EQ(back.keyframes[i].eye, path.keyframes[i].eye);
  // Playing it back passes through the recorded positions.
  EXPECT_NEAR(glm::length(back.at(path.keyframes[3].time).eye - path.keyframes[3].eye), 0.0f, 1e-5f);
}

}  // namespace
}  // namespace pl
