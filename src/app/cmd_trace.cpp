// `plenoptic trace SCENE -o OUT.exr|png`: the reference path tracer (src/trace/trace.h) through
// TraceJob (src/jobs/jobs.h): flags → job → printed summary.
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "app/cli_support.h"
#include "app/commands.h"
#include "app/view_options.h"
#include "core/error.h"
#include "jobs/jobs.h"
#include "scene/scene.h"
#include "trace/trace.h"

namespace pl {
namespace {

// The options' ranges are declared once, in jobs.h (TraceJobOptions, ViewSettings).

struct TraceOptions {
  TraceJobOptions job;     ///< the flags are bound to its fields; sceneName is the scene loaded
  std::vector<int> pixel;  ///< --pixel X,Y: replay one pixel, print it, write no image
};

void runTrace(const TraceOptions& options, const GlobalOptions& global) {
  applyGlobalOptions(global);
  const bool replay = !options.pixel.empty();
  if (!replay && options.job.output.empty()) failUsage("trace: an output image is required (-o OUT.exr|png)");
  TraceJobOptions jobOptions = options.job;
  if (replay) jobOptions.output.clear();
  jobOptions.trace.seed = global.seed;
  jobOptions.threads = global.threads;
  const TraceJob job(std::move(jobOptions));  // checks every output before the scene is loaded
  const Scene scene = loadScene(options.job.sceneName);

  if (replay) {
    const int x = options.pixel[0], y = options.pixel[1];
    TraceSettings settings;
    ViewSettings view;
    const RadianceEstimate e = job.runPixel(scene, x, y, &settings, &view);
    const Rgb se = glm::sqrt(e.varianceOfMean);
    fmt::print("pixel ({}, {}) of {}x{}, {} spp, seed {}, strategy {}, sampler {}:\n", x, y, view.width, view.height,
               settings.spp, settings.seed, strategyName(settings.strategy), samplerName(settings.sampler));
    fmt::print("  radiance  {:.6g} {:.6g} {:.6g}\n", e.mean.r, e.mean.g, e.mean.b);
    fmt::print("  std error {:.6g} {:.6g} {:.6g}\n", se.r, se.g, se.b);
    fmt::print("  finite samples {}, non-finite samples dropped {}\n", e.samples, e.nanSamples);
    return;
  }

  const TraceJobStats stats = job.run(scene).stats;
  const TraceStats& t = stats.trace;
  if (t.nanSamples > 0)
    fmt::print(stderr,
               "plenoptic: warning: {} of {} samples had a non-finite radiance and were left out "
               "(first at pixel {},{} sample {}; replay with --pixel {},{})\n",
               t.nanSamples, t.paths, t.firstNanX, t.firstNanY, t.firstNanSample, t.firstNanX, t.firstNanY);
  fmt::print("wrote {} ({}x{}, {} spp, {:.2f} s, {:.3f} M paths/s, {:.2f} M rays/s)\n", stats.output, stats.width,
             stats.height, stats.spp, t.seconds, t.pathsPerSecond() * 1e-6, t.raysPerSecond() * 1e-6);
}

}  // namespace

void addTraceCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<TraceOptions>();
  TraceJobOptions& job = options->job;
  CLI::App* command = app.add_subcommand(
      "trace", "Render a scene with the reference path tracer (NEE + BSDF sampling, MIS, Russian roulette)");
  command->add_option("scene", job.sceneName, "cornell, or a scene file (.obj, .gltf, .glb, .json)")->required();
  command->add_option("-o,--output", job.output,
                      "Output image: .exr/.hdr/.pfm hold radiance (x exposure), .png is tone-mapped sRGB "
                      "(not needed with --pixel)")
      ->option_text(cli::kRequiredText);  // required unless --pixel: checked by runTrace
  // --samples: the name render and view use, accepted here too.
  command->add_option("--spp,--samples", job.trace.spp, "Samples (paths) per pixel")
      ->check(CLI::Range(1, TraceJobOptions::kMaxSpp))
      ->capture_default_str();
  command->add_option("--max-depth", job.trace.maxDepth,
                      fmt::format("Maximum scattering events per path: {} = no cap (unbiased: Russian roulette "
                                  "alone ends paths; safety cap {}), 0 = emission seen directly, 1 = direct light, ...",
                                  kUnboundedDepth, kSafetyDepth))
      ->check(CLI::Range(kUnboundedDepth, TraceJobOptions::kMaxDepth))
      ->capture_default_str();
  command
      ->add_option_function<std::string>(
          "--strategy", [&job](const std::string& s) { job.trace.strategy = parseStrategy(s); },
          "Direct lighting: mis (default), nee (light sampling only) or bsdf (BSDF sampling only); "
          "the last two are for testing")
      ->check(CLI::IsMember({"mis", "nee", "bsdf"}))
      ->default_str(strategyName(job.trace.strategy));
  command
      ->add_option_function<std::string>(
          "--sampler", [&job](const std::string& s) { job.trace.sampler = parseSampler(s); },
          "Sample numbers: sobol (default; Owen-scrambled ZSobol, stratified per pixel) or independent "
          "(PCG32 streams; exact per-pixel variance estimates)")
      ->check(CLI::IsMember({"independent", "sobol"}))
      ->default_str(samplerName(job.trace.sampler));
  command
      ->add_option_function<std::string>(
          "--subsurface-after-diffuse",
          [&job](const std::string& s) { job.trace.subsurfaceLambertAfterDiffuse = s == "lambert"; },
          "Subsurface materials met after a Lambertian bounce: walk (default; the medium every time) or "
          "lambert (shaded as Lambertian of their albedo, as Blender Cycles does; for comparisons, biased)")
      ->check(CLI::IsMember({"walk", "lambert"}))
      ->default_str("walk");
  command->add_option("--stats", job.statsPath, "Write timings and counts as JSON");
  command->add_option("--variance", job.variancePath,
                      "Also write the per-pixel variance of the mean (.exr/.hdr/.pfm; radiance², no exposure)");
  command->add_option("--pixel", options->pixel, "Replay one pixel X,Y and print its value (writes no image)")
      ->expected(2)
      ->delimiter(',');
  addCameraOptions(*command, job.view);
  addImageOptions(*command, job.view);
  command->callback([options, command, &global] {
    // A scene file's "settings" fill in only what was not given.
    TraceJobOptions& given = options->job;
    given.sppGiven = command->count("--spp") > 0;
    given.widthGiven = command->count("--width") > 0;
    given.heightGiven = command->count("--height") > 0;
    given.cameraGiven = command->count("--camera") > 0;
    runTrace(*options, global);
  });
}

}  // namespace pl
