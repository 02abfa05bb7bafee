// `plenoptic compare A B [--json] [--heatmap OUT.png]`: error figures of A against the
// reference B (image/compare.h for the definitions).
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.h"
#include "core/error.h"
#include "core/file_io.h"
#include "image/compare.h"
#include "image/image.h"

namespace pl {
namespace {

struct CompareOptions {
  std::string test;       ///< A
  std::string reference;  ///< B
  bool json = false;
  std::string heatmap;       ///< --heatmap OUT.png
  float heatmapMax = 1.0f;   ///< relative error shown at the top of the colour map
  double peak = 1.0;         ///< PSNR peak
  std::optional<double> maxRelMse;  ///< --max-relmse: fail (exit 1) above this
};

Image readHdrInput(const std::string& path) {
  if (!isHdrExtension(path))
    fail("{}: compare reads HDR images only (.exr, .hdr, .pfm), not '{}'", path, fileExtensionLower(path));
  return readImage(path);
}

void runCompare(const CompareOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  if (!options.heatmap.empty()) checkOutputPath(options.heatmap, {".png"}, "--heatmap");
  const Image a = readHdrInput(options.test);
  const Image b = readHdrInput(options.reference);
  if (a.width != b.width || a.height != b.height)
    fail("image sizes differ: {} is {}x{}, {} (reference) is {}x{}", options.test, a.width, a.height,
         options.reference, b.width, b.height);
  const ImageComparison c = compareImages(a, b, options.peak);

  if (options.json) {
    nlohmann::json j = nlohmann::json::parse(comparisonJson(c));
    j["a"] = options.test;
    j["b"] = options.reference;
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print("A (test):      {}\nB (reference): {}\nsize:          {}x{}\n", options.test, options.reference, c.width,
               c.height);
    fmt::print("RMSE:          {:.6g}\n", c.rmse);
    fmt::print("relMSE:        {:.6g}  (R {:.6g}, G {:.6g}, B {:.6g})\n", c.relMseAverage, c.relMse[0], c.relMse[1],
               c.relMse[2]);
    fmt::print("PSNR:          {} dB (peak {})\n", std::isinf(c.psnr) ? std::string("inf") : fmt::format("{:.3f}", c.psnr),
               c.peak);
    fmt::print("mean A/B:      R {:.6g}, G {:.6g}, B {:.6g}; luminance {:.6g}\n", c.meanRatio[0], c.meanRatio[1],
               c.meanRatio[2], c.meanLuminanceRatio);
    fmt::print("max |A-B|:     {:.6g} at pixel ({}, {})\n", c.maxAbsError, c.maxErrorX, c.maxErrorY);
    if (c.nonFinitePixels)
      fmt::print("non-finite:    {} pixels (NaN/Inf in A or B; left out of the figures above)\n", c.nonFinitePixels);
  }
  if (!options.heatmap.empty()) {
    writePng(options.heatmap, relativeErrorHeatmap(a, b, options.heatmapMax));
    if (!options.json) fmt::print("heat map:      {} (relative RMS error, 0 .. {})\n", options.heatmap, options.heatmapMax);
  }
  if (options.maxRelMse && !(c.relMseAverage <= *options.maxRelMse))
    fail("relMSE {:.6g} of {} against {} exceeds --max-relmse {}", c.relMseAverage, options.test, options.reference,
         *options.maxRelMse);
}

}  // namespace

void addCompareCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<CompareOptions>();
  CLI::App* command = app.add_subcommand(
      "compare", "Error figures (RMSE, relMSE, PSNR, mean ratio, max error) of HDR image A against reference B");
  command->add_option("A", options->test, "Test image (.exr, .hdr, .pfm)")->required();
  command->add_option("B", options->reference, "Reference image (.exr, .hdr, .pfm), same size")->required();
  command->add_flag("--json", options->json, "Print the figures as JSON (infinite PSNR as null)");
  command->add_option("--heatmap", options->heatmap, "Write a false-colour PNG of the per-pixel relative error");
  command->add_option("--heatmap-max", options->heatmapMax, "Relative error at the top of the heat map's colour scale")
      ->check(CLI::Range(1e-6f, 1e6f))
      ->capture_default_str();
  command->add_option("--peak", options->peak, "Peak value for PSNR (HDR images: 1 by default)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--max-relmse", options->maxRelMse, "Exit with an error when relMSE exceeds this")
      ->check(CLI::NonNegativeNumber);
  command->callback([options, &global] { runCompare(*options, global); });
}

}  // namespace pl
