// `plenoptic render IN.plf -o OUT.exr|png`: the fast light-field renderer (src/realtime, the
// default; --renderer gpu: the same picture through OpenGL, src/gpu) or, with --reference, the
// straightforward one (src/render/render.h), through the
// shared camera, exposure and tone-mapping flags. With --path PATH.json it renders a
// walk-through (camera/camera_path.h) to an image sequence (-o frames/%04d.png) or an MP4
// video (-o walk.mp4, through ffmpeg). The work is RenderJob's (src/jobs/jobs.h): flags → job →
// printed summary.
#include <fmt/format.h>

#include <memory>
#include <string>
#include <utility>

#include "app/commands.h"
#include "app/view_options.h"
#include "core/error.h"
#include "jobs/jobs.h"

namespace pl {
namespace {

void runRender(const RenderJobOptions& options, const GlobalOptions& global) {
  applyGlobalOptions(global);
  if (options.output.empty()) failUsage("render: an output image is required (-o OUT.exr|png)");
  RenderJobOptions jobOptions = options;
  jobOptions.render.seed = global.seed;
  jobOptions.threads = global.threads;
  const RenderJob job(std::move(jobOptions));  // checks every output before the light field is read
  const RenderJobStats stats = job.run(options.inputName).stats;
  const int spp = stats.spp;
  fmt::print("wrote {} ({}x{}, {} sample{}/pixel, {} renderer, {} frame{}: median {:.2f} ms/frame = {:.1f} fps; "
             "load {:.3f} s, BVH {:.3f} s)\n",
             options.output, stats.width, stats.height, spp, spp == 1 ? "" : "s",
             stats.device.empty() ? stats.renderer : fmt::format("{} ({})", stats.renderer, stats.device), stats.frames,
             stats.frames == 1 ? "" : "s", stats.msPerFrameMedian, stats.fps, stats.loadSeconds,
             stats.accelBuildSeconds);
}

}  // namespace

void addRenderCommand(CLI::App& app, const GlobalOptions& global) {
  // The flags are bound to the job's options; inputName is the file read.
  auto options = std::make_shared<RenderJobOptions>();
  CLI::App* command = app.add_subcommand(
      "render", "Render a baked light field (.plf) by looking it up (16-neighbour interpolation, mirrors followed)");
  command->add_option("input", options->inputName, "Light-field file (.plf) written by `plenoptic bake`")->required();
  command->add_option("-o,--output", options->output,
                      "Output image: .exr/.hdr/.pfm hold radiance (x exposure), .png is tone-mapped sRGB")
      ->required();
  command->add_option("--frames", options->frames, "Render N times for timing (the median goes to --stats)")
      ->check(CLI::Range(1, RenderJobOptions::kMaxFrames))
      ->capture_default_str();
  addRenderSettingsOptions(*command, options->render);
  command->add_flag("--reference", options->reference,
                    "Use the straightforward reference renderer (src/render) instead of the fast one (the default)");
  command
      ->add_option_function<std::string>(
          "--renderer", [options](const std::string& name) { options->gpu = name == "gpu"; },
          "The fast renderer on the CPU (cpu, the default) or on the GPU through OpenGL 4.5 and headless EGL (gpu; "
          "refuses what it does not draw yet: docs/limitations.md)")
      ->check(CLI::IsMember({"cpu", "gpu"}));
  command->add_option("--path", options->pathFile,
                      "Camera path JSON (keyframes; see docs/user-guide.md): render a walk-through to -o frames/%04d.png or -o walk.mp4; "
                      "light keyframes in it relight every frame");
  command->add_option("--visibility", options->visibilityPath,
                      "The visibility field (.plv) that a path with light keyframes relights from (default: the .plf's X.plv)");
  command->add_option("--stats", options->statsPath,
                      "Write JSON: frames, ms_per_frame_median, fps, primary_ms_median (primary rays alone), load and BVH times");
  addCameraOptions(*command, options->view);
  addImageOptions(*command, options->view);
  command->callback([options, &global] { runRender(*options, global); });
}

}  // namespace pl
