// Relighting a saved light field stage by stage (bake/relight.h): reading X.plf, building the
// relighter from X.plv (and the tixel setup X.plt beside it), then the first directional light
// turned by --degrees of azimuth (about the world's y axis) and relit to the bake's tolerance,
// --turns times. Prints one JSON object (seconds; docs/benchmarks.md "Relighting").
// --save-tixel-setup first builds the parameterisation as the bake does and writes X.plt from
// it, as the bake would have (for light fields baked before the .plt existed), timing that
// (what a relighter without the .plt spends filling the tixels).
//
//   relight_bench X.plf [--degrees 10] [--turns 1] [--threads 2] [--save-tixel-setup]
#include <chrono>
#include <cstdlib>
#include <string>

#include <fmt/format.h>

#include "accel/accel.h"
#include "bake/parameterisation.h"
#include "bake/relight.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/timing.h"
#include "light/lights.h"
#include "plf/plf_file.h"
#include "plf/plv_file.h"

namespace {

int run(int argc, char** argv) {
  using namespace pl;
  if (argc < 2) fail("usage: relight_bench X.plf [--degrees D] [--turns N] [--threads N]");
  const std::string plf = argv[1];
  float degrees = 10.0f;
  int turns = 1, threads = 2;
  bool saveSetup = false;
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
    else fail("relight_bench: unknown flag {}", flag);
  }
  Progress::setEnabled(false);
  std::string json;
  runWithThreads(threads, [&] {
    auto start = std::chrono::steady_clock::now();
    const LightField lf = readLightField(plf);
    const double readSeconds = secondsSince(start);
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
