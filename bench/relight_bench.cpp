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
// renderer draws frames of --width × --height (640 × 480) from the scene's first camera one
// after another on --threads threads, first for a few seconds with nothing beside it, then
// while a LiveRelight (built first, with --share idle|nice) turns the sun by the viewer's key
// twice (10°) and re-propagates; every frame is rendered as a walking viewer renders it, with
// the newest relit light field. Prints the frame times (median, and the fps they give) alone
// and while propagating, the first updated frame and the convergence time; stops after
// SECONDS of relighting if it has not converged by then.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string>
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
#include "viewer/live_relight.h"

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// --live: frames of the CPU renderer alone, then beside the viewer's LiveRelight (see above).
std::string runLive(const std::string& plf, const pl::LightField& lf, double seconds, int width, int height,
                    pl::RelightShare share) {
  using namespace pl;
  using Clock = std::chrono::steady_clock;
  const Accel accel(lf.scene);
  const FastRenderer baked(lf, accel);
  const Camera camera(lf.scene.cameras.empty() ? lf.scene.automaticCamera() : lf.scene.cameras[0], width, height);
  const RenderSettings settings;
  Image image;
  auto frame = [&](const FastRenderer& renderer) {
    const auto start = Clock::now();
    renderer.render(camera, settings, image);
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  };
  auto setupStart = Clock::now();
  LiveRelight live(lf, accel, visibilityPathFor(plf), share);
  live.waitIdle();
  const double setupSeconds = secondsSince(setupStart);
  if (!live.status().message.empty()) fail("{}", live.status().message);
  std::vector<double> alone, beside;
  for (const auto start = Clock::now(); alone.size() < 20 || secondsSince(start) < 5.0;) alone.push_back(frame(baked));
  live.press(RelightKey::SunRight);
  live.press(RelightKey::SunRight);
  const auto relightStart = Clock::now();
  RelightStatus status;
  for (;;) {
    live.update();
    beside.push_back(frame(live.renderer() ? *live.renderer() : baked));
    status = live.status();
    if ((status.ready && !status.running && status.converged && live.showsNewest()) || !status.message.empty() ||
        secondsSince(relightStart) > seconds)
      break;
  }
  const double relightSeconds = secondsSince(relightStart);
  return fmt::format(
      "{{\"share\": \"{}\", \"width\": {}, \"height\": {}, \"setup_seconds\": {:.2f}, \"alone_frames\": {}, "
      "\"alone_ms_median\": {:.2f}, \"alone_fps\": {:.2f}, \"beside_frames\": {}, \"beside_ms_median\": {:.2f}, "
      "\"beside_fps\": {:.2f}, \"first_frame_seconds\": {:.2f}, \"iterations\": {}, \"converged\": {}, "
      "\"relight_seconds\": {:.2f}{}}}",
      share == RelightShare::Idle ? "idle" : "nice", width, height, setupSeconds, alone.size(), median(alone),
      1000.0 / median(alone), beside.size(), median(beside), 1000.0 / median(beside), status.firstFrameSeconds,
      status.iteration, status.converged && !status.running, relightSeconds,
      status.message.empty() ? "" : fmt::format(", \"message\": \"{}\"", status.message));
}

int run(int argc, char** argv) {
  using namespace pl;
  if (argc < 2)
    fail("usage: relight_bench X.plf [--degrees D] [--turns N] [--threads N] [--save-tixel-setup] | "
         "[--live SECONDS [--share idle|nice] [--width W] [--height H]]");
  const std::string plf = argv[1];
  float degrees = 10.0f;
  int turns = 1, threads = 2;
  bool saveSetup = false;
  double liveSeconds = 0.0;
  int width = 640, height = 480;
  RelightShare share = RelightShare::Idle;
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
    else if (flag == "--share" && (std::string(argv[i + 1]) == "idle" || std::string(argv[i + 1]) == "nice"))
      share = std::string(argv[i + 1]) == "idle" ? RelightShare::Idle : RelightShare::Nice;
    else fail("relight_bench: unknown flag {}", flag);
  }
  Progress::setEnabled(false);
  std::string json;
  runWithThreads(threads, [&] {
    auto start = std::chrono::steady_clock::now();
    const LightField lf = readLightField(plf);
    const double readSeconds = secondsSince(start);
    if (liveSeconds > 0.0) {
      json = runLive(plf, lf, liveSeconds, width, height, share);
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
