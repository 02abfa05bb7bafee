// `plenoptic view IN.plf`: the interactive walk-through window (src/viewer/viewer.h) with the
// shared camera, exposure and tone-mapping flags, plus headless flags for tests and CI.
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <string>

#include "accel/accel.h"
#include "app/commands.h"
#include "app/view_options.h"
#include "bake/relight.h"
#include "camera/camera_path.h"
#include "core/error.h"
#include "core/file_io.h"
#include "plf/plf_file.h"
#include "viewer/viewer.h"

namespace pl {
namespace {

constexpr int kMaxFrames = 10000000;

struct ViewCommandOptions {
  std::string input;      ///< .plf light field
  std::string pathFile;   ///< --path PATH.json: scripted camera
  std::string statsPath;  ///< --stats S.json: the session's timings; empty = none
  ViewSettings view;      ///< window size, camera, exposure and tone mapping
  ViewerOptions viewer;   ///< the other flags are bound to its fields
};

/// The --stats JSON of a session (docs/user-guide.md#view), as `render --stats` names its fields.
std::string viewStatsJson(const ViewerResult& result, const ViewerOptions& viewer) {
  nlohmann::json json;
  json["frames"] = result.frames;
  json["width"] = viewer.width;
  json["height"] = viewer.height;
  json["ms_per_frame_median"] = result.msPerFrameMedian;
  json["fps"] = result.msPerFrameMedian > 0.0 ? 1e3 / result.msPerFrameMedian : 0.0;
  json["render_ms_median"] = result.renderMsMedian;
  if (result.gpuMsMedian > 0.0) json["gpu_ms_median"] = result.gpuMsMedian;
  json["renderer"] = result.device.empty() ? "cpu" : "gpu";
  if (!result.device.empty()) json["device"] = result.device;
  if (!result.fallback.empty()) json["fallback"] = result.fallback;
  json["presentation"] = result.presentation;
  json["vsync"] = result.vsync;
  if (!viewer.relightKeys.empty()) {
    json["relight_iterations"] = result.relightIterations;
    json["relight_converged"] = result.relightConverged;
    json["relight_seconds"] = result.relightSeconds;
    json["relight_first_frame_seconds"] = result.relightFirstFrameSeconds;
    json["relight_frames"] = result.relightFrames;
    json["relight_ms_per_frame_median"] = result.relightMsPerFrameMedian;
  }
  return json.dump(2) + "\n";
}

void runView(const ViewCommandOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  const ViewSettings& view = options.view;
  if (!options.viewer.screenshotPath.empty()) ViewSettings::checkImageOutput(options.viewer.screenshotPath, "--screenshot");
  if (!options.statsPath.empty()) checkOutputPath(options.statsPath, {}, "--stats");
  if (!options.viewer.windowShotPath.empty()) checkOutputPath(options.viewer.windowShotPath, {".png"}, "--window-shot");
  const LightField lightField = readLightField(options.input);
  const Accel accel(lightField.scene);

  ViewerOptions viewer = options.viewer;
  viewer.width = view.width;
  viewer.height = view.height;
  viewer.camera = view.resolveCamera(lightField.scene);
  viewer.vignetting = view.vignetting;
  viewer.metresPerUnit = view.metresPerUnit(lightField.scene);
  viewer.exposureScale = view.exposureScale();
  viewer.toneMap = view.toneMapSettings();
  viewer.render.seed = global.seed;
  if (!options.pathFile.empty()) viewer.path = loadCameraPath(options.pathFile);
  viewer.title = "plenoptic view " + options.input;
  // The relighting keys need the visibility field: the one named, else X.plv beside X.plf.
  if (viewer.visibilityPath.empty()) {
    const std::string beside = visibilityPathFor(options.input);
    if (std::filesystem::exists(beside)) viewer.visibilityPath = beside;
    else if (!viewer.relightKeys.empty()) fail("view: --relight-keys needs the visibility field {}, which is not there", beside);
    else fmt::print("view: no {}: the relighting keys are off (bake with -o next to it to get one)\n", beside);
  }
  const ViewerResult result = runViewer(lightField, accel, viewer);
  fmt::print("view: {} frames rendered, median {:.2f} ms/frame (render {:.2f} ms), renderer {}{}\n", result.frames,
             result.msPerFrameMedian, result.renderMsMedian, result.renderer,
             viewer.screenshotPath.empty() ? "" : ", screenshot " + viewer.screenshotPath);
  if (!options.statsPath.empty()) writeFileAtomically(options.statsPath, viewStatsJson(result, viewer));
  if (!viewer.relightKeys.empty())
    fmt::print("view: relit: {} iterations ({}), first frame {:.3f} s (sun masks {:.3f} s, first shot {:.3f} s), {:.3f} s "
               "in all; {} frames while propagating, median {:.2f} ms/frame{}\n",
               result.relightIterations, result.relightConverged ? "converged" : "not converged",
               result.relightFirstFrameSeconds, result.relightSunMaskSeconds, result.relightFirstShotSeconds,
               result.relightSeconds, result.relightFrames, result.relightMsPerFrameMedian,
               result.relightMessage.empty() ? "" : "; " + result.relightMessage);
}

}  // namespace

void addViewCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<ViewCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "view",
      "Interactive walk-through of a baked light field: W/A/S/D/Q/E move, mouse drag looks, Shift/Ctrl speed, "
      "+/- exposure, T tone mapping, F12 screenshot, P record path, Esc quit");
  command->add_option("input", options->input, "Light-field file (.plf) written by `plenoptic bake`")->required();
  ViewerOptions& viewer = options->viewer;
  command->add_option("--frames", viewer.frames, "Quit after N frames (0 = run until Esc)")
      ->check(CLI::Range(0, kMaxFrames))
      ->capture_default_str();
  command->add_option("--screenshot", viewer.screenshotPath,
                      "Write the last frame to this image (.png tone-mapped, .exr/.hdr/.pfm radiance) on exit");
  command->add_option("--window-shot", viewer.windowShotPath,
                      "Write the last frame's window as shown, HUD included, to this PNG on exit");
  command->add_option("--path", options->pathFile, "Fly a camera path (JSON keyframes) instead of the keys");
  command->add_option("--stats", options->statsPath,
                      "Write JSON on exit: frames, ms_per_frame_median, fps, render_ms_median, gpu_ms_median, renderer, device");
  command->add_option("--record", viewer.recordPath, "Where P (or R) saves the recorded camera path")
      ->capture_default_str();
  command->add_option("--speed", viewer.speed, "Movement speed in scene units per second (0 = automatic)")
      ->check(CLI::Range(0.0f, 1e9f));
  command
      ->add_option_function<std::string>(
          "--renderer",
          [options](const std::string& name) {
            options->viewer.renderer = name == "gpu" ? ViewerRendererChoice::Gpu : ViewerRendererChoice::Cpu;
          },
          "gpu (OpenGL 4.5 through EGL) or cpu (the fast renderer); default: the GPU one on a graphics card when it "
          "draws this light field, else the CPU one with a warning saying why")
      ->check(CLI::IsMember({"cpu", "gpu"}));
  command
      ->add_option_function<std::string>(
          "--vsync", [options](const std::string& s) { options->viewer.vsync = s == "on"; },
          "GPU renderer in the window: swap at the display's vertical sync (on) or as soon as a frame is drawn (off)")
      ->check(CLI::IsMember({"on", "off"}))
      ->default_str("on");
  command->add_option("--target-fps", viewer.targetFps,
                      "CPU renderer: frame rate held while moving, by rendering at a lower resolution (0 = always full)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  command->add_option("--visibility", viewer.visibilityPath,
                      "The visibility field (.plv) the relighting keys re-propagate from (default: the .plf's X.plv when it exists)");
  command->add_option("--relight-keys", viewer.relightKeys,
                      "Press these relighting keys at the first frame (e.g. JJ] : sun 10 degrees left, brighter); without "
                      "--frames, quit once the light field has converged (headless benchmarks)");
  addRenderSettingsOptions(*command, viewer.render);
  options->view.width = viewer.width;
  options->view.height = viewer.height;
  addCameraOptions(*command, options->view);
  addImageOptions(*command, options->view);
  command->callback([options, &global] { runView(*options, global); });
}

}  // namespace pl
