// Relighting (relight.h): after sequences of changes the relit light field equals a fresh bake
// of the changed scene within the bake's tolerance; warm against cold start; refusals.
#include "bake/relight.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "bake/bake.h"
#include "bake/parameterisation.h"
#include "bake/visibility.h"
#include "core/error.h"
#include "core/progress.h"
#include "light/lights.h"
#include "plf/plf_file.h"
#include "plf/plv_file.h"
#include "support/expect_error.h"
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

class RelightTest : public ::testing::Test {
 protected:
  void SetUp() override { Progress::setEnabled(false); }
};

/// A bake with its parameterisation and visibility field kept, as a Relighter.
Relighter bakeForRelight(const Scene& scene, const BakeSettings& settings, LightField* baked = nullptr) {
  Parameterisation param;
  VisibilityShard visibility;
  BakeOptions options;
  options.keepParameterisation = &param;
  options.keepVisibility = &visibility;
  LightField lf = bake(scene, settings, options);
  Relighter relighter(lf, std::move(visibility), std::move(param));
  if (baked) *baked = std::move(lf);
  return relighter;
}

using test_support::relativeDifference;

/// The relit field against a fresh bake of the relighter's scene: the same within the
/// tolerance's order (both stop when their remaining error is below it), and the same sun masks.
void expectFreshBake(const Relighter& relighter, const BakeSettings& settings, const char* step) {
  const LightField relit = relighter.lightField();
  const LightField fresh = bake(relighter.scene(), settings);
  EXPECT_LT(relativeDifference(relit, fresh), 5.0 * settings.tolerance) << step;
  EXPECT_EQ(relit.sunMasks, fresh.sunMasks) << step;
  EXPECT_EQ(relit.sunMaskLightCount, fresh.sunMaskLightCount) << step;
}

TEST_F(RelightTest, CornellSequenceEqualsFreshBakes) {
  const BakeSettings settings = relightTestSettings();
  Relighter relighter = bakeForRelight(cornellWithPointLight(), settings);
  const uint32_t light = materialIndex(relighter.scene(), "light");
  const uint32_t red = materialIndex(relighter.scene(), "red");
  EXPECT_FALSE(relighter.pending());

  // 1. The area light recoloured: D_e scaled, nothing traced.
  relighter.setEmission(light, relighter.scene().materials[light].emission * Rgb(0.5f, 1.0f, 2.0f));
  EXPECT_TRUE(relighter.pending());
  RelightStats stats = relighter.relight();
  EXPECT_TRUE(stats.emittersScaled);
  EXPECT_FALSE(stats.emittersShot);
  EXPECT_EQ(stats.lightsShot, 0u);
  EXPECT_TRUE(stats.converged);
  EXPECT_FALSE(relighter.pending());
  expectFreshBake(relighter, settings, "area light recoloured");

  // 2. The point light moved and recoloured: only its first shot traced.
  Light moved = relighter.scene().lights[0];
  std::get<PointLight>(moved).position = Vec3(150.0f, 300.0f, 250.0f);
  setLightEmission(moved, Rgb(1e4f, 3e4f, 1e4f));
  relighter.setLight(0, moved);
  stats = relighter.relight();
  EXPECT_EQ(stats.lightsShot, 1u);
  EXPECT_FALSE(stats.emittersShot);
  EXPECT_TRUE(stats.converged);
  expectFreshBake(relighter, settings, "point light moved");

  // 3. An albedo, then 4. the point light switched off.
  relighter.setAlbedo(red, Rgb(0.2f, 0.5f, 0.7f));
  stats = relighter.relight();
  EXPECT_EQ(stats.lightsShot, 0u);
  EXPECT_TRUE(stats.converged);
  expectFreshBake(relighter, settings, "albedo");
  relighter.setLightEmission(0, Rgb(0.0f));
  stats = relighter.relight();
  EXPECT_EQ(stats.lightsShot, 0u);
  expectFreshBake(relighter, settings, "point light off");
}

// The built-in box's one light recoloured: the solution is scaled per channel, exactly
// converged, without an iteration.
TEST_F(RelightTest, RecolouringTheOnlyLightScalesTheSolution) {
  const BakeSettings settings = relightTestSettings();
  LightField baked;
  Relighter relighter = bakeForRelight(makeCornellBox(), settings, &baked);
  const uint32_t light = materialIndex(relighter.scene(), "light");
  relighter.setEmission(light, relighter.scene().materials[light].emission * 3.0f);
  uint32_t calls = 0;
  const RelightStats stats = relighter.relight([&](const RelightProgress& p) {
    ++calls;
    EXPECT_EQ(p.iteration, 0u);
    EXPECT_TRUE(p.converged);
    return true;
  });
  EXPECT_TRUE(stats.scaledWarmStart);
  EXPECT_EQ(stats.iterations, 0u);
  EXPECT_EQ(calls, 1u);
  const LightField relit = relighter.lightField();
  for (size_t v = 0; v < baked.values.size(); v += 97)
    EXPECT_NEAR(relit.values[v].g, 3.0f * baked.values[v].g, 1e-4f * (1.0f + baked.values[v].g));
  expectFreshBake(relighter, settings, "recoloured");
}

// Glossy charts (the McGuire glossy box: Blinn-Phong sphere and floor) through emission,
// albedo and a point light's changes.
TEST_F(RelightTest, GlossyBoxSequenceEqualsFreshBakes) {
  Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/CornellBox-Glossy.obj");
  scene.lights.push_back(createLight("point", {{"position", Vec3(0.0f, 1.2f, 0.3f)}, {"intensity", Vec3(0.5f)}}, "test"));
  scene.finalize();
  const BakeSettings settings = relightTestSettings(8.0f);
  Relighter relighter = bakeForRelight(scene, settings);
  const uint32_t light = materialIndex(relighter.scene(), "light");
  relighter.setEmission(light, Rgb(0.5f, 0.8f, 1.5f));
  relighter.setLightEmission(0, Rgb(1.0f, 0.3f, 0.2f));
  RelightStats stats = relighter.relight();
  EXPECT_TRUE(stats.converged);
  expectFreshBake(relighter, settings, "glossy: emission and light colour");
  Light moved = relighter.scene().lights[0];
  std::get<PointLight>(moved).position = Vec3(-0.4f, 1.0f, 0.0f);
  relighter.setLight(0, moved);
  relighter.setAlbedo(materialIndex(relighter.scene(), "rightWall"), Rgb(0.1f, 0.2f, 0.8f));
  EXPECT_THROW(relighter.setAlbedo(materialIndex(relighter.scene(), "sphere"), Rgb(0.5f)), Error);  // Blinn-Phong
  stats = relighter.relight();
  EXPECT_EQ(stats.lightsShot, 1u);
  EXPECT_TRUE(stats.converged);
  expectFreshBake(relighter, settings, "glossy: light moved, albedo");
}

TEST_F(RelightTest, SunMovedRetracesItsMasksOnly) {
  const BakeSettings settings = relightTestSettings(16.0f);
  Relighter relighter = bakeForRelight(sunScene(sunAt(40.0f, 20.0f)), settings);
  ASSERT_EQ(relighter.parameterisation().sunMaskLights.size(), 1u);
  Light sun = relighter.scene().lights[0];
  std::get<DirectionalLight>(sun).direction = sunAt(40.0f, 30.0f);  // 10° of azimuth
  relighter.setLight(0, sun);
  RelightStats stats = relighter.relight();
  EXPECT_EQ(stats.sunMasksTraced, 1u);
  EXPECT_EQ(stats.lightsShot, 1u);
  EXPECT_FALSE(stats.emittersShot);
  EXPECT_TRUE(stats.converged);
  expectFreshBake(relighter, settings, "sun moved");  // masks bit for bit
  // Sun colour: nothing traced.
  relighter.setLightEmission(0, Rgb(4.0f, 3.0f, 2.0f));
  stats = relighter.relight();
  EXPECT_EQ(stats.sunMasksTraced, 0u);
  EXPECT_EQ(stats.lightsShot, 0u);
  expectFreshBake(relighter, settings, "sun recoloured");
}

// A small change starts near the solution: fewer iterations than a cold bake, the same field.
TEST_F(RelightTest, WarmStartNeedsFewerIterationsThanColdStart) {
  const BakeSettings settings = relightTestSettings();
  Relighter relighter = bakeForRelight(cornellWithPointLight(), settings);
  Light moved = relighter.scene().lights[0];
  std::get<PointLight>(moved).position += Vec3(20.0f, 0.0f, 0.0f);
  relighter.setLight(0, moved);
  const RelightStats warm = relighter.relight();
  const LightField cold = bake(relighter.scene(), settings);
  EXPECT_TRUE(warm.converged);
  EXPECT_LT(warm.iterations, cold.stats.iterations);
  EXPECT_LT(relativeDifference(relighter.lightField(), cold), 5.0 * settings.tolerance);
}

// Iteration by iteration: the callback sees every iteration and may stop; the next relight()
// goes on to the same result.
TEST_F(RelightTest, CancelledRelightGoesOnLater) {
  const BakeSettings settings = relightTestSettings();
  Relighter relighter = bakeForRelight(cornellWithPointLight(), settings);
  relighter.setAlbedo(materialIndex(relighter.scene(), "white"), Rgb(0.3f));
  const RelightStats first = relighter.relight([](const RelightProgress& p) { return p.iteration < 1; });
  EXPECT_TRUE(first.cancelled);
  EXPECT_FALSE(first.converged);
  EXPECT_EQ(first.iterations, 1u);
  EXPECT_FALSE(relighter.pending());
  std::vector<double> residuals;
  const RelightStats rest = relighter.relight([&](const RelightProgress& p) {
    if (p.iteration > 0) residuals.push_back(p.residual);
    return true;
  });
  EXPECT_TRUE(rest.converged);
  EXPECT_EQ(residuals.size(), rest.iterations);
  expectFreshBake(relighter, settings, "after a cancelled relight");
}

void expectRefused(const std::function<void()>& change, const std::string& what) {
  try {
    change();
    ADD_FAILURE() << "not refused: " << what;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("cannot relight"), std::string::npos) << message;
    EXPECT_NE(message.find("plenoptic bake"), std::string::npos) << message;
  }
}

TEST_F(RelightTest, RefusesWhatTheFieldCannotServe) {
  const BakeSettings settings = relightTestSettings(6.0f);
  Relighter relighter = bakeForRelight(cornellWithPointLight(), settings);
  const Scene original = relighter.scene();
  expectRefused([&] { relighter.setLight(0, createLight("spot", {{"position", Vec3(278.0f, 400.0f, 200.0f)}}, "t")); },
                "a new light type");
  expectRefused([&] {
    Scene moved = original;
    moved.meshes[0].positions[0] += Vec3(10.0f);
    relighter.setScene(moved);
  }, "geometry moved");
  expectRefused([&] {
    Scene glass = original;
    glass.materials[materialIndex(glass, "red")].bsdf = DielectricBsdf{};
    relighter.setScene(glass);
  }, "diffuse to glass");
  expectRefused([&] {
    Scene more = original;
    more.lights.push_back(more.lights[0]);
    relighter.setScene(more);
  }, "a light added");
  expectRefused([&] {
    Light outside = original.lights[0];
    std::get<PointLight>(outside).position = Vec3(278.0f, 273.0f, 2000.0f);  // behind the back wall
    relighter.setLight(0, outside);
  }, "a light behind a one-sided wall");
  // Refusals change nothing.
  EXPECT_FALSE(relighter.pending());
  // A setScene with only lighting edits is taken.
  Scene edited = original;
  setLightEmission(edited.lights[0], Rgb(1e3f));
  edited.materials[materialIndex(edited, "green")].bsdf = LambertBsdf{Rgb(0.1f, 0.9f, 0.1f)};
  relighter.setScene(edited);
  EXPECT_TRUE(relighter.pending());
  EXPECT_TRUE(relighter.relight().converged);
  expectFreshBake(relighter, settings, "setScene");
}

TEST_F(RelightTest, RefusesAVisibilityFieldOfAnotherScene) {
  const BakeSettings settings = relightTestSettings(6.0f);
  Parameterisation param;
  VisibilityShard visibility;
  BakeOptions options;
  options.keepParameterisation = &param;
  options.keepVisibility = &visibility;
  bake(makeCornellBox(), settings, options);
  const LightField other = bake(sunScene(sunAt(40.0f, 0.0f)), settings);
  EXPECT_THROW(Relighter(other, std::move(visibility)), Error);
}

// Relighting a light field loaded from its files (.plf, .plv and the .plt the bake writes
// beside them) without filling the tixels again: the same parameterisation bit for bit, so the
// same relit light field bit for bit as relighting right after the bake.
class RelightFileTest : public test_support::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    Progress::setEnabled(false);
  }
};

/// Every tixel-setup array byte for byte, and the sun masks of the masked lights.
void expectSameTixelSetup(const Parameterisation& a, const Parameterisation& b) {
  ASSERT_EQ(a.tixelCount, b.tixelCount);
  ASSERT_EQ(a.charts.size(), b.charts.size());
  std::vector<std::pair<const void*, size_t>> arrays;
  forEachTixelSetupArray(a, [&](const char*, const auto& array) {
    arrays.emplace_back(array.data(), array.size() * sizeof(array[0]));
  });
  size_t index = 0;
  forEachTixelSetupArray(b, [&](const char* tag, const auto& array) {
    const size_t bytes = array.size() * sizeof(array[0]);
    ASSERT_EQ(bytes, arrays[index].second) << tag;
    EXPECT_TRUE(bytes == 0 || std::memcmp(array.data(), arrays[index].first, bytes) == 0) << tag;
    ++index;
  });
  ASSERT_EQ(a.sunMaskLights, b.sunMaskLights);
  for (uint64_t g = 0; g < a.tixelCount; ++g)
    for (size_t slot = 0; slot < a.sunMaskLights.size(); ++slot)
      ASSERT_EQ(a.sunMask[g][slot], b.sunMask[g][slot]) << "tixel " << g;
}

TEST_F(RelightFileTest, LoadedLightFieldRelightsAsRightAfterTheBake) {
  const BakeSettings settings = relightTestSettings(16.0f);
  Parameterisation param;
  VisibilityShard visibility;
  BakeOptions options;
  options.keepParameterisation = &param;
  options.keepVisibility = &visibility;
  options.visibilityPath = path("sun.plv");
  const LightField baked = bake(sunScene(sunAt(40.0f, 20.0f)), settings, options);
  writeLightField(path("sun.plf"), baked);
  ASSERT_TRUE(std::filesystem::exists(path("sun.plt")));
  const LightField loaded = readLightField(path("sun.plf"));

  std::vector<std::string> notes;
  const auto note = [&](const std::string& text) { notes.push_back(text); };
  auto filledAgain = [&] {
    for (const std::string& n : notes)
      if (n.find("filling the tixels again") != std::string::npos) return n;
    return std::string();
  };
  Relighter fromFiles(loaded, path("sun.plv"), note);
  EXPECT_EQ(filledAgain(), "");
  expectSameTixelSetup(fromFiles.parameterisation(), param);

  // The sun turned 10°: the same light field, bit for bit.
  const Parameterisation original = param;
  Relighter inMemory(baked, std::move(visibility), std::move(param));
  Light sun = baked.scene.lights[0];
  std::get<DirectionalLight>(sun).direction = sunAt(40.0f, 30.0f);
  inMemory.setLight(0, sun);
  fromFiles.setLight(0, sun);
  const RelightStats a = inMemory.relight(), b = fromFiles.relight();
  EXPECT_EQ(a.iterations, b.iterations);
  const LightField relitA = inMemory.lightField(), relitB = fromFiles.lightField();
  EXPECT_TRUE(relitA.values == relitB.values);
  EXPECT_EQ(relitA.sunMasks, relitB.sunMasks);
  expectSameTixelSetup(fromFiles.parameterisation(), inMemory.parameterisation());

  // Files without a .plt (written before it, or deleted), or with one of another bake: the
  // tixels are filled again, with a note, to the same parameterisation.
  std::filesystem::copy_file(path("sun.plt"), path("kept.plt"));
  std::filesystem::remove(path("sun.plt"));
  notes.clear();
  const Relighter withoutSetup(loaded, path("sun.plv"), note);
  EXPECT_NE(filledAgain().find("sun.plt does not exist"), std::string::npos) << filledAgain();
  expectSameTixelSetup(withoutSetup.parameterisation(), original);
  writeTixelSetup(path("sun.plt"), withoutSetup.scene(), withoutSetup.parameterisation(), 42);
  notes.clear();
  const Relighter otherBake(loaded, path("sun.plv"), note);
  EXPECT_NE(filledAgain().find("another bake"), std::string::npos) << filledAgain();

  // A damaged .plt: an error naming it.
  std::string bytes = test_support::readFileText(path("kept.plt"));
  bytes[bytes.size() / 2] = char(bytes[bytes.size() / 2] ^ 0x10);
  std::ofstream(path("sun.plt"), std::ios::binary | std::ios::trunc) << bytes;
  test_support::expectError([&] { Relighter broken(loaded, path("sun.plv")); }, {"sun.plt", "corrupt"});
  // No .plv: said at once, naming it.
  test_support::expectError([&] { Relighter none(loaded, path("none.plv")); }, {"none.plv", "does not exist"});
}

// bake --reuse-visibility takes the tixel setup saved beside the field (.plt), recomputing
// only what the edited scene changed: the light field is a full bake's of that scene, bit for
// bit, whatever changed and whether the .plt is there, stale or another bake's.
TEST_F(RelightFileTest, ReusedVisibilityTakesTheTixelSetupAndEqualsFullBakes) {
  const BakeSettings settings = relightTestSettings(16.0f);
  const Scene original = sunScene(sunAt(40.0f, 20.0f));
  BakeOptions save;
  save.visibilityPath = path("s.plv");
  bake(original, settings, save);
  ASSERT_TRUE(std::filesystem::exists(path("s.plt")));
  std::filesystem::copy_file(path("s.plt"), path("original.plt"));

  struct Case {
    const char* name;
    std::function<void(Scene&)> edit;
    const char* setupNote;  ///< what the tixel-setup note must say
  };
  const std::vector<Case> cases = {
      {"light colour", [](Scene& s) { setLightEmission(s.lights[0], Rgb(4.0f, 3.0f, 2.0f)); },
       "(0 charts of changed materials filled again, sun masks of 0 moved lights"},
      {"light moved",
       [](Scene& s) { std::get<DirectionalLight>(s.lights[0]).direction = sunAt(40.0f, 30.0f); },
       "(0 charts of changed materials filled again, sun masks of 1 moved lights"},
      {"albedo", [](Scene& s) { s.materials[0].bsdf = LambertBsdf{Rgb(0.2f, 0.5f, 0.7f)}; },
       "charts of changed materials filled again, sun masks of 0 moved lights"},
      {"no .plt", [&](Scene& s) {
         setLightEmission(s.lights[0], Rgb(1.0f, 2.0f, 3.0f));
         std::filesystem::remove(path("s.plt"));
       },
       "filling the tixels, because"},
      {"another bake's .plt", [&](Scene& s) {
         setLightEmission(s.lights[0], Rgb(1.0f, 2.0f, 3.0f));
         writeTixelSetup(path("s.plt"), s, buildParameterisation(s, settings), 42);
       },
       "belongs to another bake"},
  };
  for (const Case& c : cases) {
    std::filesystem::copy_file(path("original.plt"), path("s.plt"), std::filesystem::copy_options::overwrite_existing);
    Scene edited = original;
    c.edit(edited);
    edited.finalize();
    BakeOptions reuse;
    reuse.visibilityPath = path("s.plv");
    reuse.reuseVisibility = true;
    std::string notes;
    reuse.log = [&](const std::string& line) { notes += line + "\n"; };
    const LightField reused = bake(edited, settings, reuse);
    EXPECT_TRUE(reused.stats.reusedVisibility) << c.name << "\n" << notes;
    EXPECT_NE(notes.find(c.setupNote), std::string::npos) << c.name << "\n" << notes;
    const LightField full = bake(edited, settings);
    EXPECT_TRUE(reused.values == full.values) << c.name;
    EXPECT_EQ(reused.sunMasks, full.sunMasks) << c.name;
    // The .plt left beside the field is the edited scene's: reused again with nothing to redo.
    notes.clear();
    const LightField again = bake(edited, settings, reuse);
    EXPECT_NE(notes.find("(0 charts of changed materials filled again, sun masks of 0 moved lights"), std::string::npos)
        << c.name << "\n" << notes;
    EXPECT_TRUE(again.values == full.values) << c.name;
  }
}

}  // namespace
}  // namespace pl
