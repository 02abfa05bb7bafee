// Relighting a saved light field stage by stage (bake/relight.h): reading X.plf, building the
// relighter from X.plv (and the tixel setup X.plt beside it), then the first directional light
// turned by --degrees of azimuth (about the world's y axis) and relit to the bake's tolerance,
// --turns times. Prints one JSON object (seconds; docs/benchmarks.md "Relighting").
// --save-tixel-setup first builds the parameterisation as the bake does and writes X.plt from
// it, as the bake would have (for light fields baked before the .plt existed), timing that
// (what a relighter without the .plt spends filling the tixels).
//
//   relight_bench X.plf [--degrees 10] [--turns 1] [--threads 2] [--save-tixel-setup]
//
// --live SECONDS: what the viewer runs instead (viewer/live_relight.h): the light field's CPU
// renderer draws frames for a --width × --height (640 × 480) window from the scene's first
// camera one after another on --threads threads, first for a few seconds at full resolution
// with nothing beside it, then as a walking viewer draws them (every frame "moving": at the
// render scale that holds the frame rate) while a LiveRelight (built first) turns the sun by the
// viewer's key twice (10°) and re-propagates, the cores shared by --share
// split|cap|idle|nice (viewer/core_share.h: the renderer's threads, the target frame rate —
// --target-fps, default 30 as the viewer's, or the policy's — and the frame cap, asked before
// every frame as the viewer does); every frame is drawn with the newest relit light field.
// Prints the frames' rate alone and while the relighter works (fps of the median frame and of
// the 90th-percentile frame, "p10"), the render scale they ran at (median and lowest), the
// first updated frame and the convergence time after the key (wall seconds), and stops after
// SECONDS of relighting if it has not converged by then.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "accel/accel.h"
#include "bake/parameterisation.h"
#include "camera/camera.h"
#include "bake/relight.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/timing.h"
#include "light/lights.h"
#include "plf/plf_file.h"
#include "plf/plv_file.h"
#include "realtime/realtime.h"
#include "viewer/core_share.h"
#include "viewer/live_relight.h"
#include "viewer/render_scale.h"

namespace {

/// The q-quantile (0 … 1) of v (the nearest rank below).
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}
double median(const std::vector<double>& v) { return quantile(v, 0.5); }

/// --live: frames of the CPU renderer alone, then beside the viewer's LiveRelight (see above).
std::string runLive(const std::string& plf, const pl::LightField& lf, double seconds, int width, int height,
                    pl::RelightShare share, double targetFps) {
  using namespace pl;
  using Clock = std::chrono::steady_clock;
  const Accel accel(lf.scene);
  const FastRenderer baked(lf, accel);
  const CameraDesc desc = lf.scene.cameras.empty() ? lf.scene.automaticCamera() : lf.scene.cameras[0];
  const RenderSettings settings;
  Image image;
  auto setupStart = Clock::now();
  LiveRelight live(lf, accel, visibilityPathFor(plf), share);
  live.waitIdle();
  const double setupSeconds = secondsSince(setupStart);
  if (!live.status().message.empty()) fail("{}", live.status().message);
  std::vector<double> alone, beside, scales;
  for (const auto start = Clock::now(); alone.size() < 20 || secondsSince(start) < 5.0;) {
    const auto frameStart = Clock::now();
    baked.render(Camera(desc, width, height), settings, image);
    alone.push_back(std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count());
  }
  live.press(RelightKey::SunRight);
  live.press(RelightKey::SunRight);
  const auto relightStart = Clock::now();
  ShareScale controllers;
  double firstShown = -1.0;
  int renderThreads = 0;
  RelightStatus status;
  for (;;) {
    const auto frameStart = Clock::now();
    if (live.update() && firstShown < 0.0) firstShown = secondsSince(relightStart);
    // As the viewer's frame: the share asked first, the relit light field drawn at the scale.
    const CoreShare cs = coreShare(share, parallelThreads(), live.busy(), true, targetFps);
    if (cs.renderThreads > 0) renderThreads = cs.renderThreads;
    RenderScaleController& controller = controllers(cs);
    const double scale = controller.scale(true);
    int w = width, h = height;
    scaledSize(width, height, scale, w, h);
    const FastRenderer& renderer = live.renderer() ? *live.renderer() : baked;
    drawWithShare(cs, [&] { renderer.render(Camera(desc, w, h), settings, image); });
    controller.record(scale, std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count());
    if (cs.minFrameSeconds > 0.0)
      std::this_thread::sleep_until(frameStart + std::chrono::duration<double>(cs.minFrameSeconds));
    status = live.status();
    const bool done = status.ready && !live.busy() && live.showsNewest();
    if (done || !status.message.empty() || secondsSince(relightStart) > seconds) break;
    beside.push_back(std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count());
    scales.push_back(scale);
  }
  const double relightSeconds = secondsSince(relightStart);
  const bool converged = status.converged && !status.running && live.showsNewest();
  return fmt::format(
      "{{\"share\": \"{}\", \"width\": {}, \"height\": {}, \"threads\": {}, \"render_threads_beside\": {}, "
      "\"target_fps\": {}, \"setup_seconds\": {:.2f}, \"alone_frames\": {}, \"alone_ms_median\": {:.2f}, "
      "\"alone_fps\": {:.2f}, \"beside_frames\": {}, \"beside_ms_median\": {:.2f}, \"beside_fps\": {:.2f}, "
      "\"beside_fps_p10\": {:.2f}, \"scale_median\": {:.4f}, \"scale_min\": {:.4f}, "
      "\"first_updated_frame_seconds\": {:.2f}, \"relighter_first_frame_seconds\": {:.2f}, \"iterations\": {}, "
      "\"converged\": {}, \"relight_seconds\": {:.2f}{}}}",
      relightShareName(share), width, height, parallelThreads(), renderThreads > 0 ? renderThreads : parallelThreads(), targetFps,
      setupSeconds, alone.size(), median(alone), 1000.0 / median(alone), beside.size(), median(beside),
      1000.0 / median(beside), 1000.0 / quantile(beside, 0.9), median(scales), quantile(scales, 0.0), firstShown,
      status.firstFrameSeconds, status.iteration, converged, relightSeconds,
      status.message.empty() ? "" : fmt::format(", \"message\": \"{}\"", status.message));
}

int run(int argc, char** argv) {
  using namespace pl;
  if (argc < 2)
    fail("usage: relight_bench X.plf [--degrees D] [--turns N] [--threads N] [--save-tixel-setup] | "
         "[--live SECONDS [--share split|cap|idle|nice] [--target-fps F] [--width W] [--height H]]");
  const std::string plf = argv[1];
  float degrees = 10.0f;
  int turns = 1, threads = 2;
  bool saveSetup = false;
  double liveSeconds = 0.0;
  int width = 640, height = 480;
  RelightShare share = RelightShare::Split;
  double targetFps = 30.0;
  for (int i = 2; i < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--save-tixel-setup") {
      saveSetup = true;
      --i;
      continue;
    }
    if (i + 1 >= argc) fail("relight_bench: {} needs a value", flag);
    if (flag == "--degrees") degrees = std::stof(argv[i + 1]);
    else if (flag == "--turns") turns = std::stoi(argv[i + 1]);
    else if (flag == "--threads") threads = std::stoi(argv[i + 1]);
    else if (flag == "--live") liveSeconds = std::stod(argv[i + 1]);
    else if (flag == "--width") width = std::stoi(argv[i + 1]);
    else if (flag == "--height") height = std::stoi(argv[i + 1]);
    else if (flag == "--target-fps") targetFps = std::stod(argv[i + 1]);
    else if (flag == "--share") {
      if (!parseRelightShare(argv[i + 1], share)) fail("relight_bench: --share is split, cap, idle or nice, not {}", argv[i + 1]);
    }
    else fail("relight_bench: unknown flag {}", flag);
  }
  Progress::setEnabled(false);
  std::string json;
  runWithThreads(threads, [&] {
    auto start = std::chrono::steady_clock::now();
    const LightField lf = readLightField(plf);
    const double readSeconds = secondsSince(start);
    if (liveSeconds > 0.0) {
      json = runLive(plf, lf, liveSeconds, width, height, share, targetFps);
      return;
    }
    double fillSeconds = 0.0;
    if (saveSetup) {
      start = std::chrono::steady_clock::now();
      Scene scene = lf.scene;
      scene.finalize();
      const Accel accel(scene);
      const Parameterisation param = buildParameterisation(scene, accel, lf.settings);
      fillSeconds = secondsSince(start);
      writeTixelSetup(tixelSetupPathFor(visibilityPathFor(plf)), scene, param, readVisibilityInfo(visibilityPathFor(plf)).hash);
      fmt::print(stderr, "relight_bench: parameterisation built in {:.2f} s and saved\n", fillSeconds);
    }
    start = std::chrono::steady_clock::now();
    std::string setupNotes;
    Relighter relighter(lf, visibilityPathFor(plf), [&](const std::string& note) {
      fmt::print(stderr, "{}\n", note);
      setupNotes += note;
    });
    const double setupSeconds = secondsSince(start);
    uint32_t sunIndex = UINT32_MAX;
    for (uint32_t l = 0; l < lf.scene.lights.size() && sunIndex == UINT32_MAX; ++l)
      if (std::holds_alternative<DirectionalLight>(lf.scene.lights[l])) sunIndex = l;
    if (sunIndex == UINT32_MAX) fail("{}: the scene has no directional light to turn", plf);
    json = fmt::format("{{\"read_seconds\": {:.3f}, \"parameterisation_seconds\": {:.3f}, \"relighter_seconds\": {:.3f}, "
                       "\"tixel_setup_read\": {}, \"turns\": [",
                       readSeconds, fillSeconds, setupSeconds, setupNotes.find("filling the tixels again") == std::string::npos);
    for (int turn = 0; turn < turns; ++turn) {
      Light sun = relighter.scene().lights[sunIndex];
      Vec3& d = std::get<DirectionalLight>(sun).direction;
      const float a = glm::radians(degrees), c = std::cos(a), s = std::sin(a);
      d = Vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
      relighter.setLight(sunIndex, sun);
      const RelightStats st = relighter.relight([&](const RelightProgress& p) {
        fmt::print(stderr, "relight_bench: iteration {} residual {:.2e} at {:.2f} s\n", p.iteration, p.residual, p.seconds);
        return true;
      });
      json += fmt::format("{}{{\"degrees\": {}, \"sun_mask_seconds\": {:.3f}, \"first_shot_seconds\": {:.3f}, "
                          "\"warm_start_seconds\": {:.3f}, \"first_frame_seconds\": {:.3f}, \"iterations\": {}, "
                          "\"residual\": {:.3e}, \"converged\": {}, \"converged_seconds\": {:.3f}}}",
                          turn > 0 ? ", " : "", degrees, st.sunMaskSeconds, st.firstShotSeconds, st.warmStartSeconds,
                          st.firstFrameSeconds, st.iterations, st.residual, st.converged, st.seconds);
    }
    json += "]}";
  });
  fmt::print("{}\n", json);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    fmt::print(stderr, "relight_bench: {}\n", e.what());
    return 1;
  }
}
