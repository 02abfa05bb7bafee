// Runs the `plenoptic trace` command end to end (PLENOPTIC_BINARY): files written on success,
// clear errors and no output on bad input.
#include <gtest/gtest.h>

#include <cmath>
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
  EXPECT_EQ(json.at("subsurface_after_diffuse").get<std::string>(), "walk");  // the default
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

// The white furnace through the command line with default flags: a closed cube whose walls
// have albedo 0.9 and emit 0.1 (inwards), so the radiance is 0.1 / (1 − 0.9) = 1 everywhere.
// The default (no depth cap, --stats max_depth −1) is unbiased: the image mean is within
// 0.5 %, where the former default cap of 32 bounces gave 3.1 % too little. 64 pixels × 16384
// samples: standard error ≈ 0.09 % (read from --variance; required ≤ 1/3 of the tolerance).
TEST_F(TraceCliTest, FurnaceWithDefaultFlagsIsUnbiased) {
  // Faces wound counter-clockwise seen from inside (emission is one-sided).
  std::ofstream(path("box.obj")) << "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                                    "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                                    "f 1 2 3 4\nf 5 8 7 6\nf 1 4 8 5\nf 2 6 7 3\nf 1 5 6 2\nf 4 3 7 8\n";
  std::ofstream(path("furnace.json"))
      << R"({"meshes": [{"file": "box.obj", "material": "wall"}],
             "materials": {"wall": {"type": "lambert", "albedo": [0.9, 0.9, 0.9], "emission": [0.1, 0.1, 0.1]}},
             "cameras": [{"name": "inside", "eye": [0.1, 0.2, -0.3], "target": [0.5, -0.2, 1], "up": [0, 1, 0],
                          "fov": 90}]})";
  const std::string scene = path("furnace.json"), size = " --width 8 --height 8";
  ASSERT_EQ(run("trace " + scene + " -o " + path("f.pfm") + " --variance " + path("v.pfm") + " --stats " +
                path("s.json") + size + " --spp 16384"),
            0);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(path("s.json"))).at("max_depth").get<int>(), -1);
  const Image image = readImage(path("f.pfm")), variance = readImage(path("v.pfm"));
  double sum = 0.0, sumVariance = 0.0;
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    sum += image.pixels[i].g;
    sumVariance += variance.pixels[i].g;
  }
  const double n = static_cast<double>(image.pixels.size());
  EXPECT_NEAR(sum / n, 1.0, 0.005);
  EXPECT_LE(std::sqrt(sumVariance) / n, 0.005 / 3.0);

  // -1 is accepted explicitly; 0 still means the emission seen directly (0.1, no noise).
  ASSERT_EQ(run("trace " + scene + " -o " + path("e.pfm") + size + " --spp 2 --max-depth 0 --stats " + path("e.json")),
            0);
  for (const Rgb& p : readImage(path("e.pfm")).pixels) EXPECT_FLOAT_EQ(p.g, 0.1f);
  ASSERT_EQ(run("trace " + scene + " -o " + path("u.pfm") + size + " --spp 2 --max-depth -1 --stats " + path("u.json")),
            0);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(path("u.json"))).at("max_depth").get<int>(), -1);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(path("e.json"))).at("max_depth").get<int>(), 0);
}

// A subsurface material renders; on an open mesh it loads with a warning naming the file, the
// mesh and the material — in `trace` and in `bake`, which bakes it all the same (the light its
// walks carry off through the gap is lost, as in the path tracer).
TEST_F(TraceCliTest, SubsurfaceOnAnOpenMeshWarnsInTraceAndBake) {
  std::ofstream(path("tri.obj")) << "o sheet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(path("s.json")) << R"({"meshes": [{"file": "tri.obj", "material": "wax"}],
      "materials": {"wax": {"type": "subsurface", "albedo": 0.7, "radius": 0.1}},
      "environment": {"color": 1}})";
  std::string output, errors;
  const std::string image = path("s.pfm");
  ASSERT_EQ(run("trace " + path("s.json") + " -o " + image + " --width 8 --height 8 --spp 2", &output, &errors), 0)
      << errors;
  EXPECT_TRUE(fs::exists(image));
  const std::string log = output + errors;  // the log's warnings go to either stream
  for (const char* needle : {"s.json", "mesh 'sheet'", "'wax'", "do not enclose a volume", "leak"})
    EXPECT_NE(log.find(needle), std::string::npos) << needle << " in: " << log;
  const std::string field = path("s.plf");
  ASSERT_EQ(run("bake " + path("s.json") + " -o " + field + " --preset draft --directions 16 --subsurface-walks 4", &output,
                &errors),
            0)
      << errors;
  EXPECT_TRUE(fs::exists(field));
  for (const char* needle : {"mesh 'sheet'", "'wax'", "do not enclose a volume"})
    EXPECT_NE((output + errors).find(needle), std::string::npos) << needle << " in: " << output + errors;
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
