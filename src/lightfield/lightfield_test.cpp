// The JSON schema of the bake's settings and statistics (lightfield.h toJson / fromJson).
#include "lightfield/lightfield.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bake/bake.h"

namespace pl {
namespace {

// The bake's settings and statistics have one JSON schema (lightfield.h toJson/fromJson): what
// the .plf's META, `info --json` and `bake --stats` write, read back field for field.
TEST(BakeJsonSchema, SettingsAndStatsRoundTripAndOldFilesMeanNoSunMasksOrHighlights) {
  BakeSettings settings = bakePreset("high");
  settings.tixelsPerUnit = 3.5f;
  settings.seed = 77;
  settings.sunMasks = true;
  settings.punctualHighlights = true;
  const nlohmann::json json = toJson(settings);
  EXPECT_EQ(json.at("gather_directions"), 576);
  EXPECT_EQ(json.at("tixels_per_unit"), 3.5f);
  BakeSettings back;
  fromJson(json, back);
  EXPECT_EQ(toJson(back), json);
  EXPECT_EQ(back.seed, 77u);

  // A writer from before sun masks and punctual highlights: both off; keys it lacks keep their values.
  nlohmann::json old = json;
  old.erase("sun_masks");
  old.erase("punctual_highlights");
  old.erase("seed");
  old["a_key_from_a_newer_writer"] = 1;
  BakeSettings fromOld;
  fromOld.seed = 5;
  fromJson(old, fromOld);
  EXPECT_FALSE(fromOld.sunMasks);
  EXPECT_FALSE(fromOld.punctualHighlights);
  EXPECT_EQ(fromOld.seed, 5u);

  BakeStats stats;
  stats.seconds = 1.25;
  stats.iterations = 7;
  stats.visibilityRays = uint64_t(1) << 40;
  stats.reusedVisibility = true;
  BakeStats statsBack;
  fromJson(toJson(stats), statsBack);
  EXPECT_EQ(toJson(statsBack), toJson(stats));
  EXPECT_EQ(statsBack.visibilityRays, uint64_t(1) << 40);
  EXPECT_THROW(fromJson(nlohmann::json{{"iterations", "seven"}}, statsBack), nlohmann::json::exception);
}

}  // namespace
}  // namespace pl
