// `plenoptic compare` and `plenoptic tonemap` end to end (runs the PLENOPTIC_BINARY executable).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "image/image.h"
#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

using cli_test::CommandResult;
using cli_test::runPlenopticCombined;

class ImageCli : public cli_test::CliTest {};

TEST_F(ImageCli, CompareOfAnImageWithItselfIsIdentical) {
  Image image(8, 4, Rgb(0.25f, 1.0f, 3.0f));
  writeHdrImage(path("a.exr"), image);
  const CommandResult r = runPlenopticCombined("compare " + path("a.exr") + " " + path("a.exr") + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["rmse"].get<double>(), 0.0);
  EXPECT_EQ(j["relmse"].get<double>(), 0.0);
  EXPECT_TRUE(j["psnr"].is_null());  // infinite
  EXPECT_TRUE(j["identical"].get<bool>());
}

TEST_F(ImageCli, CompareReportsAKnownPerturbationAcrossFormats) {
  const Image reference(8, 4, Rgb(0.5f));
  Image test = reference;
  for (Rgb& p : test.pixels) p.r += 0.125f;  // exact in float, PFM and EXR
  writeHdrImage(path("ref.pfm"), reference);
  writeHdrImage(path("test.exr"), test);
  const CommandResult r = runPlenopticCombined("compare " + path("test.exr") + " " + path("ref.pfm") + " --json --heatmap " + path("heat.png"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  // Closed forms (compare.h): mse_R = 0.125², relMSE = mse_R/(0.25 + 0.01)/3, PSNR = 10 log10(3/mse_R).
  EXPECT_NEAR(j["rmse"].get<double>(), std::sqrt(0.125 * 0.125 / 3.0), 1e-12);
  EXPECT_NEAR(j["relmse"].get<double>(), 0.125 * 0.125 / 0.26 / 3.0, 1e-12);
  EXPECT_NEAR(j["psnr"].get<double>(), 10.0 * std::log10(3.0 / (0.125 * 0.125)), 1e-9);
  EXPECT_NEAR(j["mean_ratio_rgb"][0].get<double>(), 1.25, 1e-12);
  // Grey reference: luminance ratio = 1 + 0.2126·0.125/0.5 (Rec.709 red weight).
  EXPECT_NEAR(j["mean_luminance_ratio"].get<double>(), 1.0 + 0.2126 * 0.25, 1e-9);
  EXPECT_EQ(readImage(path("heat.png")).width, 8);
  // --max-relmse turns the figure into an exit status.
  EXPECT_NE(runPlenopticCombined("compare " + path("test.exr") + " " + path("ref.pfm") + " --max-relmse 0.001").exitCode, 0);
  EXPECT_EQ(runPlenopticCombined("compare " + path("test.exr") + " " + path("ref.pfm") + " --max-relmse 0.1").exitCode, 0);
}

TEST_F(ImageCli, CompareRefusesDifferentSizesAndLdrInput) {
  writeHdrImage(path("a.exr"), Image(8, 4));
  writeHdrImage(path("b.exr"), Image(4, 8));
  CommandResult r = runPlenopticCombined("compare " + path("a.exr") + " " + path("b.exr"));
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("8x4"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("4x8"), std::string::npos) << r.output;
  writePng(path("c.png"), Image8{8, 4, std::vector<uint8_t>(8 * 4 * 3, 0)});
  r = runPlenopticCombined("compare " + path("c.png") + " " + path("a.exr"));
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("c.png"), std::string::npos) << r.output;
}

TEST_F(ImageCli, TonemapWritesPngAndExposedHdr) {
  writeHdrImage(path("in.exr"), Image(6, 3, Rgb(0.18f)));
  // Linear, exposure +1 EV: 0.36 → sRGB 1.055·0.36^(1/2.4) − 0.055 = 0.6343 → 161.7 → 162.
  CommandResult r = runPlenopticCombined("tonemap " + path("in.exr") + " -o " + path("out.png") + " --tonemap linear --exposure 1");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const Image png = readImage(path("out.png"));
  EXPECT_NEAR(linearToSrgb(png.at(2, 1).g) * 255.0f, 162.0f, 1e-3f);
  // HDR output holds input × exposure: f/4, 1/50 s, ISO 200 → H = 1/(1.2 · 2^log2(16·50·100/200)) = 1/480.
  r = runPlenopticCombined("tonemap " + path("in.exr") + " -o " + path("out.pfm") + " --fstop 4 --shutter 1/50 --iso 200");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NEAR(readImage(path("out.pfm")).at(0, 0).r, 0.18f / 480.0f, 1e-9f);
  // Incomplete photographic settings are refused before anything is written.
  r = runPlenopticCombined("tonemap " + path("in.exr") + " -o " + path("bad.png") + " --fstop 4 --iso 200");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_FALSE(fs::exists(path("bad.png")));
  r = runPlenopticCombined("tonemap " + path("missing.exr") + " -o " + path("x.png"));
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("missing.exr"), std::string::npos) << r.output;
}

TEST_F(ImageCli, TonemapRefusesUnwritableOutputsBeforeReading) {
  writeHdrImage(path("in.exr"), Image(4, 4, Rgb(1.0f)));
  CommandResult r = runPlenopticCombined("tonemap " + path("in.exr") + " -o " + path("out.bmp"));
  EXPECT_EQ(r.exitCode, 2);  // a usage error (core/error.h)
  EXPECT_NE(r.output.find("-o " + path("out.bmp") + ": expected a .exr, .hdr, .pfm or .png file name, not '.bmp'"),
            std::string::npos)
      << r.output;
  r = runPlenopticCombined("tonemap " + path("in.exr") + " -o " + path("missing/out.png"));
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.output.find("directory '" + path("missing") + "' does not exist"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("missing")));
}

}  // namespace
}  // namespace pl
