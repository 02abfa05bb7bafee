// The GPU renderer's display pass (GpuRenderer::encodeDisplay, gpu/gpu_display.h): a drawn
// frame turned into the window's 8-bit words on the GPU and read back, as the viewer does
// without a window of its own context (headless, or SDL's renderer; `read` rows), or left on
// the GPU for the present pass, as in a window with the renderer's context (`kept` rows:
// their wall time ends before the GPU has encoded the words) — for each tone curve's
// statistics: Reinhard's key (`key`: the subsample's log-average summed on the GPU, its partial
// sums read back), the automatic key (`auto`: the subsample read back, its percentiles on the
// CPU) and the linear operator (`linear`: no statistics, the floor of the pass).
//
// Light field: the built-in Cornell box baked with the draft preset (seconds), seen from its
// camera; or the .plf named by PLENOPTIC_BENCH_PLF, from its first camera.
// Counters: ms_median (one encodeDisplay: the statistics, the curve, the words and their
// read-back; it waits for the GPU), cpu_ms_median (the calling thread's CPU time in it: the
// read-backs' copies, the curve's statistics on the CPU, the driver's own work — the part a
// frame cannot overlap with the GPU's), and on the key and auto rows statistics_ms_median and
// statistics_cpu_ms_median, the same less the linear operator's at that size (what the curve's
// statistics cost). On a machine without a graphics card EGL gives Mesa's llvmpipe, whose
// "GPU" is these cores (its threads, not the calling one): there the wall times move by
// ±10 ms with the machine's load and the CPU times are the steady figures.
// Run:  build/bench/gpu_display_bench --benchmark_min_time=2
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bake/bake.h"
#include "camera/camera.h"
#include "core/progress.h"
#include "gpu/gpu.h"
#include "image/display.h"
#include "plf/plf_file.h"
#include "scene/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Setup {
  pl::LightField lightField;
  std::unique_ptr<pl::GpuRenderer> gpu;
  pl::CameraDesc camera;
  float metresPerUnit = 1.0f;
};

Setup& setup() {
  static std::unique_ptr<Setup> s;
  if (!s) {
    pl::Progress::setEnabled(false);
    const auto start = Clock::now();
    s = std::make_unique<Setup>();
    if (const char* plf = std::getenv("PLENOPTIC_BENCH_PLF")) {
      s->lightField = pl::readLightField(plf);
    } else {
      s->lightField = pl::bake(pl::makeCornellBox(), pl::bakePreset("draft"));
      s->lightField.scene.finalize();
    }
    const pl::Scene& scene = s->lightField.scene;
    s->camera = scene.cameras.empty() ? scene.automaticCamera() : scene.cameras.front();
    s->metresPerUnit = scene.sourcePath == "cornell" ? 0.001f : 1.0f;
    s->gpu = std::make_unique<pl::GpuRenderer>(s->lightField);
    std::fprintf(stderr, "[setup] %zu triangles, ready in %.1f s, on %s\n", scene.triangleCount(),
                 std::chrono::duration<double>(Clock::now() - start).count(), s->gpu->deviceName().c_str());
  }
  return *s;
}

/// The calling thread's CPU time in milliseconds.
double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// The linear operator's medians (wall, CPU) per frame size, for the statistics counters (it
/// runs first).
std::map<std::tuple<int, int, bool>, std::pair<double, double>>& floors() {
  static std::map<std::tuple<int, int, bool>, std::pair<double, double>> medians;
  return medians;
}

void BM_EncodeDisplay(benchmark::State& state, const std::string& curve, bool kept, int width, int height) {
  Setup& s = setup();
  pl::ToneMapSettings settings;
  if (curve == "auto") settings.autoKey = true;
  if (curve == "linear") settings.op = pl::ToneMapOperator::Linear;
  const pl::Camera camera(s.camera, width, height, false, s.metresPerUnit);
  s.gpu->draw(camera, pl::RenderSettings{});
  pl::DisplayEncoder encoder;
  std::vector<uint32_t> read(size_t(width) * size_t(height));
  uint32_t* words = kept ? nullptr : read.data();
  s.gpu->encodeDisplay(encoder, 1.0f, settings, words, width * 4);  // warm-up: programs, buffers
  std::vector<double> ms, cpuMs;
  for (auto _ : state) {
    const auto start = Clock::now();
    const double cpuStart = threadCpuMs();
    s.gpu->encodeDisplay(encoder, 1.0f, settings, words, width * 4);
    cpuMs.push_back(threadCpuMs() - cpuStart);
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    benchmark::DoNotOptimize(read.data());
  }
  const double m = median(ms), cpu = median(cpuMs);
  state.counters["ms_median"] = m;
  state.counters["cpu_ms_median"] = cpu;
  if (curve == "linear") {
    floors()[{width, height, kept}] = {m, cpu};
  } else if (auto floor = floors().find({width, height, kept}); floor != floors().end()) {
    state.counters["statistics_ms_median"] = m - floor->second.first;
    state.counters["statistics_cpu_ms_median"] = cpu - floor->second.second;
  }
}

const int kRegistered = [] {
  for (auto [width, height] : {std::pair{1920, 1080}, std::pair{640, 480}})
    for (bool kept : {false, true})
      for (const char* curve : {"linear", "key", "auto"})
        benchmark::RegisterBenchmark(("encode_display/" + std::string(kept ? "kept/" : "read/") + curve + "/" +
                                      std::to_string(width) + "x" + std::to_string(height)).c_str(),
                                     BM_EncodeDisplay, std::string(curve), kept, width, height)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();
