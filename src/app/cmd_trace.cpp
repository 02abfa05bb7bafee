// `plenoptic trace SCENE -o OUT.exr|png`: the reference path tracer (src/trace/trace.h).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "app/commands.h"
#include "app/view_options.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/file_io.h"
#include "image/image.h"
#include "scene/scene.h"
#include "trace/trace.h"

namespace pl {
namespace {

// Ranges of the options, declared once (image size: ViewOptions::kMaxImageSide).
constexpr int kMaxSpp = 1 << 24;
constexpr int kMaxDepth = 100000;

struct TraceOptions {
  std::string scene;        ///< `cornell`, .obj, .gltf/.glb, .json
  std::string output;       ///< .exr/.hdr/.pfm (radiance × exposure) or .png (tone-mapped)
  int spp = 64;
  int maxDepth = TraceSettings{}.maxDepth;
  std::string strategy = "mis";
  std::string sampler = samplerName(TraceSettings{}.sampler);
  std::string statsPath;     ///< --stats: JSON with timings
  std::string variancePath;  ///< --variance: per-pixel variance of the mean (HDR file)
  std::vector<int> pixel;    ///< --pixel X,Y: replay one pixel, print it, write no image
  ViewOptions view;
  // Which flags were given: a scene file's "settings" fill in only the ones that were not.
  bool sppGiven = false, widthGiven = false, heightGiven = false, cameraGiven = false;
};

void runTrace(const TraceOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  const bool replay = !options.pixel.empty();
  // Every output is checked before the scene is even loaded (core/file_io.h).
  if (!replay) {
    if (options.output.empty()) failUsage("trace: an output image is required (-o OUT.exr|png)");
    ViewOptions::checkImageOutput(options.output, "-o");
  }
  if (!options.variancePath.empty()) checkOutputPath(options.variancePath, {".exr", ".hdr", ".pfm"}, "--variance");
  if (!options.statsPath.empty()) checkOutputPath(options.statsPath, {}, "--stats");
  checkDistinctOutputs({{"-o", options.output}, {"--variance", options.variancePath}, {"--stats", options.statsPath}});

  TraceSettings settings;
  settings.spp = options.spp;
  settings.maxDepth = options.maxDepth;
  settings.seed = global.seed;
  settings.strategy = parseStrategy(options.strategy);
  settings.sampler = parseSampler(options.sampler);

  const Scene scene = loadScene(options.scene);
  // The scene file's suggested settings, where the command line is silent.
  ViewOptions view = options.view;
  const SceneSettings& suggested = scene.settings;
  if (!options.widthGiven && suggested.width) view.width = *suggested.width;
  if (!options.heightGiven && suggested.height) view.height = *suggested.height;
  if (!options.cameraGiven && suggested.camera) view.camera = *suggested.camera;
  if (!options.sppGiven && suggested.spp) settings.spp = *suggested.spp;
  constexpr int kMaxSide = ViewOptions::kMaxImageSide;
  if (view.width < 1 || view.width > kMaxSide || view.height < 1 || view.height > kMaxSide)
    fail("{}: image size {}x{} is out of range (width and height must be 1..{})", options.scene, view.width,
         view.height, kMaxSide);
  if (settings.spp < 1 || settings.spp > kMaxSpp)
    fail("{}: {} samples per pixel is out of range (1..{})", options.scene, settings.spp, kMaxSpp);
  // The radiance and variance images (replaying one pixel needs neither).
  if (!replay) view.requireImageMemory(2, "trace");

  const Accel accel(scene);
  const PathTracer tracer(scene, accel);
  const CameraDesc cameraDesc = view.resolveCamera(scene);
  const Camera camera = view.makeCamera(scene);

  if (replay) {
    const int x = options.pixel[0], y = options.pixel[1];
    const RadianceEstimate e = tracer.renderPixel(camera, settings, x, y);
    const Rgb se = glm::sqrt(e.varianceOfMean);
    fmt::print("pixel ({}, {}) of {}x{}, {} spp, seed {}, strategy {}, sampler {}:\n", x, y, view.width, view.height,
               settings.spp, settings.seed, strategyName(settings.strategy), samplerName(settings.sampler));
    fmt::print("  radiance  {:.6g} {:.6g} {:.6g}\n", e.mean.r, e.mean.g, e.mean.b);
    fmt::print("  std error {:.6g} {:.6g} {:.6g}\n", se.r, se.g, se.b);
    fmt::print("  finite samples {}, non-finite samples dropped {}\n", e.samples, e.nanSamples);
    return;
  }

  const TraceResult result = tracer.render(camera, settings);
  const TraceStats& stats = result.stats;
  if (stats.nanSamples > 0)
    fmt::print(stderr,
               "plenoptic: warning: {} of {} samples had a non-finite radiance and were left out "
               "(first at pixel {},{} sample {}; replay with --pixel {},{})\n",
               stats.nanSamples, stats.paths, stats.firstNanX, stats.firstNanY, stats.firstNanSample, stats.firstNanX,
               stats.firstNanY);

  view.writeImage(options.output, result.radiance);
  if (!options.variancePath.empty()) writeHdrImage(options.variancePath, result.variance);

  if (!options.statsPath.empty()) {
    nlohmann::json json;
    json["command"] = "trace";
    json["scene"] = options.scene;
    json["output"] = options.output;
    json["camera"] = cameraDesc.name;
    json["width"] = view.width;
    json["height"] = view.height;
    json["spp"] = settings.spp;
    json["max_depth"] = settings.maxDepth;
    json["strategy"] = strategyName(settings.strategy);
    json["sampler"] = samplerName(settings.sampler);
    json["seed"] = settings.seed;
    json["threads"] = runtime.threads();
    json["seconds"] = stats.seconds;
    json["paths"] = stats.paths;
    json["paths_per_second"] = stats.pathsPerSecond();
    json["rays"] = stats.rays;
    json["rays_per_second"] = stats.raysPerSecond();
    json["nan_samples"] = stats.nanSamples;
    json["triangles"] = scene.triangleCount();
    json["emissive_triangles"] = tracer.emissiveTriangleCount();
    writeFileAtomically(options.statsPath, json.dump(2) + "\n");
  }
  fmt::print("wrote {} ({}x{}, {} spp, {:.2f} s, {:.3f} M paths/s, {:.2f} M rays/s)\n", options.output, view.width,
             view.height, settings.spp, stats.seconds, stats.pathsPerSecond() * 1e-6, stats.raysPerSecond() * 1e-6);
}

}  // namespace

void addTraceCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<TraceOptions>();
  CLI::App* command = app.add_subcommand(
      "trace", "Render a scene with the reference path tracer (NEE + BSDF sampling, MIS, Russian roulette)");
  command->add_option("scene", options->scene, "cornell, or a scene file (.obj, .gltf, .glb, .json)")->required();
  command->add_option("-o,--output", options->output,
                      "Output image: .exr/.hdr/.pfm hold radiance (x exposure), .png is tone-mapped sRGB");
  command->add_option("--spp", options->spp, "Samples (paths) per pixel")
      ->check(CLI::Range(1, kMaxSpp))
      ->capture_default_str();
  command->add_option("--max-depth", options->maxDepth,
                      fmt::format("Maximum scattering events per path: {} = no cap (unbiased: Russian roulette "
                                  "alone ends paths; safety cap {}), 0 = emission seen directly, 1 = direct light, ...",
                                  kUnboundedDepth, kSafetyDepth))
      ->check(CLI::Range(kUnboundedDepth, kMaxDepth))
      ->capture_default_str();
  command->add_option("--strategy", options->strategy,
                      "Direct lighting: mis (default), nee (light sampling only) or bsdf (BSDF sampling only); "
                      "the last two are for testing")
      ->check(CLI::IsMember({"mis", "nee", "bsdf"}))
      ->capture_default_str();
  command->add_option("--sampler", options->sampler,
                      "Sample numbers: sobol (default; Owen-scrambled ZSobol, stratified per pixel) or independent "
                      "(PCG32 streams; exact per-pixel variance estimates)")
      ->check(CLI::IsMember({"independent", "sobol"}))
      ->capture_default_str();
  command->add_option("--stats", options->statsPath, "Write timings and counts as JSON");
  command->add_option("--variance", options->variancePath,
                      "Also write the per-pixel variance of the mean (.exr/.hdr/.pfm; radiance², no exposure)");
  command->add_option("--pixel", options->pixel, "Replay one pixel X,Y and print its value (writes no image)")
      ->expected(2)
      ->delimiter(',');
  options->view.addCameraOptions(*command);
  options->view.addImageOptions(*command);
  command->callback([options, command, &global] {
    options->sppGiven = command->count("--spp") > 0;
    options->widthGiven = command->count("--width") > 0;
    options->heightGiven = command->count("--height") > 0;
    options->cameraGiven = command->count("--camera") > 0;
    runTrace(*options, global);
  });
}

}  // namespace pl
