// Camera paths: parsing, errors that name the file and the problem, interpolation
// properties (through the keyframes, smooth, straight lines stay straight), round trip.
#include "camera/camera_path.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "light/lights.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

std::string errorOf(const std::string& json) {
  try {
    parseCameraPath(json, "walk.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CameraPath, ParsesTheDocumentedFormat) {
  const CameraPath path = parseCameraPath(R"({"fps": 24, "keyframes": [
      {"time": 0, "eye": [0, 1, 5], "target": [0, 1, 0], "fov": 40, "up": [0, 1, 0]},
      {"time": 2, "eye": [3, 1, 4], "target": [0, 1, 0]}]})",
                                          "walk.json");
  EXPECT_EQ(path.fps, 24.0);
  ASSERT_EQ(path.keyframes.size(), 2u);
  EXPECT_EQ(path.keyframes[1].eye, Vec3(3, 1, 4));
  // A keyframe without fov keeps the previous one's.
  ASSERT_TRUE(path.keyframes[1].fovYDegrees.has_value());
  EXPECT_EQ(*path.keyframes[1].fovYDegrees, 40.0f);
  EXPECT_EQ(path.frameCount(), 2 * 24 + 1);  // both ends included
  EXPECT_DOUBLE_EQ(path.frameTime(24), 1.0);
}

TEST(CameraPath, DefaultsFpsAndLeavesFovToTheCamera) {
  const CameraPath path = parseCameraPath(R"({"keyframes": [{"time": 1, "eye": [0, 0, 1], "target": [0, 0, 0]}]})", "p");
  EXPECT_EQ(path.fps, CameraPath::kDefaultFps);
  EXPECT_EQ(path.frameCount(), 1);
  EXPECT_FALSE(path.at(0.0).fovYDegrees.has_value());
  CameraDesc base;
  base.fovYDegrees = 55.0f;
  EXPECT_EQ(applyPose(base, path.at(1.0)).fovYDegrees, 55.0f);
}

TEST(CameraPath, BadFilesNameTheFileAndTheProblem) {
  EXPECT_NE(errorOf("{").find("walk.json: not valid JSON"), std::string::npos);
  EXPECT_NE(errorOf("[]").find("walk.json: expected a JSON object"), std::string::npos);
  // A number beyond a double: nlohmann throws out_of_range, not parse_error.
  EXPECT_NE(errorOf(R"({"fps": 1e400, "keyframes": []})").find("walk.json: not valid JSON"), std::string::npos);
  EXPECT_NE(errorOf(R"({"fps": 30})").find("missing \"keyframes\""), std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": []})").find("non-empty array"), std::string::npos);
  EXPECT_NE(errorOf(R"({"fps": 0, "keyframes": [{"time": 0, "eye": [0,0,1], "target": [0,0,0]}]})").find("'fps' must be in"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"frames": 3, "keyframes": []})").find("unknown key 'frames'"), std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "eye": [0,0], "target": [0,0,0]}]})")
                .find("walk.json: keyframe 0: 'eye' must be an array of 3 numbers"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "eye": [0,0,"x"], "target": [0,0,0]}]})").find("'eye' must be"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"eye": [0,0,1], "target": [0,0,0]}]})").find("keyframe 0: missing 'time'"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "target": [0,0,0]}]})").find("missing 'eye'"), std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "eye": [0,0,1]}]})").find("missing 'target'"), std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "eye": [1,1,1], "target": [1,1,1]}]})").find("coincide"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "eye": [0,1,0], "target": [0,0,0]}]})").find("parallel"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "eye": [0,0,1], "target": [0,0,0], "fov": 180}]})").find("'fov' must be in"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 0, "eye": [0,0,1], "target": [0,0,0], "eyes": 1}]})")
                .find("keyframe 0: unknown key 'eyes'"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"keyframes": [{"time": 1, "eye": [0,0,1], "target": [0,0,0]},
                                      {"time": 1, "eye": [0,0,2], "target": [0,0,0]}]})")
                .find("keyframe 1: time 1 is not after"),
            std::string::npos);
  try {
    loadCameraPath("/nonexistent/dir/walk.json");
    FAIL() << "no error for a missing file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/walk.json: cannot open"), std::string::npos);
  }
}

CameraPath squarePath() {
  return parseCameraPath(R"({"fps": 10, "keyframes": [
      {"time": 0, "eye": [0, 0, 0], "target": [0, 0, -1], "fov": 30},
      {"time": 1, "eye": [1, 0, 0], "target": [1, 0, -1], "fov": 50},
      {"time": 3, "eye": [1, 0, 4], "target": [1, 0, 3], "fov": 40},
      {"time": 4, "eye": [0, 0, 4], "target": [0, 0, 3], "fov": 40}]})",
                         "square");
}

TEST(CameraPath, PassesThroughEveryKeyframeAtItsTime) {
  const CameraPath path = squarePath();
  for (const CameraKeyframe& k : path.keyframes) {
    const CameraPose pose = path.at(k.time);
    // Exact at the keyframe (u = 0 gives P1 in the pyramid up to float rounding of ~1 ulp).
    EXPECT_NEAR(glm::length(pose.eye - k.eye), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(pose.target - k.target), 0.0f, 1e-5f);
    EXPECT_NEAR(*pose.fovYDegrees, *k.fovYDegrees, 1e-4f);
  }
  // Clamped outside.
  EXPECT_EQ(path.at(-5.0).eye, path.keyframes.front().eye);
  EXPECT_EQ(path.at(99.0).eye, path.keyframes.back().eye);
}

TEST(CameraPath, IsContinuousAndSmoothAcrossKeyframes) {
  // Velocity (finite differences in time) just before and after keyframe 1: a Catmull–Rom
  // spline is C¹ in its knot parameter; in time the speed may change where segment
  // durations differ, but the *direction* of motion is continuous (tangents are parallel).
  const CameraPath path = squarePath();
  const double h = 1e-3;
  const Vec3 before = (path.at(1.0).eye - path.at(1.0 - h).eye) / float(h);
  const Vec3 after = (path.at(1.0 + h).eye - path.at(1.0).eye) / float(h);
  // cos of the angle between the two one-sided tangents; 0.999 allows the O(h) change of
  // direction within one finite-difference step (curvature × h), a kink would give ≪ 0.99.
  EXPECT_GT(glm::dot(glm::normalize(before), glm::normalize(after)), 0.999f);
  // No jumps: consecutive frames are close (the path is 10 units long over 4 s at 10 fps,
  // so ≈ 0.25 per frame; 0.6 leaves room for the speed-up along the long side).
  for (int f = 1; f < path.frameCount(); ++f)
    EXPECT_LT(glm::length(path.at(path.frameTime(f)).eye - path.at(path.frameTime(f - 1)).eye), 0.6f) << f;
}

TEST(CameraPath, CollinearKeyframesGiveAStraightLine) {
  // Centripetal Catmull–Rom through collinear points stays on the line (no overshoot
  // sideways); evenly spaced points in space and time give uniform motion.
  const CameraPath path = parseCameraPath(R"({"keyframes": [
      {"time": 0, "eye": [0, 0, 0], "target": [0, 0, -1]},
      {"time": 1, "eye": [1, 0, 0], "target": [1, 0, -1]},
      {"time": 2, "eye": [2, 0, 0], "target": [2, 0, -1]}]})",
                                          "line");
  for (double t = 0.0; t <= 2.0; t += 0.125) {
    const CameraPose pose = path.at(t);
    // Float rounding of the spline weights on coordinates ≤ 2: a few ulps (1e-6 off the line, 1e-5 along it).
    EXPECT_NEAR(pose.eye.y, 0.0f, 1e-6f);
    EXPECT_NEAR(pose.eye.z, 0.0f, 1e-6f);
    EXPECT_NEAR(pose.eye.x, float(t), 1e-5f);  // uniform motion
  }
}

TEST(CameraPath, StandingStillStaysStill) {
  const CameraPath path = parseCameraPath(R"({"keyframes": [
      {"time": 0, "eye": [0, 0, 0], "target": [0, 0, -1]},
      {"time": 1, "eye": [0, 0, 0], "target": [0, 0, -1]},
      {"time": 2, "eye": [5, 0, 0], "target": [5, 0, -1]}]})",
                                          "still");
  for (double t = 0.0; t <= 1.0; t += 0.1) EXPECT_EQ(path.at(t).eye, Vec3(0.0f));
}

TEST(CameraPath, OrbitKeepsDistanceAndReturnsToTheStart) {
  CameraDesc camera;  // looking at the origin from (0, 0, 5)
  camera.eye = {0, 0, 5};
  const CameraPath path = orbitPath(camera, 2.0, 10.0, 30.0f);
  ASSERT_EQ(path.keyframes.size(), 5u);
  EXPECT_EQ(path.frameCount(), 21);
  // 1e-5: float rounding of the rotation (sin, cos and products) on coordinates of size 5.
  for (const CameraKeyframe& k : path.keyframes) EXPECT_NEAR(glm::length(k.eye - k.target), 5.0f, 1e-5f);
  // Keyframe 1 is rotated by +30° about +y: x = 5·sin 30° = 2.5 (right-handed, counter-clockwise from above).
  EXPECT_NEAR(path.keyframes[1].eye.x, 2.5f, 1e-5f);
  EXPECT_NEAR(glm::length(path.keyframes[4].eye - camera.eye), 0.0f, 1e-5f);
  EXPECT_THROW(orbitPath(camera, 0.0), Error);
}

/// Path files go into a fresh directory per test.
class CameraPathFile : public test_support::TempDirTest {};

TEST_F(CameraPathFile, RoundTripsThroughTheFile) {
  const CameraPath path = squarePath();
  const std::string file = this->path("walk.json");
  saveCameraPath(file, path);
  const CameraPath back = loadCameraPath(file);
  ASSERT_EQ(back.keyframes.size(), path.keyframes.size());
  EXPECT_EQ(back.fps, path.fps);
  for (size_t i = 0; i < path.keyframes.size(); ++i) {
    EXPECT_EQ(back.keyframes[i].time, path.keyframes[i].time);
    EXPECT_EQ(back.keyframes[i].eye, path.keyframes[i].eye);  // floats print round-trippably
    EXPECT_EQ(back.keyframes[i].target, path.keyframes[i].target);
    EXPECT_EQ(back.keyframes[i].fovYDegrees, path.keyframes[i].fovYDegrees);
  }
}


// Light keyframes: each parameter linear in time between the keyframes that set it, held
// outside them; a direction renormalised; what no keyframe sets keeps the scene's value.
TEST(CameraPath, InterpolatesLightKeyframes) {
  const CameraPath path = parseCameraPath(R"({"fps": 10, "keyframes": [
      {"time": 0, "eye": [0, 0, 5], "target": [0, 0, 0],
       "lights": [{"light": 1, "direction": [1, -1, 0], "irradiance": [2, 2, 2]}]},
      {"time": 1, "eye": [0, 0, 5], "target": [0, 0, 0], "lights": [{"light": 1, "irradiance": 4}]},
      {"time": 2, "eye": [0, 0, 5], "target": [0, 0, 0], "lights": [{"light": 1, "direction": [-1, -1, 0]}]}]})",
                                          "sun.json");
  ASSERT_TRUE(path.animatesLights());
  const std::vector<Light> scene = {createLight("point", {{"intensity", 7.0f}}, "p"),
                                    createLight("directional", {{"direction", Vec3(0, -1, 0)}}, "d")};
  std::vector<Light> at = scene;
  path.lightsAt(0.5, at);
  EXPECT_EQ(lightEmission(at[0]), Rgb(7.0f));  // not animated
  EXPECT_NEAR(lightEmission(at[1]).g, 3.0f, 1e-6f);
  // The direction is keyed at 0 and 2: at 0.5 a quarter of the way, renormalised.
  const Vec3 expected = glm::normalize(Vec3(0.5f, -1.0f, 0.0f));
  const Vec3 direction = std::get<DirectionalLight>(at[1]).direction;
  EXPECT_NEAR(direction.x, expected.x, 1e-5f);
  EXPECT_NEAR(direction.y, expected.y, 1e-5f);
  at = scene;
  path.lightsAt(5.0, at);  // held after the last keyframe
  EXPECT_NEAR(lightEmission(at[1]).r, 4.0f, 1e-6f);
  EXPECT_NEAR(std::get<DirectionalLight>(at[1]).direction.x, -std::sqrt(0.5f), 1e-5f);
  // Round trip through the file format.
  const CameraPath again = parseCameraPath(cameraPathToJson(path), "again.json");
  std::vector<Light> a = scene, b = scene;
  path.lightsAt(1.3, a);
  again.lightsAt(1.3, b);
  EXPECT_EQ(lightEmission(a[1]), lightEmission(b[1]));
  EXPECT_EQ(std::get<DirectionalLight>(a[1]).direction, std::get<DirectionalLight>(b[1]).direction);
}

TEST(CameraPath, BadLightKeyframesNameTheKeyframe) {
  auto lightsAt = [](const std::string& lights, std::vector<Light> scene) {
    parseCameraPath(R"({"keyframes": [{"time": 0, "eye": [0, 0, 5], "target": [0, 0, 0], "lights": )" + lights + "}]}",
                    "bad.json")
        .lightsAt(0.0, scene);
  };
  const std::vector<Light> one = {createLight("point", {}, "p")};
  auto expectError = [&](const std::string& lights, const std::string& message) {
    try {
      lightsAt(lights, one);
      ADD_FAILURE() << "accepted " << lights;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  expectError(R"({"light": 0})", "'lights' must be an array");
  expectError(R"([{"intensity": 1}])", "bad.json: keyframe 0: lights[0]: expected an object with \"light\"");
  expectError(R"([{"light": -1}])", "'light' must be a light's index");
  expectError(R"([{"light": 3, "intensity": 1}])", "light 3 does not exist (the scene has 1)");
  expectError(R"([{"light": 0, "irradiance": 1}])", "unknown key 'irradiance' for a point light");
  expectError(R"([{"light": 0, "intensity": -1}])", "at time 0");
}

}  // namespace
}  // namespace pl
