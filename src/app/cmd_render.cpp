// `plenoptic render IN.plf -o OUT.exr|png`: the fast light-field renderer (src/realtime, the
// default) or, with --reference, the straightforward one (src/render/render.h), through the
// shared camera, exposure and tone-mapping flags. With --path PATH.json it renders a
// walk-through (realtime/camera_path.h) to an image sequence (-o frames/%04d.png) or an MP4
// video (-o walk.mp4, through ffmpeg).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "app/commands.h"
#include "app/view_options.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/timing.h"
#include "image/image.h"
#include "lightfield/plf_file.h"
#include "realtime/camera_path.h"
#include "realtime/frame_output.h"
#include "realtime/realtime.h"
#include "realtime/walkthrough.h"
#include "render/render.h"

namespace pl {
namespace {

// Ranges of the options, declared once (image size: ViewOptions::kMaxImageSide; samples and
// mirror depth: RenderSettings).
constexpr int kMaxFrames = 100000;

struct RenderOptions {
  std::string input;      ///< .plf light field
  std::string output;     ///< .exr/.hdr/.pfm (radiance × exposure) or .png (tone-mapped)
  std::string statsPath;  ///< --stats: JSON with frames, ms_per_frame_median, fps
  int frames = 1;         ///< --frames N: render N times (timing); the last frame is written
  int samples = 0;        ///< --samples N: camera samples per pixel (0 = automatic, see render.h)
  int mirrorDepth = -1;   ///< --mirror-depth N (-1 = the bake's)
  bool reference = false;  ///< --reference: the straightforward renderer instead of the fast one
  bool fast = false;       ///< --fast: the fast renderer (the default; excludes --reference)
  std::string pathFile;    ///< --path PATH.json: render a walk-through, one output per frame
  ViewOptions view;
};

void runRender(const RenderOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  const ViewOptions& view = options.view;
  constexpr int kMaxSide = ViewOptions::kMaxImageSide;
  if (view.width < 1 || view.width > kMaxSide || view.height < 1 || view.height > kMaxSide)
    fail("image size {}x{} is out of range (width and height must be 1..{})", view.width, view.height, kMaxSide);
  // Every output is checked before the light field is read (core/file_io.h).
  if (options.output.empty()) failUsage("render: an output image is required (-o OUT.exr|png)");
  const bool video = isVideoOutput(options.output);
  const bool sequence = isFramePattern(options.output);
  if (options.pathFile.empty() && (video || sequence))
    failUsage("-o {}: a frame pattern or .mp4 output needs a camera path (--path PATH.json)", options.output);
  if (!options.pathFile.empty() && !video && !sequence)
    failUsage("-o {}: a camera path renders many frames: give a frame pattern like frames/%04d.png or an .mp4 file",
              options.output);
  if (!options.pathFile.empty() && options.frames != 1)
    failUsage("--frames cannot be combined with --path (the path sets the frames)");
  if (sequence) {
    // Frames go into the pattern's directory, created if needed.
    const std::filesystem::path parent = std::filesystem::path(options.output).parent_path();
    std::error_code error;
    if (!parent.empty()) std::filesystem::create_directories(parent, error);
    if (error) fail("-o {}: cannot create directory '{}': {}", options.output, parent.string(), error.message());
  }
  if (!video) ViewOptions::checkImageOutput(options.output, "-o");
  else checkOutputPath(options.output, {".mp4"}, "-o");
  if (!options.statsPath.empty()) checkOutputPath(options.statsPath, {}, "--stats");
  checkDistinctOutputs({{"-o", options.output}, {"--stats", options.statsPath}});
  std::optional<CameraPath> cameraPath;
  if (!options.pathFile.empty()) cameraPath = loadCameraPath(options.pathFile);
  if (video && findFfmpeg().empty())
    fail("-o {}: MP4 output needs ffmpeg, which is not installed (not found on PATH); write an image sequence "
         "instead, e.g. -o frames/%04d.png",
         options.output);
  const auto loadStart = SteadyClock::now();
  const LightField lightField = readLightField(options.input);
  const double loadSeconds = secondsSince(loadStart);
  // The frame (two for a walk-through: the one being rendered and the one being written); the
  // light field, read by now, is already taken from the available memory.
  view.requireImageMemory(cameraPath ? 2 : 1, "render");
  const auto accelStart = SteadyClock::now();
  const Accel accel(lightField.scene);
  const double accelSeconds = secondsSince(accelStart);
  const CameraDesc cameraDesc = view.resolveCamera(lightField.scene);
  const Camera camera(cameraDesc, view.width, view.height, view.vignetting, view.metresPerUnit(lightField.scene));
  const FastRenderer fastRenderer(lightField, accel);

  RenderSettings settings;
  settings.samplesPerPixel = options.samples;
  settings.mirrorDepth = options.mirrorDepth;
  settings.seed = global.seed;
  settings.showProgress = options.frames == 1 && options.reference;
  Image image;
  std::vector<double> frameMs, primaryMs;
  // With --stats, the fast renderer's first pass alone (FastRenderer::castPrimaryRays) is
  // timed on every frame's camera after the last frame (interleaving it with the frames would
  // evict their light-field data from the caches and slow them down).
  const bool timePrimary = !options.statsPath.empty() && !options.reference;
  std::vector<Camera> frameCameras;
  // One frame through the chosen renderer; frame time excludes writing files.
  auto renderFrame = [&](const Camera& frameCamera) {
    const auto start = SteadyClock::now();
    if (options.reference) {
      image = renderLightField(lightField, accel, frameCamera, settings);
    } else {
      fastRenderer.render(frameCamera, settings, image);
    }
    frameMs.push_back(1e3 * secondsSince(start));
    if (timePrimary) frameCameras.push_back(frameCamera);
  };
  int frames = options.frames;
  if (!cameraPath) {
    for (int frame = 0; frame < options.frames; ++frame) renderFrame(camera);
    view.writeImage(options.output, image);
  } else {
    // The walk-through (realtime/walkthrough.h): frame k at time t₀ + k/fps, the path's pose
    // on the resolved camera (which keeps its lens and, without a path fov, its fov).
    WalkthroughOptions walk;
    walk.output = options.output;
    walk.width = view.width;
    walk.height = view.height;
    walk.vignetting = view.vignetting;
    walk.metresPerUnit = view.metresPerUnit(lightField.scene);
    walk.exposureScale = view.exposureScale();
    walk.toneMap = view.toneMapSettings();
    const WalkthroughResult result =
        renderWalkthrough(*cameraPath, cameraDesc, walk, [&](const Camera& frameCamera, Image& frameImage) {
          renderFrame(frameCamera);
          std::swap(frameImage, image);
        });
    frames = result.frames;
  }

  std::vector<float> depth;
  for (const Camera& frameCamera : frameCameras) {
    const auto start = SteadyClock::now();
    fastRenderer.castPrimaryRays(frameCamera, settings, depth);
    primaryMs.push_back(1e3 * secondsSince(start));
  }
  const double medianMs = median(frameMs);
  const double fps = medianMs > 0.0 ? 1e3 / medianMs : 0.0;
  const int spp = options.samples > 0 ? options.samples : camera.isThinLens() ? RenderSettings::kThinLensSamples : 1;
  if (!options.statsPath.empty()) {
    nlohmann::json json;
    json["command"] = "render";
    json["input"] = options.input;
    json["output"] = options.output;
    json["camera"] = cameraDesc.name;
    json["width"] = view.width;
    json["height"] = view.height;
    json["samples_per_pixel"] = spp;
    json["mirror_depth"] = options.mirrorDepth >= 0 ? uint32_t(options.mirrorDepth) : lightField.settings.mirrorDepth;
    json["threads"] = runtime.threads();
    json["renderer"] = options.reference ? "reference" : "fast";
    if (cameraPath) json["path"] = options.pathFile;
    json["frames"] = frames;
    json["ms_per_frame_median"] = medianMs;
    json["ms_per_frame_min"] = *std::min_element(frameMs.begin(), frameMs.end());
    json["ms_per_frame_max"] = *std::max_element(frameMs.begin(), frameMs.end());
    json["fps"] = fps;
    if (timePrimary) {
      const double primary = median(primaryMs);
      json["primary_ms_median"] = primary;
      json["primary_ms_min"] = *std::min_element(primaryMs.begin(), primaryMs.end());
      json["ratio_to_primary"] = primary > 0.0 ? medianMs / primary : 0.0;
    }
    json["load_seconds"] = loadSeconds;
    json["accel_build_seconds"] = accelSeconds;
    json["file_bytes"] = std::filesystem::file_size(options.input);
    writeFileAtomically(options.statsPath, json.dump(2) + "\n");
  }
  fmt::print("wrote {} ({}x{}, {} sample{}/pixel, {} renderer, {} frame{}: median {:.2f} ms/frame = {:.1f} fps; "
             "load {:.3f} s, BVH {:.3f} s)\n",
             options.output, view.width, view.height, spp, spp == 1 ? "" : "s", options.reference ? "reference" : "fast",
             frames, frames == 1 ? "" : "s", medianMs, fps, loadSeconds, accelSeconds);
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
      ->check(CLI::Range(1, kMaxFrames))
      ->capture_default_str();
  command->add_option("--samples", options->samples,
                      "Camera samples per pixel (0 = 1 at the pixel centre for a pinhole, 16 for a thin lens)")
      ->check(CLI::Range(0, RenderSettings::kMaxSamplesPerPixel))
      ->capture_default_str();
  command->add_option("--mirror-depth", options->mirrorDepth,
                      "Mirror reflections followed (-1 = the bake's own mirror depth)")
      ->check(CLI::Range(-1, RenderSettings::kMaxMirrorDepth))
      ->capture_default_str();
  auto* reference = command->add_flag("--reference", options->reference,
                                      "Use the straightforward reference renderer (src/render) instead of the fast one");
  command->add_flag("--fast", options->fast, "Use the fast renderer (the default)")->excludes(reference);
  command->add_option("--path", options->pathFile,
                      "Camera path JSON (keyframes; see README): render a walk-through to -o frames/%04d.png or -o walk.mp4");
  command->add_option("--stats", options->statsPath,
                      "Write JSON: frames, ms_per_frame_median, fps, primary_ms_median (primary rays alone), load and BVH times");
  options->view.addCameraOptions(*command);
  options->view.addImageOptions(*command);
  command->callback([options, &global] { runRender(*options, global); });
}

}  // namespace pl
