// The first shot by source beside the visibility field (first_shot.h): the file round trip,
// every stale or damaged file read as none with the reason, a bake of a scene without scene
// lights writing it and a Relighter reading it instead of shooting — with the same light field
// bit for bit — and a warm-started re-bake leaving the one of its new scene behind.
#include "bake/first_shot.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "bake/bake.h"
#include "bake/relight.h"
#include "bake/warm_start.h"
#include "core/progress.h"
#include "plf/plf_file.h"
#include "support/relight_scenes.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

using test_support::materialIndex;
using test_support::relightTestSettings;
using test_support::sunAt;
using test_support::sunScene;

class FirstShotTest : public test_support::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    Progress::setEnabled(false);
  }
};

FirstShotBySource sampleShot(uint64_t values, uint32_t lights, bool punctual) {
  FirstShotBySource shot;
  auto array = [&](float seed) {
    std::vector<Rgb> a(values);
    for (uint64_t v = 0; v < values; ++v) a[v] = Rgb(seed + float(v), seed * 2.0f, -float(v));
    return a;
  };
  for (uint32_t l = 0; l < lights; ++l) {
    shot.lightDirect.push_back(array(float(l) + 0.5f));
    if (punctual) shot.lightPunctual.push_back(array(float(l) + 0.25f));
  }
  shot.emitterDirect = array(7.0f);
  return shot;
}

void flipByte(const std::string& path, uint64_t at) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(std::streamoff(at));
  char c = 0;
  f.get(c);
  f.seekp(std::streamoff(at));
  f.put(char(c ^ 0x5a));
}

TEST_F(FirstShotTest, RoundTripsAndReadsEveryStaleOrDamagedFileAsNone) {
  const std::string file = path("x.pls");
  EXPECT_EQ(firstShotPathFor("/a/b/x.plv"), "/a/b/x.pls");
  const FirstShotBySource shot = sampleShot(37, 2, true);
  writeFirstShot(file, 11, 22, shot);
  FirstShotBySource read;
  std::string why;
  ASSERT_TRUE(readFirstShot(file, 11, 22, 2, 37, true, read, &why)) << why;
  EXPECT_EQ(read.lightDirect, shot.lightDirect);
  EXPECT_EQ(read.lightPunctual, shot.lightPunctual);
  EXPECT_EQ(read.emitterDirect, shot.emitterDirect);

  auto expectNone = [&](uint64_t hash, uint64_t key, uint32_t lights, uint64_t values, bool punctual,
                        const std::string& reason) {
    FirstShotBySource untouched;
    std::string because;
    EXPECT_FALSE(readFirstShot(file, hash, key, lights, values, punctual, untouched, &because)) << reason;
    EXPECT_NE(because.find(reason), std::string::npos) << because;
    EXPECT_TRUE(untouched.emitterDirect.empty());
  };
  expectNone(12, 22, 2, 37, true, "stale");   // another .plv
  expectNone(11, 23, 2, 37, true, "stale");   // another scene
  expectNone(11, 22, 3, 37, true, "holds 2 lights");
  expectNone(11, 22, 2, 38, true, "holds 2 lights");
  expectNone(11, 22, 2, 37, false, "punctual");
  const uint64_t size = std::filesystem::file_size(file);
  flipByte(file, size - 5);  // a value
  expectNone(11, 22, 2, 37, true, "checksum");
  writeFirstShot(file, 11, 22, shot);
  std::filesystem::resize_file(file, size - 12);
  expectNone(11, 22, 2, 37, true, "damaged");
  writeFirstShot(file, 11, 22, shot);
  flipByte(file, 0);
  expectNone(11, 22, 2, 37, true, "not a .pls");
  writeFirstShot(file, 11, 22, shot);
  flipByte(file, 8);  // the version
  expectNone(11, 22, 2, 37, true, "version");
  std::filesystem::resize_file(file, 20);
  expectNone(11, 22, 2, 37, true, "header");
  std::filesystem::remove(file);
  expectNone(11, 22, 2, 37, true, "there is no");

  // Without punctual parts, no lights.
  const FirstShotBySource emitters = sampleShot(5, 0, false);
  writeFirstShot(file, 1, 2, emitters);
  ASSERT_TRUE(readFirstShot(file, 1, 2, 0, 5, false, read, &why)) << why;
  EXPECT_EQ(read.emitterDirect, emitters.emitterDirect);
  EXPECT_TRUE(read.lightDirect.empty());
}

// The built-in box has no scene lights: its bake's first shot is D_e, written beside the .plv.
// A Relighter reads it instead of shooting, and relights to the same light field bit for bit as
// one that shot it; a damaged file is shot again, with a note saying why.
TEST_F(FirstShotTest, ABakeWritesItAndTheRelighterReadsItToTheSameField) {
  const BakeSettings settings = relightTestSettings();
  Scene scene = makeCornellBox();
  scene.finalize();
  ASSERT_TRUE(scene.lights.empty());
  BakeOptions options;
  options.visibilityPath = path("box.plv");
  writeLightField(path("box.plf"), bake(scene, settings, options));
  ASSERT_TRUE(std::filesystem::exists(path("box.pls")));
  const LightField lf = readLightField(path("box.plf"));

  auto relit = [&](std::string& notes) {
    notes.clear();
    Relighter relighter(lf, path("box.plv"), [&](const std::string& line) { notes += line + "\n"; });
    relighter.setAlbedo(materialIndex(relighter.scene(), "red"), Rgb(0.2f, 0.5f, 0.7f));
    relighter.relight();
    return relighter.lightField().values;
  };
  std::string notes;
  const std::vector<Rgb> fromFile = relit(notes);
  EXPECT_NE(notes.find("(read from " + path("box.pls") + ")"), std::string::npos) << notes;
  flipByte(path("box.pls"), std::filesystem::file_size(path("box.pls")) - 1);
  const std::vector<Rgb> shot = relit(notes);
  EXPECT_NE(notes.find("shooting the first shot by source again, because " + path("box.pls") + " is damaged"),
            std::string::npos)
      << notes;
  EXPECT_TRUE(fromFile == shot);
  std::filesystem::remove(path("box.pls"));
  EXPECT_TRUE(relit(notes) == shot);
  EXPECT_EQ(notes.find("read from"), std::string::npos) << notes;
}

// A scene with a sun: the bake shoots its first shot by source and writes it; a warm-started
// re-bake for a moved sun reads the rest and shoots the sun alone — to the light field it
// would relight to shooting everything (the bake's parts are a relight's bit for bit) — and
// leaves the first shot of its new scene, which the next one (from the relit light field, as
// `bake -o` leaves it) reads.
TEST_F(FirstShotTest, ABakeWithASunAndEachWarmStartLeaveTheFirstShotOfTheirSceneForTheNext) {
  const BakeSettings settings = relightTestSettings(8.0f);
  BakeOptions options;
  options.visibilityPath = path("prev.plv");
  std::string notes;
  options.log = [&](const std::string& line) { notes += line + "\n"; };
  writeLightField(path("prev.plf"), bake(sunScene(sunAt(40.0f, 20.0f)), settings, options));
  ASSERT_TRUE(std::filesystem::exists(path("prev.pls"))) << notes;
  auto warm = [&](Scene edited) {
    notes.clear();
    edited.finalize();
    WarmStartOutcome outcome;
    std::optional<LightField> lf = warmStartBake(edited, settings, path("prev.plf"), options, outcome);
    EXPECT_TRUE(lf) << outcome.reason;
    return lf ? *lf : LightField{};
  };
  Scene moved = sunScene(sunAt(40.0f, 30.0f));
  const LightField first = warm(moved);
  EXPECT_NE(notes.find("(read from " + path("prev.pls") + ")"), std::string::npos) << notes;
  EXPECT_NE(notes.find("1 lights and 1 sun masks traced again"), std::string::npos) << notes;
  std::filesystem::remove(path("prev.pls"));
  EXPECT_TRUE(warm(moved).values == first.values);
  EXPECT_EQ(notes.find("read from"), std::string::npos) << notes;
  ASSERT_TRUE(std::filesystem::exists(path("prev.pls")));
  writeLightField(path("prev.plf"), first);
  Scene recoloured = first.scene;
  setLightEmission(recoloured.lights[0], Rgb(4.0f, 3.0f, 2.0f));
  const LightField second = warm(recoloured);
  EXPECT_NE(notes.find("(read from " + path("prev.pls") + ")"), std::string::npos) << notes;
  std::filesystem::remove(path("prev.pls"));
  const LightField shot = warm(recoloured);
  EXPECT_EQ(notes.find("read from"), std::string::npos) << notes;
  EXPECT_TRUE(second.values == shot.values);
}

// A bake's first shot is the sum of its parts by source, each light's at unit emission times
// its emission: the same light field whether the bake keeps the parts (one process writing a
// .pls) or not (no .plv), bit for bit.
TEST_F(FirstShotTest, ABakeIsTheSameWhetherItKeepsTheFirstShotBySourceOrNot) {
  const BakeSettings settings = relightTestSettings(8.0f);
  Scene scene = sunScene(sunAt(40.0f, 20.0f));
  setLightEmission(scene.lights[0], Rgb(5.0f, 2.5f, 1.0f));
  BakeOptions kept;
  kept.visibilityPath = path("kept.plv");
  const LightField withFile = bake(scene, settings, kept);
  ASSERT_TRUE(std::filesystem::exists(path("kept.pls")));
  const LightField without = bake(scene, settings, BakeOptions{});
  EXPECT_TRUE(withFile.values == without.values);
}

}  // namespace
}  // namespace pl
