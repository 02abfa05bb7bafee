// `plenoptic render IN.plf -o OUT.exr|png`: the fast light-field renderer (src/realtime, the
// default) or, with --reference, the straightforward one (src/render/render.h), through the
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

struct RenderOptions {
  std::string input;      ///< .plf light field
  std::string output;     ///< .exr/.hdr/.pfm (radiance × exposure) or .png (tone-mapped)
  std::string statsPath;  ///< --stats: JSON with frames, ms_per_frame_median, fps
  int frames = 1;         ///< --frames N: render N times (timing); the last frame is written
  int samples = 0;        ///< --samples N: camera samples per pixel (0 = automatic, see render_settings.h)
  int mirrorDepth = -1;   ///< --mirror-depth N (-1 = the bake's)
  bool textureLod = true;  ///< --texture-lod on|off
  bool reference = false;  ///< --reference: the straightforward renderer instead of the fast one
  std::string pathFile;    ///< --path PATH.json: render a walk-through, one output per frame
  ViewOptions view;
};

void runRender(const RenderOptions& options, const GlobalOptions& global) {
  applyGlobalOptions(global);
  if (options.output.empty()) failUsage("render: an output image is required (-o OUT.exr|png)");
  RenderJobOptions jobOptions;
  jobOptions.inputName = options.input;
  jobOptions.output = options.output;
  jobOptions.statsPath = options.statsPath;
  jobOptions.frames = options.frames;
  jobOptions.render.samplesPerPixel = options.samples;
  jobOptions.render.mirrorDepth = options.mirrorDepth;
  jobOptions.render.textureLod = options.textureLod;
  jobOptions.render.seed = global.seed;
  jobOptions.reference = options.reference;
  jobOptions.pathFile = options.pathFile;
  jobOptions.view = options.view;
  jobOptions.threads = global.threads;
  const RenderJob job(std::move(jobOptions));  // checks every output before the light field is read
  const RenderJobStats stats = job.run(options.input).stats;
  const int spp = stats.samplesPerPixel;
  fmt::print("wrote {} ({}x{}, {} sample{}/pixel, {} renderer, {} frame{}: median {:.2f} ms/frame = {:.1f} fps; "
             "load {:.3f} s, BVH {:.3f} s)\n",
             options.output, stats.width, stats.height, spp, spp == 1 ? "" : "s", stats.renderer, stats.frames,
             stats.frames == 1 ? "" : "s", stats.msPerFrameMedian, stats.fps, stats.loadSeconds,
             stats.accelBuildSeconds);
}

}  // namespace

void addRenderCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* command = app.add_subcommand(
      "render", "Render a baked light field (.plf) by looking it up (16-neighbour interpolation, mirrors followed)");
  command->add_option("input", options->input, "Light-field file (.plf) written by `plenoptic bake`")->required();
  command->add_option("-o,--output", options->output,
                      "Output image: .exr/.hdr/.pfm hold radiance (x exposure), .png is tone-mapped sRGB")
      ->required();
  command->add_option("--frames", options->frames, "Render N times for timing (the median goes to --stats)")
      ->check(CLI::Range(1, RenderJobOptions::kMaxFrames))
      ->capture_default_str();
  command->add_option("--samples", options->samples,
                      "Camera samples per pixel (0 = 1 at the pixel centre for a pinhole, 16 for a thin lens)")
      ->check(CLI::Range(0, RenderSettings::kMaxSamplesPerPixel))
      ->capture_default_str();
  command->add_option("--mirror-depth", options->mirrorDepth,
                      "Mirror reflections followed (-1 = the bake's own mirror depth)")
      ->check(CLI::Range(-1, RenderSettings::kMaxMirrorDepth))
      ->capture_default_str();
  addTextureLodOption(*command, options->textureLod);
  command->add_flag("--reference", options->reference,
                    "Use the straightforward reference renderer (src/render) instead of the fast one (the default)");
  command->add_option("--path", options->pathFile,
                      "Camera path JSON (keyframes; see docs/user-guide.md): render a walk-through to -o frames/%04d.png or -o walk.mp4");
  command->add_option("--stats", options->statsPath,
                      "Write JSON: frames, ms_per_frame_median, fps, primary_ms_median (primary rays alone), load and BVH times");
  options->view.addCameraOptions(*command);
  options->view.addImageOptions(*command);
  command->callback([options, &global] { runRender(*options, global); });
}

}  // namespace pl
