// The warm-started re-bake (warm_start.h): for each change relighting serves, the relit
// previous light field against a fresh bake of the changed scene (values and a render); a
// change it refuses, a damaged previous light field and one of another scene decline with the
// reason, and a cold bake's reuse of the .plt left behind stays bit-identical to a full bake.
#include "bake/warm_start.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "accel/accel.h"
#include "bake/bake.h"
#include "camera/camera.h"
#include "core/progress.h"
#include "env/env.h"
#include "image/compare.h"
#include "light/lights.h"
#include "plf/plf_file.h"
#include "render/render.h"
#include "support/light_field_difference.h"
#include "support/relight_scenes.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

using test_support::cornellWithPointLight;
using test_support::materialIndex;
using test_support::relightTestSettings;
using test_support::sunAt;
using test_support::sunScene;

class WarmStartTest : public test_support::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    Progress::setEnabled(false);
  }

  /// Bakes `scene` as `bake -o prev.plf` does: prev.plf, prev.plv, prev.plt.
  void bakePrevious(const Scene& scene, const BakeSettings& settings) {
    BakeOptions options;
    options.visibilityPath = path("prev.plv");
    writeLightField(path("prev.plf"), bake(scene, settings, options));
  }

  /// warmStartBake of `edited` from prev.plf (or `previous`), the notes in notes_.
  std::optional<LightField> warm(Scene edited, const BakeSettings& settings, WarmStartOutcome& outcome,
                                 const std::string& previous = "") {
    BakeOptions options;
    options.visibilityPath = path("prev.plv");
    notes_.clear();
    options.log = [&](const std::string& line) { notes_ += line + "\n"; };
    edited.finalize();
    return warmStartBake(edited, settings, previous.empty() ? path("prev.plf") : previous, options, outcome);
  }

  std::string notes_;
};

Image renderAt(const LightField& lf, const CameraDesc& desc) {
  const Accel accel(lf.scene);
  RenderSettings settings;
  settings.samplesPerPixel = 4;
  return renderLightField(lf, accel, Camera(desc, 48, 48), settings);
}

/// The warm-started field against a fresh bake of its scene: values within 5× the bake's
/// tolerance (relative L1; both stop once their remaining error is below the tolerance;
/// measured ≤ 7.1e-5 here, tolerance 1e-4), the same sun masks, and renders from `camera`
/// within relMSE 1e-5 (measured ≤ 4.2e-8).
void expectFreshBake(const LightField& warm, const BakeSettings& settings, const CameraDesc& camera, const char* step) {
  const LightField fresh = bake(warm.scene, settings);
  const double difference = test_support::relativeDifference(warm, fresh);
  EXPECT_LT(difference, 5.0 * settings.tolerance) << step;
  EXPECT_EQ(warm.sunMasks, fresh.sunMasks) << step;
  const ImageComparison images = compareImages(renderAt(warm, camera), renderAt(fresh, camera));
  EXPECT_LT(images.relMseAverage, 1e-5) << step;
  std::printf("[ measured ] %s: values %.2e, render relMSE %.2e\n", step, difference, images.relMseAverage);
}

CameraDesc cornellCamera() {
  CameraDesc desc;
  desc.eye = {278.0f, 273.0f, -800.0f};
  desc.target = {278.0f, 273.0f, 0.0f};
  desc.up = {0, 1, 0};
  desc.fovYDegrees = 39.0f;
  return desc;
}

TEST_F(WarmStartTest, LightColourIntensityAndAlbedoEqualFreshBakes) {
  const BakeSettings settings = relightTestSettings();
  const Scene original = cornellWithPointLight();
  bakePrevious(original, settings);
  struct Case {
    const char* name;
    std::function<void(Scene&)> edit;
  };
  const std::vector<Case> cases = {
      {"point light recoloured", [](Scene& s) { setLightEmission(s.lights[0], Rgb(3e4f, 2e4f, 0.5e4f)); }},
      {"area light scaled",
       [](Scene& s) { s.materials[materialIndex(s, "light")].emission *= 2.0f; }},
      {"albedo", [](Scene& s) { s.materials[materialIndex(s, "red")].bsdf = LambertBsdf{Rgb(0.2f, 0.5f, 0.7f)}; }},
      {"nothing", [](Scene&) {}},
  };
  for (const Case& c : cases) {
    Scene edited = original;
    c.edit(edited);
    WarmStartOutcome outcome;
    const std::optional<LightField> lf = warm(edited, settings, outcome);
    ASSERT_TRUE(lf) << c.name << ": " << outcome.reason;
    EXPECT_TRUE(outcome.used);
    EXPECT_TRUE(lf->stats.reusedVisibility);
    EXPECT_NE(notes_.find("warm start: relit"), std::string::npos) << notes_;
    EXPECT_EQ(outcome.relight.lightsShot, 0u) << c.name;  // nothing moved: nothing traced again
    expectFreshBake(*lf, settings, cornellCamera(), c.name);
  }
}

TEST_F(WarmStartTest, SunMovedEqualsAFreshBakeAndTheSetupLeftBehindStaysExact) {
  const BakeSettings settings = relightTestSettings(16.0f);
  bakePrevious(sunScene(sunAt(40.0f, 20.0f)), settings);
  CameraDesc camera;
  camera.eye = {5.0f, 6.0f, -6.0f};
  camera.target = {5.0f, 0.0f, 5.0f};
  camera.up = {0, 1, 0};
  camera.fovYDegrees = 60.0f;
  Scene moved = sunScene(sunAt(40.0f, 30.0f));  // 10° of azimuth
  moved.materials[0].bsdf = LambertBsdf{Rgb(0.3f, 0.6f, 0.4f)};
  WarmStartOutcome outcome;
  const std::optional<LightField> lf = warm(moved, settings, outcome);
  ASSERT_TRUE(lf) << outcome.reason;
  EXPECT_EQ(outcome.relight.sunMasksTraced, 1u);
  EXPECT_EQ(outcome.relight.lightsShot, 1u);
  expectFreshBake(*lf, settings, camera, "sun moved, albedo changed");

  // The .plt left beside the .plv marks the relit material: a cold reuse fills its charts
  // again and is a full bake's light field bit for bit; a warm start from the relit field
  // (written as `bake -o` would) relights it again.
  writeLightField(path("prev.plf"), *lf);
  BakeOptions cold;
  cold.visibilityPath = path("prev.plv");
  cold.reuseVisibility = true;
  std::string notes;
  cold.log = [&](const std::string& line) { notes += line + "\n"; };
  const LightField reused = bake(lf->scene, settings, cold);
  EXPECT_NE(notes.find("charts of changed materials filled again, sun masks of 0 moved lights"), std::string::npos)
      << notes;
  EXPECT_EQ(notes.find("(0 charts of changed materials"), std::string::npos) << notes;
  EXPECT_TRUE(reused.values == bake(lf->scene, settings).values);
  Scene again = lf->scene;
  setLightEmission(again.lights[0], Rgb(4.0f, 3.0f, 2.0f));
  const std::optional<LightField> twice = warm(again, settings, outcome);
  ASSERT_TRUE(twice) << outcome.reason;
  expectFreshBake(*twice, settings, camera, "then recoloured");
}

// The scene to bake holds its own copy of the sky (loaded again): an unchanged map is not a
// changed environment, so only the recoloured sun is recombined, nothing is shot again.
TEST_F(WarmStartTest, AnUnchangedSkyMapIsNotShotAgain) {
  const BakeSettings settings = relightTestSettings(8.0f);
  auto withSky = [](Scene scene) {
    Image sky(16, 8);
    for (int y = 0; y < sky.height; ++y)
      for (int x = 0; x < sky.width; ++x) sky.at(x, y) = Rgb(0.1f + 0.05f * float(x % 4), 0.2f, 0.1f * float(y));
    scene.environment.map = std::make_shared<const EnvironmentMap>(LatLongMap{std::move(sky)}, 0.8f, 30.0f);
    return scene;
  };
  bakePrevious(withSky(sunScene(sunAt(40.0f, 20.0f))), settings);
  Scene recoloured = withSky(sunScene(sunAt(40.0f, 20.0f)));
  setLightEmission(recoloured.lights[0], Rgb(4.0f, 3.0f, 2.0f));
  WarmStartOutcome outcome;
  ASSERT_TRUE(warm(recoloured, settings, outcome)) << outcome.reason;
  EXPECT_FALSE(outcome.relight.emittersShot);
  EXPECT_EQ(outcome.relight.lightsShot, 0u);
}

TEST_F(WarmStartTest, DeclinesWithTheReason) {
  const BakeSettings settings = relightTestSettings();
  const Scene original = cornellWithPointLight();
  WarmStartOutcome outcome;
  auto declined = [&](const Scene& scene, const BakeSettings& s, const std::string& why, const std::string& previous = "") {
    const std::optional<LightField> lf = warm(scene, s, outcome, previous);
    EXPECT_FALSE(lf) << why;
    EXPECT_FALSE(outcome.used);
    EXPECT_NE(outcome.reason.find(why), std::string::npos) << outcome.reason;
    EXPECT_NE(notes_.find("warm start: not used, because"), std::string::npos) << notes_;
  };
  declined(original, settings, "no previous light field");
  bakePrevious(original, settings);

  // A material's model changed: the Relighter refuses it.
  Scene glossy = original;
  glossy.materials[materialIndex(glossy, "red")].bsdf = GgxBsdf{};
  declined(glossy, settings, "cannot relight");
  // Other settings.
  BakeSettings other = settings;
  other.tolerance = 1e-3f;
  declined(original, other, "other settings: tolerance");
  // Another scene's light field (the sun scene, baked beside).
  BakeOptions beside;
  beside.visibilityPath = path("sun.plv");
  writeLightField(path("sun.plf"), bake(sunScene(sunAt(40.0f, 20.0f)), settings, beside));
  declined(original, settings, "the tixel setup has", path("sun.plf"));
  // A damaged light field: every byte flipped in its middle.
  std::string bytes = test_support::readFileText(path("prev.plf"));
  for (size_t i = bytes.size() / 3; i < bytes.size() / 3 + 64; ++i) bytes[i] = char(bytes[i] ^ 0x5a);
  std::ofstream(path("damaged.plf"), std::ios::binary | std::ios::trunc) << bytes;
  declined(original, settings, "damaged.plf", path("damaged.plf"));
  std::ofstream(path("short.plf"), std::ios::binary | std::ios::trunc) << bytes.substr(0, 10);
  declined(original, settings, "short.plf", path("short.plf"));
}

}  // namespace
}  // namespace pl
