// `plenoptic tonemap IN -o OUT.png [exposure and tone-mapping flags]`: the same exposure and
// tone mapping as trace/render, applied to an existing image.
#include <fmt/format.h>

#include <memory>
#include <string>

#include "app/commands.h"
#include "app/view_options.h"
#include "core/error.h"
#include "image/image.h"

namespace pl {
namespace {

struct TonemapOptions {
  std::string input;   ///< any readable image (.exr, .hdr, .pfm; .png is decoded to linear)
  std::string output;  ///< .png (tone-mapped sRGB) or .exr/.hdr/.pfm (input × exposure)
  ViewSettings view;   ///< only its exposure and tone-mapping flags are used
};

void runTonemap(const TonemapOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  ViewSettings::checkImageOutput(options.output, "-o");
  const std::string ext = fileExtensionLower(options.output);
  const Image image = readImage(options.input);
  options.view.writeImage(options.output, image);
  const ToneMapSettings t = options.view.toneMapSettings();
  fmt::print("wrote {} ({}x{}, exposure x{:.6g}{})\n", options.output, image.width, image.height,
             options.view.exposureScale(),
             ext == ".png" ? fmt::format(", {} tone mapping", toneMapOperatorName(t.op)) : std::string());
}

}  // namespace

void addTonemapCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<TonemapOptions>();
  CLI::App* command = app.add_subcommand(
      "tonemap", "Expose and tone-map an existing HDR image to PNG (same operators as trace and render)");
  command->add_option("input", options->input, "Input image (.exr, .hdr, .pfm, or .png decoded to linear)")->required();
  command->add_option("-o,--output", options->output, "Output: .png tone-mapped sRGB, or .exr/.hdr/.pfm exposed")
      ->required();
  addExposureOptions(*command, options->view);
  addToneMapOptions(*command, options->view);
  command->callback([options, &global] { runTonemap(*options, global); });
}

}  // namespace pl
