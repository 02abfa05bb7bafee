// The .plv file on its own: a hand-made field written and read back, and extra records with
// absurd contents refused though the file's checksums are valid. The round trips of traced
// fields, stale and corrupt files and the reuse decision are the bake's (bake/bake_test.cpp).
#include "plf/plv_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"

namespace pl {
namespace {

/// A two-tixel field (grid 1): tixel 0 sees tixel 1 through a mirror (one extra record),
/// tixel 1 sees the environment.
VisibilityField tinyField(const VisibilityExtra& extra) {
  VisibilityField field;
  field.gridSide = 1;
  field.tixelCount = 2;
  field.hash = 0x1234;
  VisibilityEntry seen, escaped;
  seen.target = 1u | VisibilityEntry::kHasExtra;
  field.entries = FieldArray<VisibilityEntry>(std::vector<VisibilityEntry>{seen, escaped});
  field.extraOffset = FieldArray<uint64_t>(std::vector<uint64_t>{0, 1, 1});
  field.extras = FieldArray<VisibilityExtra>(std::vector<VisibilityExtra>{extra});
  return field;
}

TEST(VisibilityFile, RecordsWithAbsurdContentsAreRefusedDespiteAValidChecksum) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "plenoptic_plv_contents_test";
  std::filesystem::create_directories(dir);
  const std::string plv = (dir / "crafted.plv").string();
  VisibilityField read;
  std::string why;
  const VisibilityExtra sane{Rgb(0.9f, 0.5f, 0.0f), Vec2(-1.0f, 0.7f), 1};
  writeVisibility(plv, tinyField(sane));
  ASSERT_TRUE(readVisibility(plv, 0x1234, read, &why)) << why;
  EXPECT_EQ(read.extras[0].throughput, sane.throughput);

  const float nan = std::numeric_limits<float>::quiet_NaN();
  const struct {
    VisibilityExtra extra;
    const char* problem;
  } cases[] = {
      {{Rgb(1e9f, 1.0f, 1.0f), Vec2(0.0f), 1}, "throughput 1000000000 outside [0, 1]"},
      {{Rgb(1.0f, nan, 1.0f), Vec2(0.0f), 1}, "throughput nan outside [0, 1]"},
      {{Rgb(1.0f, 1.0f, -0.5f), Vec2(0.0f), 1}, "throughput -0.5 outside [0, 1]"},
      {{Rgb(1.0f), Vec2(0.0f, 3.0f), 1}, "direction coordinate 3 outside [-1, 1]"},
      {{Rgb(1.0f), Vec2(nan, 0.0f), 1}, "direction coordinate nan outside [-1, 1]"},
      {{Rgb(1.0f), Vec2(0.0f), 7}, "mirror flag of 7"},
  };
  for (const auto& c : cases) {
    writeVisibility(plv, tinyField(c.extra));
    try {
      readVisibility(plv, 0x1234, read, &why);
      ADD_FAILURE() << "accepted: " << c.problem;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("crafted.plv: extra record 0"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.problem), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pl
