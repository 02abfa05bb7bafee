// `plenoptic demo [--output-dir DIR]`: renders the built-in Cornell box and prints where the
// files are. Each step is one function taking the options struct, so further steps (the
// light-field bake and its real-time rendering) slot in beside the path-traced reference.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "app/commands.h"
#include "app/view_options.h"
#include "camera/camera.h"
#include "core/error.h"
#include "scene/scene.h"
#include "trace/trace.h"

namespace pl {
namespace {

struct DemoOptions {
  std::string outputDir = "out/demo";
  // Path-traced reference. 512² × 256 spp ≈ 67 M paths: the tracer does ≈ 1.5 M paths per
  // CPU-second on this machine, so ≈ 20–25 s on 2 idle cores; nearly noise-free.
  int traceSize = 512;
  int traceSpp = 256;
};

struct DemoFile {
  std::string what;
  std::string path;
};

/// Path-traces the Cornell box from its own camera; writes linear EXR and tone-mapped PNG.
std::vector<DemoFile> traceReference(const DemoOptions& options, const Scene& scene, const GlobalOptions& global) {
  const Accel accel(scene);
  const PathTracer tracer(scene, accel);
  ViewOptions view;  // defaults: scene camera, exposure 1, Reinhard tone mapping for the PNG
  view.width = options.traceSize;
  view.height = options.traceSize;
  const Camera camera = view.makeCamera(scene);
  TraceSettings settings;
  settings.spp = options.traceSpp;
  settings.seed = global.seed;
  const TraceResult result = tracer.render(camera, settings);
  if (result.stats.nanSamples > 0)
    fmt::print(stderr, "plenoptic: warning: {} non-finite samples were left out of the demo render\n",
               result.stats.nanSamples);

  const std::string base = (std::filesystem::path(options.outputDir) / "cornell_trace").string();
  view.writeImage(base + ".exr", result.radiance);
  view.writeImage(base + ".png", result.radiance);
  const std::string what = fmt::format("path-traced reference, {}x{}, {} spp, {:.1f} s ({:.2f} M paths/s)",
                                       view.width, view.height, settings.spp, result.stats.seconds,
                                       result.stats.pathsPerSecond() * 1e-6);
  return {{what + ", radiance", base + ".exr"}, {what + ", tone-mapped", base + ".png"}};
}

void runDemo(const DemoOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  std::error_code error;
  std::filesystem::create_directories(options.outputDir, error);
  if (error || !std::filesystem::is_directory(options.outputDir))
    fail("--output-dir {}: cannot create the directory{}{}", options.outputDir, error ? ": " : "", error.message());

  const Scene scene = makeCornellBox();
  std::vector<DemoFile> files = traceReference(options, scene, global);

  fmt::print("plenoptic demo: the built-in Cornell box\n");
  for (const DemoFile& file : files)
    fmt::print("  {}\n      {}\n", file.what, std::filesystem::absolute(file.path).string());
}

}  // namespace

void addDemoCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<DemoOptions>();
  CLI::App* command = app.add_subcommand("demo", "Render the built-in Cornell box and print where the images are");
  command->add_option("--output-dir", options->outputDir, "Directory for the demo's files (created if missing)")
      ->capture_default_str();
  command->callback([options, &global] { runDemo(*options, global); });
}

}  // namespace pl
