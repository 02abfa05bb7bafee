// The viewer's live relighting (live_relight.h) without a window: keys edit the lighting, the
// background propagation converges, and the light field on screen is the relit one.
#include "viewer/live_relight.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bake/relight.h"
#include "camera/camera.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "viewer/core_share.h"

namespace pl {
namespace {

class LiveRelightTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Progress::setEnabled(false);
    // One directory per test: ctest runs the tests of this fixture in parallel processes.
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("plenoptic_live_relight_test_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    BakeSettings settings = bakePreset("draft");
    settings.tixelsAcrossScene = 8.0f;
    settings.gatherDirections = 64;
    settings.tolerance = 1e-4f;
    BakeOptions options;
    options.visibilityPath = (dir_ / "cornell.plv").string();
    lightField_ = bake(makeCornellBox(), settings, options);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Σ of the diffuse values' green channel: the light field's brightness.
  static double total(const LightField& lf) {
    double sum = 0.0;
    for (const Rgb& v : lf.values) sum += v.g;
    return sum;
  }

  std::filesystem::path dir_;
  LightField lightField_;
};

TEST_F(LiveRelightTest, KeysRelightInTheBackground) {
  const Accel accel(lightField_.scene);
  LiveRelight live(lightField_, accel, (dir_ / "cornell.plv").string());
  EXPECT_EQ(live.renderer(), nullptr);
  EXPECT_EQ(&live.lightField(), &lightField_);
  // The built-in box has no scene lights: the first source is its emitters.
  live.press(RelightKey::Brighter);
  EXPECT_TRUE(live.busy());  // from the key on, until the relight is done
  live.waitIdle();
  EXPECT_FALSE(live.busy());
  live.update();
  ASSERT_NE(live.renderer(), nullptr);
  RelightStatus status = live.status();
  EXPECT_TRUE(status.ready);
  EXPECT_TRUE(status.converged);
  EXPECT_TRUE(status.message.empty()) << status.message;
  EXPECT_NEAR(total(live.lightField()), 1.25 * total(lightField_), 1e-3 * total(lightField_));
  EXPECT_NE(live.hudLines().back().find("CONVERGED"), std::string::npos);
  // Emitters off: a dark box.
  live.press(RelightKey::ToggleSource);
  live.waitIdle();
  live.update();
  EXPECT_NEAR(total(live.lightField()), 0.0, 1e-6 * total(lightField_));
  // On again, and a darker material: less light than before.
  live.press(RelightKey::ToggleSource);
  for (int k = 0; k < 5; ++k) live.press(RelightKey::Darker);
  live.waitIdle();
  live.update();
  status = live.status();
  EXPECT_TRUE(status.converged);
  EXPECT_LT(total(live.lightField()), 1.25 * total(lightField_));
  // Turning a sun that is not there does nothing and refuses nothing.
  live.press(RelightKey::SunLeft);
  live.waitIdle();
  EXPECT_TRUE(live.status().message.empty());
}

// The viewer's frames beside the relighter (core_share.h, Split): the renderer on the pool's
// threads − 1 while the relighter is busy, the whole pool once it is done; and the relight,
// with frames drawn all along, converges to the light field the Relighter alone gives.
TEST_F(LiveRelightTest, ConvergesToTheSameLightFieldWhileFramesAreDrawn) {
  const ThreadPool pool(2);
  const Accel accel(lightField_.scene);
  const FastRenderer baked(lightField_, accel);
  const std::string plv = (dir_ / "cornell.plv").string();
  LiveRelight live(lightField_, accel, plv, RelightShare::Split);
  live.press(RelightKey::Brighter);
  const CameraDesc desc = lightField_.scene.automaticCamera();
  Image image;
  int framesBeside = 0, framesAfter = 0;
  for (int frame = 0; frame < 100000 && framesAfter < 3; ++frame) {
    live.update();
    const bool busy = live.busy();
    const CoreShare share = coreShare(RelightShare::Split, parallelThreads(), busy, true, 30.0);
    EXPECT_EQ(share.renderThreads, busy ? 1 : 0);
    EXPECT_EQ(share.targetFps, busy ? kRelightTargetFps : 30.0);
    const FastRenderer& renderer = live.renderer() ? *live.renderer() : baked;
    drawWithShare(share, [&] { renderer.render(Camera(desc, 32, 24), RenderSettings{}, image); });
    if (busy) ++framesBeside;
    else if (live.showsNewest()) ++framesAfter;
  }
  EXPECT_GT(framesBeside, 0);
  ASSERT_EQ(framesAfter, 3);
  const RelightStatus status = live.status();
  EXPECT_TRUE(status.converged);
  EXPECT_TRUE(status.message.empty()) << status.message;
  // The same edit by the Relighter alone, on the whole pool.
  Relighter alone(lightField_, plv);
  for (uint32_t m = 0; m < lightField_.scene.materials.size(); ++m)
    if (!isBlack(lightField_.scene.materials[m].emission))
      alone.setEmission(m, lightField_.scene.materials[m].emission * 1.25f);
  ASSERT_TRUE(alone.relight().converged);
  const LightField expected = alone.lightField();
  const LightField& relit = live.lightField();
  ASSERT_EQ(relit.values.size(), expected.values.size());
  double difference = 0.0, norm = 0.0;
  for (size_t i = 0; i < relit.values.size(); ++i) {
    const Rgb d = relit.values[i] - expected.values[i];
    difference += double(glm::dot(d, d));
    norm += double(glm::dot(expected.values[i], expected.values[i]));
  }
  EXPECT_LT(std::sqrt(difference / norm), 1e-4);
}

TEST_F(LiveRelightTest, AMissingVisibilityFieldTurnsRelightingOff) {
  const Accel accel(lightField_.scene);
  LiveRelight live(lightField_, accel, (dir_ / "absent.plv").string());
  live.press(RelightKey::Brighter);
  live.waitIdle();
  const RelightStatus status = live.status();
  EXPECT_FALSE(status.ready);
  EXPECT_FALSE(live.busy());  // off: the renderer keeps every core
  EXPECT_NE(status.message.find("absent.plv"), std::string::npos) << status.message;
  EXPECT_EQ(live.renderer(), nullptr);
}

}  // namespace
}  // namespace pl
