// Runs the `plenoptic trace` command end to end (PLENOPTIC_BINARY): files written on success,
// clear errors and no output on bad input.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "image/image.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

class TraceCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("plenoptic_trace_cli_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Runs plenoptic with `arguments`; returns the exit status, stderr in *errors.
  int run(const std::string& arguments, std::string* errors = nullptr) const {
    const fs::path errFile = dir_ / "stderr.txt";
    const std::string command =
        std::string("\"") + PLENOPTIC_BINARY + "\" " + arguments + " --quiet > /dev/null 2> \"" + errFile.string() + "\"";
    const int status = std::system(command.c_str());
    if (errors) {
      std::ifstream in(errFile);
      std::stringstream text;
      text << in.rdbuf();
      *errors = text.str();
    }
    return status;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
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
  EXPECT_GE(json.at("threads").get<int>(), 1);
  EXPECT_GT(json.at("seconds").get<double>(), 0.0);
  // paths/s is consistent with the counts it is derived from.
  EXPECT_NEAR(json.at("paths_per_second").get<double>() * json.at("seconds").get<double>(), 32.0 * 24.0 * 4.0, 1e-3);
  EXPECT_FALSE(fs::exists(stats + ".tmp"));
}

TEST_F(TraceCliTest, PixelReplayPrintsTheRenderedValue) {
  // Render a tiny image to PFM (float, exact), then replay one pixel: the printed radiance
  // must be the pixel's value (same streams), to the 6 significant digits printed.
  const std::string out = path("small.pfm");
  const std::string common = " --width 8 --height 8 --spp 16 --seed 3";
  ASSERT_EQ(run("trace cornell -o " + out + common), 0);
  const Image image = readImage(out);
  const fs::path printed = dir_ / "pixel.txt";
  const std::string command = std::string("\"") + PLENOPTIC_BINARY + "\" trace cornell --pixel 5,6" + common +
                              " --quiet > \"" + printed.string() + "\"";
  ASSERT_EQ(std::system(command.c_str()), 0);
  std::ifstream in(printed);
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
  EXPECT_NE(run("trace " + path("no_such_scene.obj") + " -o " + out + " --width 8 --height 8 --spp 1", &errors), 0);
  EXPECT_NE(errors.find("no_such_scene.obj"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(TraceCliTest, AbsurdImageSizesFailCleanly) {
  for (const char* size : {"--width 0", "--width 100000", "--height -3"}) {
    const std::string out = path("never.exr");
    std::string errors;
    EXPECT_NE(run(std::string("trace cornell -o ") + out + " --spp 1 " + size, &errors), 0) << size;
    EXPECT_FALSE(errors.empty()) << size;
    EXPECT_NE(errors.find(size[2] == 'w' ? "width" : "height"), std::string::npos) << size << ": " << errors;
    EXPECT_FALSE(fs::exists(out)) << size;
  }
}

TEST_F(TraceCliTest, UnknownOutputTypeFailsBeforeRendering) {
  std::string errors;
  EXPECT_NE(run("trace cornell -o " + path("image.bmp") + " --spp 1 --width 8 --height 8", &errors), 0);
  EXPECT_NE(errors.find("image.bmp"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(path("image.bmp")));
}

}  // namespace
}  // namespace pl
