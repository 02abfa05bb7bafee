// `plenoptic view IN.plf`: the interactive walk-through window (src/viewer/viewer.h) with the
// shared camera, exposure and tone-mapping flags, plus headless flags for tests and CI.
#include <fmt/format.h>

#include <memory>
#include <string>

#include "accel/accel.h"
#include "app/commands.h"
#include "app/view_options.h"
#include "camera/camera_path.h"
#include "core/error.h"
#include "plf/plf_file.h"
#include "viewer/viewer.h"

namespace pl {
namespace {

constexpr int kMaxFrames = 10000000;

struct ViewCommandOptions {
  std::string input;           ///< .plf light field
  int frames = 0;              ///< --frames N: quit after N frames (0 = until Esc)
  std::string screenshot;      ///< --screenshot OUT.png: written after the last frame
  std::string pathFile;        ///< --path PATH.json: scripted camera
  std::string record = "walk-path.json";  ///< --record: where P/R saves the flown path
  float speed = 0.0f;          ///< --speed: scene units per second (0 = quarter of the scene diagonal)
  int samples = 0;             ///< --samples N (0 = automatic, as render)
  int mirrorDepth = -1;        ///< --mirror-depth N (-1 = the bake's)
  bool textureLod = true;      ///< --texture-lod on|off
  ViewOptions view;
};

void runView(const ViewCommandOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  const ViewOptions& view = options.view;
  if (!options.screenshot.empty()) ViewOptions::checkImageOutput(options.screenshot, "--screenshot");
  const LightField lightField = readLightField(options.input);
  const Accel accel(lightField.scene);

  ViewerOptions viewer;
  viewer.width = view.width;
  viewer.height = view.height;
  viewer.camera = view.resolveCamera(lightField.scene);
  viewer.vignetting = view.vignetting;
  viewer.metresPerUnit = view.metresPerUnit(lightField.scene);
  viewer.exposureScale = view.exposureScale();
  viewer.toneMap = view.toneMapSettings();
  viewer.render.samplesPerPixel = options.samples;
  viewer.render.mirrorDepth = options.mirrorDepth;
  viewer.render.textureLod = options.textureLod;
  viewer.render.seed = global.seed;
  viewer.frames = options.frames;
  viewer.screenshotPath = options.screenshot;
  if (!options.pathFile.empty()) viewer.path = loadCameraPath(options.pathFile);
  viewer.recordPath = options.record;
  viewer.speed = options.speed;
  viewer.title = "plenoptic view " + options.input;
  const ViewerResult result = runViewer(lightField, accel, viewer);
  fmt::print("view: {} frames, median {:.2f} ms/frame (render {:.2f} ms){}\n", result.frames, result.msPerFrameMedian,
             result.renderMsMedian, options.screenshot.empty() ? "" : ", screenshot " + options.screenshot);
}

}  // namespace

void addViewCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<ViewCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "view",
      "Interactive walk-through of a baked light field: W/A/S/D/Q/E move, mouse drag looks, Shift/Ctrl speed, "
      "+/- exposure, T tone mapping, F12 screenshot, P record path, Esc quit");
  command->add_option("input", options->input, "Light-field file (.plf) written by `plenoptic bake`")->required();
  command->add_option("--frames", options->frames, "Quit after N frames (0 = run until Esc)")
      ->check(CLI::Range(0, kMaxFrames))
      ->capture_default_str();
  command->add_option("--screenshot", options->screenshot,
                      "Write the last frame to this image (.png tone-mapped, .exr/.hdr/.pfm radiance) on exit");
  command->add_option("--path", options->pathFile, "Fly a camera path (JSON keyframes) instead of the keys");
  command->add_option("--record", options->record, "Where P (or R) saves the recorded camera path")
      ->capture_default_str();
  command->add_option("--speed", options->speed, "Movement speed in scene units per second (0 = automatic)")
      ->check(CLI::Range(0.0f, 1e9f));
  command->add_option("--samples", options->samples, "Camera samples per pixel (0 = automatic, as render)")
      ->check(CLI::Range(0, RenderSettings::kMaxSamplesPerPixel));
  command->add_option("--mirror-depth", options->mirrorDepth, "Mirror reflections followed (-1 = the bake's)")
      ->check(CLI::Range(-1, RenderSettings::kMaxMirrorDepth));
  addTextureLodOption(*command, options->textureLod);
  options->view.width = 1024;
  options->view.height = 768;
  options->view.addCameraOptions(*command);
  options->view.addImageOptions(*command);
  command->callback([options, &global] { runView(*options, global); });
}

}  // namespace pl
