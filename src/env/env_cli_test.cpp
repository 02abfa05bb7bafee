// Runs `plenoptic env ...` end to end (PLENOPTIC_BINARY): outputs written where the README
// says, numbers equal to the library's, clear errors and no output on bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "env/env.h"
#include "env/ibl.h"
#include "image/image.h"
#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;
const std::string kData = PLENOPTIC_TEST_DATA_DIR;
const std::string kVenice = kData + "/envmaps/venice_sunset_1k.hdr";

class EnvCliTest : public cli_test::CliTest {};

TEST_F(EnvCliTest, ShJsonMatchesLibrary) {
  std::string out;
  ASSERT_EQ(run("env sh " + kData + "/envmaps/pisa-cube --json", &out), 0);
  const auto j = nlohmann::json::parse(out);
  ASSERT_EQ(j["coefficients"].size(), 9u);
  const Sh9 sh = projectSh9(loadEnvironment(kData + "/envmaps/pisa-cube"));
  for (int k = 0; k < 9; ++k)
    for (int c = 0; c < 3; ++c)  // JSON prints doubles round-trip exactly; summation order may differ (threads)
      EXPECT_NEAR(j["coefficients"][size_t(k)][size_t(c)].get<double>(), sh.coefficients[size_t(k)][c],
                  1e-9 * (1.0 + std::abs(sh.coefficients[size_t(k)][c])));
}

TEST_F(EnvCliTest, ConvertIrradiancePrefilterSplitSum) {
  ASSERT_EQ(run("env convert " + kVenice + " -o " + path("cube") + " --layout cube --size 16"), 0);
  for (const char* face : kCubeFaceNames) EXPECT_EQ(readImage(path("cube/") + face + ".hdr").width, 16);
  ASSERT_EQ(run("env convert " + path("cube") + " -o " + path("cross.exr") + " --layout vcross"), 0);
  EXPECT_EQ(readImage(path("cross.exr")).height, 64);

  std::string out;
  ASSERT_EQ(run("env irradiance " + kVenice + " -o " + path("irr.exr") + " --size 8 --source-size 64", &out), 0);
  EXPECT_EQ(readImage(path("irr.exr")).width, 16);
  EXPECT_EQ(readImage(path("irr.sh.exr")).width, 16);
  EXPECT_NE(out.find("SH vs brute force"), std::string::npos) << out;

  ASSERT_EQ(run("env prefilter " + kVenice + " -o " + path("spec.exr") +
                " --levels 2 --size 16 --samples 16 --lut-size 4 --lut-samples 16"),
            0);
  EXPECT_EQ(readImage(path("spec.level0.exr")).width, 32);
  EXPECT_EQ(readImage(path("spec.level1.exr")).width, 32);
  EXPECT_EQ(readImage(path("spec.dfg.exr")).width, 4);

  ASSERT_EQ(run("env splitsum-error " + kVenice +
                    " --roughness 0.5 --view 0,60 --normals 2 --samples 64 --json --plot " + path("err.png"),
                &out),
            0);
  const auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j["cells"].size(), 2u);
  EXPECT_GT(readImage(path("err.png")).width, 0);
}

TEST_F(EnvCliTest, BadInputsFailCleanly) {
  std::string err;
  EXPECT_NE(run("env convert " + path("missing.hdr") + " -o " + path("x.exr"), nullptr, &err), 0);
  EXPECT_NE(err.find("missing.hdr"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("x.exr")));
  EXPECT_NE(run("env irradiance " + kVenice + " -o " + path("x.png"), nullptr, &err), 0);
  EXPECT_NE(err.find("x.png"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("x.png")));
  EXPECT_NE(run("env convert " + kVenice + " -o " + path("x.exr") + " --layout sphere", nullptr, &err), 0);
  EXPECT_NE(run("env splitsum-error " + kVenice + " --roughness 0 --normals 1 --samples 8", nullptr, &err), 0);
  EXPECT_NE(err.find("roughness"), std::string::npos) << err;
}

}  // namespace
}  // namespace pl
