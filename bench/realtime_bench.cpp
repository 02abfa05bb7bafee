// Real-time walk-through speed: median milliseconds per frame of the fast light-field
// renderer (src/realtime), next to Embree primary-ray casting alone for the same view (the
// limit of this design: the renderer casts exactly these rays, then looks the light field up).
//
// Scenes (each baked once, at the first benchmark that needs it, with the default preset
// through the bake API; the bake time is printed, not measured):
//   cornell   the built-in measured Cornell box (32 triangles)
//   glossy    CornellBox-Glossy (Morgan McGuire's archive, tests/data/cornell-mcguire): glossy floor
//             and spheres, so lookups are 16-neighbour ones
//   mirror    CornellBox-Mirror: a mirror sphere (reflection rays, bounded depth)
//   million   the built-in Cornell box with every triangle regularly subdivided into 180²
//             triangles: 1.04 M triangles. Subdivision keeps the faces planar, so the charts
//             (and the bake) stay those of the box, while primary visibility pays for a
//             million-triangle BVH: it isolates what the design claims, a frame cost that
//             does not depend on how complex the lighting or the light field is.
//   plf       the light field in the .plf file named by the environment variable
//             PLENOPTIC_BENCH_PLF (not baked; registered only when the variable is set), seen
//             from its scene's first camera: e.g. a default bake of Sponza (issue 13's
//             walk-through target), whose frames are too slow to bake inside a benchmark.
// Counters: ms_median (fast renderer, radiance only), primary_ms_median (rays only),
// ratio = ms_median / primary_ms_median, the same with minima (ms_min, primary_ms_min,
// ratio_min), CPU milliseconds per frame summed over threads (cpu_ms, primary_cpu_ms,
// cpu_ratio: independent of other processes' load on a shared machine), display_ms_median (exposure + Reinhard + sRGB into
// 8-bit pixels, as the viewer does), fps = 1000 / ms_median.
// Run:  build/bench/realtime_bench --benchmark_min_time=1
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "bake/bake.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "image/display.h"
#include "plf/plf_file.h"
#include "realtime/realtime.h"
#include "scene/scene.h"

namespace {

using Clock = std::chrono::steady_clock;

/// Splits every triangle of every mesh into n² triangles (regular subdivision: barycentric
/// grid of step 1/n), interpolating normals and uvs; materials are kept.
pl::Scene subdivided(pl::Scene scene, int n) {
  for (pl::Mesh& mesh : scene.meshes) {
    pl::Mesh out;
    out.name = mesh.name;
    const bool hasNormals = !mesh.normals.empty(), hasUvs = !mesh.uvs.empty();
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const pl::UVec3 tri = mesh.triangles[t];
      const uint32_t base = uint32_t(out.positions.size());
      // Vertex (i, j) with i + j ≤ n at barycentrics (i/n, j/n) towards p1 and p2.
      auto index = [&](int i, int j) { return base + uint32_t(j * (n + 1) - j * (j - 1) / 2 + i); };
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i + j <= n; ++i) {
          const float b1 = float(i) / float(n), b2 = float(j) / float(n), b0 = 1.0f - b1 - b2;
          out.positions.push_back(b0 * mesh.positions[tri.x] + b1 * mesh.positions[tri.y] + b2 * mesh.positions[tri.z]);
          if (hasNormals)
            out.normals.push_back(glm::normalize(b0 * mesh.normals[tri.x] + b1 * mesh.normals[tri.y] + b2 * mesh.normals[tri.z]));
          if (hasUvs) out.uvs.push_back(b0 * mesh.uvs[tri.x] + b1 * mesh.uvs[tri.y] + b2 * mesh.uvs[tri.z]);
        }
      for (int j = 0; j < n; ++j)
        for (int i = 0; i + j < n; ++i) {
          out.triangles.push_back({index(i, j), index(i + 1, j), index(i, j + 1)});
          out.materials.push_back(mesh.materials[t]);
          if (i + j + 1 < n) {
            out.triangles.push_back({index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
            out.materials.push_back(mesh.materials[t]);
          }
        }
    }
    mesh = std::move(out);
  }
  scene.finalize();
  return scene;
}

struct BakedScene {
  pl::LightField lightField;
  std::unique_ptr<pl::Accel> accel;
  std::unique_ptr<pl::FastRenderer> renderer;
  pl::CameraDesc camera;
  float metresPerUnit = 1.0f;
};

pl::Scene sceneNamed(const std::string& name) {
  const std::string mcguire = std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/";
  if (name == "cornell") return pl::makeCornellBox();
  if (name == "glossy") return pl::loadScene(mcguire + "CornellBox-Glossy.obj");
  if (name == "mirror") return pl::loadScene(mcguire + "CornellBox-Mirror.obj");
  if (name == "million") return subdivided(pl::makeCornellBox(), 180);
  throw pl::Error("unknown benchmark scene " + name);
}

/// The baked scene `name` (baked on first use, kept for the other benchmarks).
BakedScene& baked(const std::string& name) {
  static std::map<std::string, std::unique_ptr<BakedScene>> cache;
  auto& slot = cache[name];
  if (!slot) {
    pl::Progress::setEnabled(false);
    const auto start = Clock::now();
    slot = std::make_unique<BakedScene>();
    if (name == "plf") {
      slot->lightField = pl::readLightField(std::getenv("PLENOPTIC_BENCH_PLF"));
    } else {
      pl::Scene scene = sceneNamed(name);
      slot->lightField = pl::bake(std::move(scene), pl::bakePreset("default"));
      slot->lightField.scene.finalize();
    }
    const pl::Scene& scene = slot->lightField.scene;
    slot->camera = scene.cameras.empty() ? scene.automaticCamera() : scene.cameras.front();
    slot->metresPerUnit = scene.sourcePath == "cornell" ? 0.001f : 1.0f;
    slot->accel = std::make_unique<pl::Accel>(slot->lightField.scene);
    slot->renderer = std::make_unique<pl::FastRenderer>(slot->lightField, *slot->accel);
    std::fprintf(stderr, "[setup] %s: %zu triangles, %zu charts, %s in %.1f s\n", name.c_str(),
                 slot->lightField.scene.triangleCount(), slot->lightField.charts.size(),
                 name == "plf" ? "read" : "baked (default preset)", std::chrono::duration<double>(Clock::now() - start).count());
  }
  return *slot;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// CPU time of the whole process (all threads, user + system) in milliseconds.
double processCpuMs() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return 1e3 * (double(usage.ru_utime.tv_sec) + double(usage.ru_stime.tv_sec)) +
         1e-3 * (double(usage.ru_utime.tv_usec) + double(usage.ru_stime.tv_usec));
}

double msSince(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

void BM_Frame(benchmark::State& state, const std::string& name, int width, int height, float fNumber, int spp) {
  pl::ThreadPool pool(0);
  BakedScene& scene = baked(name);
  pl::CameraDesc desc = scene.camera;
  desc.fNumber = fNumber;
  const pl::Camera camera(desc, width, height, false, scene.metresPerUnit);
  pl::RenderSettings settings;
  settings.samplesPerPixel = spp;
  pl::Image image;
  std::vector<float> depth;
  pl::DisplayEncoder display;
  std::vector<uint32_t> pixels(size_t(width) * size_t(height));
  pl::ToneMapSettings toneMap;
  std::vector<double> frameMs, primaryMs, displayMs;
  double fastCpuMs = 0.0, primaryCpuMs = 0.0;
  scene.renderer->render(camera, settings, image);  // warm-up: scratch buffers, caches
  for (auto _ : state) {
    double cpu = processCpuMs();
    auto start = Clock::now();
    scene.renderer->render(camera, settings, image);
    frameMs.push_back(msSince(start));
    fastCpuMs += processCpuMs() - cpu;
    benchmark::DoNotOptimize(image.pixels.data());
    state.PauseTiming();
    cpu = processCpuMs();
    start = Clock::now();
    scene.renderer->castPrimaryRays(camera, settings, depth);  // the renderer's first pass alone
    primaryMs.push_back(msSince(start));
    primaryCpuMs += processCpuMs() - cpu;
    start = Clock::now();
    display.encode(image, 1.0f, toneMap, pixels.data(), width * 4);
    displayMs.push_back(msSince(start));
    state.ResumeTiming();
  }
  const double ms = median(frameMs), primary = median(primaryMs);
  // The machine is shared: medians move with other processes' load, minima much less, so the
  // ratio of minima is the steadier estimate of the renderer's cost over ray casting alone.
  const double msMin = *std::min_element(frameMs.begin(), frameMs.end());
  const double primaryMin = *std::min_element(primaryMs.begin(), primaryMs.end());
  state.counters["ms_min"] = msMin;
  state.counters["primary_ms_min"] = primaryMin;
  state.counters["ratio_min"] = primaryMin > 0 ? msMin / primaryMin : 0.0;
  // CPU time (all threads) per frame: what the frame costs the machine, independent of how
  // much of it other processes took; cpu_ratio is the load-independent cost ratio.
  const double frames = double(frameMs.size());
  state.counters["cpu_ms"] = fastCpuMs / frames;
  state.counters["primary_cpu_ms"] = primaryCpuMs / frames;
  state.counters["cpu_ratio"] = primaryCpuMs > 0 ? fastCpuMs / primaryCpuMs : 0.0;
  state.counters["ms_median"] = ms;
  state.counters["fps"] = ms > 0 ? 1e3 / ms : 0.0;
  state.counters["primary_ms_median"] = primary;
  state.counters["ratio"] = primary > 0 ? ms / primary : 0.0;
  state.counters["display_ms_median"] = median(displayMs);
  state.counters["spp"] = pl::effectiveSamplesPerPixel(settings, camera.isThinLens());
  state.counters["threads"] = pool.threads();
}

void registerAll() {
  for (const char* name : {"cornell", "glossy", "mirror", "million"})
    for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 720}})
      benchmark::RegisterBenchmark(fmt::format("frame/{}/{}x{}", name, w, h).c_str(), BM_Frame, name, w, h, 0.0f, 1)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  if (std::getenv("PLENOPTIC_BENCH_PLF"))
    for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 720}})
      benchmark::RegisterBenchmark(fmt::format("frame/plf/{}x{}", w, h).c_str(), BM_Frame, std::string("plf"), w, h, 0.0f, 1)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  // The lens model: a thin lens (f/1.4, focused at the target) with 4 and 16 aperture samples.
  for (int spp : {4, 16})
    benchmark::RegisterBenchmark(fmt::format("thinlens/cornell/640x480/spp{}", spp).c_str(), BM_Frame,
                                 std::string("cornell"), 640, 480, 1.4f, spp)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  registerAll();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
