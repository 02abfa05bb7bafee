// Runs the `plenoptic trace` command end to end (PLENOPTIC_BINARY): files written on success,
// clear errors and no output on bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "image/image.h"
#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

class TraceCliTest : public cli_test::CliTest {
 protected:
  void checkPixelReplay(const std::string& flags);
};

TEST_F(TraceCliTest, WritesImageAndStats) {
  const std::string out = path("cornell.exr"), stats = path("stats.json");
  ASSERT_EQ(run("trace cornell -o " + out + " --width 32 --height 24 --spp 4 --stats " + stats), 0);
  const Image image = readImage(out);
  EXPECT_EQ(image.width, 32);
  EXPECT_EQ(image.height, 24);
  double sum = 0.0;
  for (const Rgb& p : image.pixels) {
    EXPECT_TRUE(isFinite(p));
    sum += luminance(p);
  }
  EXPECT_GT(sum, 0.0);  // the box is lit

  std::ifstream in(stats);
  const nlohmann::json json = nlohmann::json::parse(in);
  EXPECT_EQ(json.at("spp").get<int>(), 4);
  EXPECT_EQ(json.at("width").get<int>(), 32);
  EXPECT_EQ(json.at("height").get<int>(), 24);
  EXPECT_EQ(json.at("nan_samples").get<int>(), 0);
  EXPECT_EQ(json.at("sampler").get<std::string>(), "sobol");  // the default
  EXPECT_GE(json.at("threads").get<int>(), 1);
  EXPECT_GT(json.at("seconds").get<double>(), 0.0);
  // paths/s is consistent with the counts it is derived from. 1e-3 of 3072 paths: the JSON
  // doubles round-trip exactly, so only the rounding of one division and one product remains.
  EXPECT_NEAR(json.at("paths_per_second").get<double>() * json.at("seconds").get<double>(), 32.0 * 24.0 * 4.0, 1e-3);
  // Nothing else was left in the directory (no temporary files): the two outputs and run()'s captures.
  size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++entries;
  EXPECT_EQ(entries, 4u);
}

TEST_F(TraceCliTest, PixelReplayPrintsTheRenderedValue) {
  for (const std::string sampler : {"sobol", "independent"}) {
    SCOPED_TRACE(sampler);
    checkPixelReplay(" --width 8 --height 8 --spp 16 --seed 3 --sampler " + sampler);
  }
}

TEST_F(TraceCliTest, UnknownSamplerFailsCleanly) {
  std::string err;
  EXPECT_NE(run("trace cornell -o " + path("x.exr") + " --sampler halton", nullptr, &err), 0);
  EXPECT_NE(err.find("--sampler"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("x.exr")));
}

void TraceCliTest::checkPixelReplay(const std::string& common) {
  // Render a tiny image to PFM (float, exact), then replay one pixel: the printed radiance
  // must be the pixel's value (same samples), to the 6 significant digits printed.
  const std::string out = path("small.pfm");
  ASSERT_EQ(run("trace cornell -o " + out + common), 0);
  const Image image = readImage(out);
  std::string printed;
  ASSERT_EQ(run("trace cornell --pixel 5,6" + common, &printed), 0);
  std::istringstream in(printed);
  std::string line, word;
  while (std::getline(in, line) && line.find("radiance") == std::string::npos) {
  }
  std::istringstream values(line);
  float r = 0, g = 0, b = 0;
  values >> word >> r >> g >> b;
  ASSERT_EQ(word, "radiance") << line;
  const Rgb expected = image.at(5, 6);
  EXPECT_NEAR(r, expected.r, 1e-5f * std::max(1.0f, expected.r));
  EXPECT_NEAR(g, expected.g, 1e-5f * std::max(1.0f, expected.g));
  EXPECT_NEAR(b, expected.b, 1e-5f * std::max(1.0f, expected.b));
  EXPECT_GT(r + g + b, 0.0f);
}

TEST_F(TraceCliTest, MissingSceneFileFailsCleanly) {
  const std::string out = path("never.exr");
  std::string errors;
  EXPECT_NE(run("trace " + path("no_such_scene.obj") + " -o " + out + " --width 8 --height 8 --spp 1",
                nullptr, &errors),
            0);
  EXPECT_NE(errors.find("no_such_scene.obj"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(TraceCliTest, AbsurdImageSizesFailCleanly) {
  for (const char* size : {"--width 0", "--width 100000", "--height -3"}) {
    const std::string out = path("never.exr");
    std::string errors;
    EXPECT_NE(run(std::string("trace cornell -o ") + out + " --spp 1 " + size, nullptr, &errors), 0) << size;
    EXPECT_FALSE(errors.empty()) << size;
    EXPECT_NE(errors.find(size[2] == 'w' ? "width" : "height"), std::string::npos) << size << ": " << errors;
    EXPECT_FALSE(fs::exists(out)) << size;
  }
}

TEST_F(TraceCliTest, UnknownOutputTypeFailsBeforeRendering) {
  std::string errors;
  EXPECT_NE(run("trace cornell -o " + path("image.bmp") + " --spp 1 --width 8 --height 8", nullptr, &errors), 0);
  EXPECT_NE(errors.find("image.bmp"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(path("image.bmp")));
}

}  // namespace
}  // namespace pl
