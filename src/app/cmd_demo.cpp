// `plenoptic demo [--output-dir DIR]` (what `make demo` runs): the whole pipeline on the
// built-in Cornell box, each step one function taking the options struct and running one
// library job (jobs/jobs.h), as the trace, bake and render commands do:
//   1. path-traced reference (the ground truth),
//   2. light-field bake (default preset) written as a .plf,
//   3. the light field rendered from the same camera, compared with the reference
//      (relMSE, per-channel mean ratio, mean-luminance ratio, false-colour heat map),
//   4. the real-time walk-through: the viewer when a display is present, otherwise a rendered
//      camera path (PNG frames, and MP4 when ffmpeg is installed).
// It ends by printing where every file is.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "app/commands.h"
#include "bake/bake.h"
#include "core/error.h"
#include "image/compare.h"
#include "jobs/jobs.h"
#include "realtime/realtime.h"
#include "scene/scene.h"
#include "viewer/viewer.h"

namespace pl {
namespace {

struct DemoOptions {
  std::string outputDir = "out/demo";
  // Path-traced reference. 512² × 256 spp ≈ 67 M paths: nearly noise-free, in well under a
  // minute on two cores (the time `make demo` prints; README.md's tour shows one run).
  int imageSize = 512;
  int traceSpp = 256;
  std::string preset = "default";
  /// Jittered samples per pixel of the light-field render: the path tracer averages radiance
  /// over each pixel, so a single centre sample would alias at the light's edges and bias
  /// the comparison (≈ 2.5 % low in mean); 16 samples make the two estimate the same thing.
  int lightFieldSamples = 16;
  bool walkthrough = true;
};

/// One output the demo prints at the end.
struct DemoFile {
  std::string what;
  std::string path;
};

std::string outputPath(const DemoOptions& options, const std::string& name) {
  return (std::filesystem::path(options.outputDir) / name).string();
}

ViewSettings demoView(const DemoOptions& options) {
  ViewSettings view;  // scene camera, exposure 1 (EXR = radiance), Reinhard for the PNGs
  view.width = options.imageSize;
  view.height = options.imageSize;
  return view;
}

/// Step 1: path-traces the Cornell box from its own camera (TraceJob); writes linear EXR and PNG.
Image traceReference(const DemoOptions& options, const GlobalOptions& global, std::vector<DemoFile>& files) {
  TraceJobOptions job;
  job.sceneName = "cornell";
  job.output = outputPath(options, "cornell_trace.exr");
  job.trace.spp = options.traceSpp;
  job.trace.seed = global.seed;
  job.view = demoView(options);
  job.threads = global.threads;
  const TraceJobResult result = TraceJob(job).run(makeCornellBox());
  const TraceStats& stats = result.stats.trace;
  if (stats.nanSamples > 0)
    fmt::print(stderr, "plenoptic: warning: {} non-finite samples were left out of the demo render\n", stats.nanSamples);
  const std::string png = outputPath(options, "cornell_trace.png");
  job.view.writeImage(png, result.radiance);
  const std::string what = fmt::format("path-traced reference, {}x{}, {} spp, {:.1f} s ({:.2f} M paths/s)",
                                       result.stats.width, result.stats.height, result.stats.spp, stats.seconds,
                                       stats.pathsPerSecond() * 1e-6);
  files.push_back({what, job.output});
  files.push_back({what, png});
  return result.radiance;
}

/// Step 2: bakes the light field (BakeJob) and writes it, with its visibility field beside it.
LightField bakeLightField(const DemoOptions& options, const GlobalOptions& global, std::vector<DemoFile>& files) {
  BakeJobOptions job;
  job.sceneName = "cornell";
  job.output = outputPath(options, "cornell.plf");
  job.visibilityPath = outputPath(options, "cornell.plv");
  job.preset = options.preset;
  job.seed = global.seed;
  job.threads = global.threads;
  job.log = [](const std::string& line) { fmt::print(stderr, "{}\n", line); };
  BakeJobResult result = BakeJob(job).run(makeCornellBox());
  const BakeStats& stats = result.stats.bake;
  files.push_back({fmt::format("light field, preset {}: {} tixels, {} iterations (residual {:.1e}), {:.2f} s "
                               "(visibility {:.2f} s, propagation {:.2f} s)",
                               options.preset, stats.tixels, stats.iterations, stats.residual, stats.seconds,
                               stats.visibilitySeconds, stats.propagationSeconds),
                   job.output});
  return std::move(result.lightField);
}

/// Step 3: renders the light field from the reference's camera (RenderJob, fast renderer)
/// and compares the two.
void renderAndCompare(const DemoOptions& options, const GlobalOptions& global, const LightField& lightField,
                      const Image& reference, std::vector<DemoFile>& files) {
  RenderJobOptions job;
  job.inputName = outputPath(options, "cornell.plf");
  job.output = outputPath(options, "cornell_lightfield.exr");
  job.render.samplesPerPixel = options.lightFieldSamples;
  job.view = demoView(options);
  job.threads = global.threads;
  const RenderJobResult result = RenderJob(job).run(lightField);
  const Image& rendered = result.image;
  const std::string png = outputPath(options, "cornell_lightfield.png");
  job.view.writeImage(png, rendered);
  const std::string what = fmt::format("light-field render, {}x{}, {} samples/pixel, {:.1f} ms", result.stats.width,
                                       result.stats.height, result.stats.spp, result.stats.msPerFrameMedian);
  files.push_back({what, job.output});
  files.push_back({what, png});

  const ImageComparison comparison = compareImages(rendered, reference);
  double lumRendered = 0.0, lumReference = 0.0;
  for (size_t i = 0; i < rendered.pixels.size(); ++i) {
    lumRendered += luminance(rendered.pixels[i]);
    lumReference += luminance(reference.pixels[i]);
  }
  const std::string heatmapPath = outputPath(options, "cornell_error_heatmap.png");
  writePng(heatmapPath, relativeErrorHeatmap(rendered, reference, 0.25f));
  files.push_back({fmt::format("light field vs path tracer: relMSE {:.2e}, mean ratio R/G/B {:.4f} / {:.4f} / {:.4f}, "
                               "mean luminance ratio {:.4f} (heat map: relative error, 0 … 0.25)",
                               comparison.relMseAverage, comparison.meanRatio[0], comparison.meanRatio[1],
                               comparison.meanRatio[2], lumReference > 0.0 ? lumRendered / lumReference : 0.0),
                   heatmapPath});
}

void runDemo(const DemoOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  std::error_code error;
  std::filesystem::create_directories(options.outputDir, error);
  if (error || !std::filesystem::is_directory(options.outputDir))
    fail("--output-dir {}: cannot create the directory{}{}", options.outputDir, error ? ": " : "", error.message());

  std::vector<DemoFile> files;
  const Image reference = traceReference(options, global, files);
  const LightField lightField = bakeLightField(options, global, files);
  renderAndCompare(options, global, lightField, reference, files);

  std::vector<std::string> walkthrough;
  if (options.walkthrough) {
    const ViewSettings view = demoView(options);
    const Accel accel(lightField.scene);
    walkthrough = runDemoWalkthrough(lightField, accel, view.resolveCamera(lightField.scene),
                                     view.metresPerUnit(lightField.scene),
                                     std::filesystem::absolute(options.outputDir).string());
  }

  fmt::print("plenoptic demo: the built-in Cornell box\n");
  for (const DemoFile& file : files)
    fmt::print("  {}\n      {}\n", file.what, std::filesystem::absolute(file.path).string());
  for (const std::string& line : walkthrough) fmt::print("  {}\n", line);
}

}  // namespace

void addDemoCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<DemoOptions>();
  CLI::App* command = app.add_subcommand(
      "demo", "Path-trace, bake and render the built-in Cornell box, compare, walk through; print where the files are");
  command->add_option("--output-dir", options->outputDir, "Directory for the demo's files (created if missing)")
      ->capture_default_str();
  command->add_option("--size", options->imageSize, "Width and height of the images in pixels")
      ->check(CLI::Range(16, 4096))
      ->capture_default_str();
  command->add_option("--spp", options->traceSpp, "Samples per pixel of the path-traced reference")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  command->add_option("--preset", options->preset, "Bake preset (as bake --preset)")
      ->check(CLI::IsMember(bakePresetNames()))  // checked before the reference is traced
      ->capture_default_str();
  command->add_flag("!--no-walkthrough", options->walkthrough, "Skip the viewer / rendered walk-through");
  command->callback([options, &global] { runDemo(*options, global); });
}

}  // namespace pl
