// The JSON scene's "environment" block (src/scene/json_scene.cpp) loads an EnvironmentMap
// with its scale and rotation, and Environment::radiance combines it with the constant.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "core/error.h"
#include "env/env.h"
#include "scene/scene.h"

namespace pl {
namespace {

namespace fs = std::filesystem;
const std::string kData = PLENOPTIC_TEST_DATA_DIR;

TEST(EnvScene, JsonEnvironmentFileScaleRotation) {
  const Scene scene = loadScene(kData + "/env/cornell_sky.json");
  ASSERT_TRUE(scene.environment.map);
  const EnvironmentMap& map = *scene.environment.map;
  EXPECT_EQ(map.map().width(), 16);
  EXPECT_FLOAT_EQ(map.scale(), 2.0f);
  EXPECT_FLOAT_EQ(map.rotationDegrees(), 90.0f);
  // The sun texel (10, 2) of sky_16x8.hdr, seen through the +90° rotation, times scale 2,
  // plus the constant 0.01. The file stores 50 as RGBE mantissa 200, exponent 2⁻²; like
  // Radiance's own reader, the decoder returns the centre of the mantissa's bucket,
  // (200 + ½)/4 = 50.125. 1e-3: float rounding of the rotation round trip moves the bilinear
  // lookup off the texel centre by ~1e-6 texel, and neighbours differ by < 100.
  const Vec3 sunMap = LatLongMap::direction(10.5 / 16.0, 2.5 / 8.0);
  const Rgb sun = scene.environment.radiance(map.toWorld(sunMap));
  EXPECT_NEAR(sun.r, 2.0f * 50.125f + 0.01f, 1e-3f);
  // Below the horizon: ground colour (0.2, 0.15, 0.1) × 2 + 0.01 (RGBE rounding ≤ 2^-8 relative).
  const Rgb ground = scene.environment.radiance(Vec3(0, -1, 0));
  EXPECT_NEAR(ground.r, 0.41f, 0.41f / 128.0f);
  EXPECT_NEAR(ground.b, 0.21f, 0.21f / 128.0f);
  EXPECT_FALSE(scene.environment.isBlack());
  // The map is importance-sampled towards the sun: the sun texel and its bilinear spill
  // hold ~45 % of the sampling weight (measured 445 of 1000 within 23°), whereas uniform
  // sampling would put ~4 % of the samples in that cone (0.5 sr of 4π).
  int nearSun = 0;
  for (int i = 0; i < 1000; ++i) {
    const EnvironmentSample s = map.sample({(i + 0.5f) / 1000.0f, std::fmod(i * 0.618034f, 1.0f)});
    if (glm::dot(s.direction, map.toWorld(sunMap)) > std::cos(0.4f)) ++nearSun;
  }
  EXPECT_GT(nearSun, 300);
}

TEST(EnvScene, JsonEnvironmentErrorsNameBothFiles) {
  const fs::path dir = fs::temp_directory_path() / ("pl_env_scene_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto load = [&](const std::string& body) -> std::string {
    const fs::path json = dir / "s.json";
    std::ofstream(json) << body;
    try {
      loadScene(json.string());
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  std::string msg = load(R"({"include_cornell": true, "environment": {"file": "nope.hdr"}})");
  EXPECT_NE(msg.find("s.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("nope.hdr"), std::string::npos) << msg;
  msg = load(R"({"include_cornell": true, "environment": {"rotation": 30}})");
  EXPECT_NE(msg.find("need a \"file\""), std::string::npos) << msg;
  msg = load(R"({"include_cornell": true, "environment": {"file": "x.hdr", "scael": 2}})");
  EXPECT_NE(msg.find("scael"), std::string::npos) << msg;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pl
