// Ray-casting throughput of pl::Accel (Embree 3), in millions of rays per second, with all
// hardware threads (pl::ThreadPool + pl::parallelForRange):
//   Primary/Packets   640×480 pinhole camera rays, 4×4-pixel blocks as 16-wide packets
//                     (Accel::intersectCoherent)
//   Primary/Single    the same rays one at a time (Accel::intersect)
//   Incoherent/Stream rays from random surface points in uniformly random directions
//                     (Accel::intersectIncoherent)
//   Incoherent/Single the same rays one at a time
//   Occlusion/Stream  shadow segments between two random surface points (Accel::occludedMany)
//   Bounce/Stream     a path tracer's second-bounce rays: cosine-distributed directions from
//                     the points the camera sees (jittered pixels), on the side facing the
//                     camera (Accel::intersectIncoherent)
// on two scenes: the built-in Cornell box (32 triangles) and a generated ~1M-triangle scene
// (4×4 bumpy spheres of 65,024 triangles each inside an open box). Rays are generated once,
// outside the timed loop; only the traversal is timed. Run all (medians of 5 repetitions):
//   bench/run.sh build        or
//   build/bench/ray_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <ctime>
#include <memory>
#include <span>
#include <vector>

#include "accel/accel.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/scene.h"

namespace {

using pl::Ray;
using pl::RayHit;
using pl::Vec3;

constexpr int kWidth = 640, kHeight = 480;
constexpr int kBlock = 4;              ///< 4×4 pixels = one 16-wide packet
constexpr uint64_t kGrainRays = 4096;  ///< rays per parallel task
constexpr int kRandomRays = 1 << 20;   ///< incoherent and occlusion rays per iteration

// ---------------------------------------------------------------------------------------
// Scenes.

/// A UV sphere of `rings` × `segments` quads (triangle fans at the poles, so no degenerate
/// triangles) with radius modulated by a few sinusoids: 2·segments·(rings − 1) triangles.
void addBumpySphere(pl::Mesh& mesh, const Vec3& centre, float radius, int rings, int segments, uint32_t material) {
  auto point = [&](float theta, float phi) {
    const float bump = 1.0f + 0.06f * std::sin(9.0f * theta) * std::cos(7.0f * phi) +
                       0.03f * std::sin(23.0f * theta + 1.0f) * std::sin(19.0f * phi);
    return centre + radius * bump * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  };
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  mesh.positions.push_back(point(0.0f, 0.0f));      // north pole: base
  mesh.positions.push_back(point(pl::kPi, 0.0f));   // south pole: base + 1
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j)
      mesh.positions.push_back(point(pl::kPi * i / rings, pl::kTwoPi * j / segments));
  auto ring = [&](int i, int j) { return base + 2 + static_cast<uint32_t>((i - 1) * segments + (j % segments)); };
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    mesh.triangles.push_back({a, b, c});
    mesh.materials.push_back(material);
  };
  for (int j = 0; j < segments; ++j) {
    add(base, ring(1, j + 1), ring(1, j));
    add(base + 1, ring(rings - 1, j), ring(rings - 1, j + 1));
    for (int i = 1; i + 1 < rings; ++i) {
      add(ring(i, j), ring(i, j + 1), ring(i + 1, j));
      add(ring(i + 1, j), ring(i, j + 1), ring(i + 1, j + 1));
    }
  }
}

/// 16 bumpy spheres (2·256·127 = 65,024 triangles each, 1,040,384 in all) in an open box.
pl::Scene makeMillionTriangleScene() {
  pl::Scene scene;
  scene.sourcePath = "bench:spheres";
  scene.materials.push_back({.name = "grey", .bsdf = pl::LambertBsdf{pl::Rgb(0.5f)}});
  pl::Mesh spheres;
  spheres.name = "spheres";
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      addBumpySphere(spheres, Vec3(x - 1.5f, y - 1.5f, 0.0f), 0.42f, 128, 256, 0);
  scene.meshes.push_back(std::move(spheres));
  // The box: floor, ceiling, back and side walls (open towards the camera at −z).
  pl::Mesh box;
  box.name = "box";
  const float s = 2.5f;
  const Vec3 c[8] = {{-s, -s, -s}, {s, -s, -s}, {s, s, -s}, {-s, s, -s}, {-s, -s, s}, {s, -s, s}, {s, s, s}, {-s, s, s}};
  box.positions.assign(std::begin(c), std::end(c));
  const uint32_t quads[5][4] = {{0, 1, 5, 4}, {3, 7, 6, 2}, {4, 5, 6, 7}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  for (const auto& q : quads) {
    box.triangles.push_back({q[0], q[1], q[2]});
    box.triangles.push_back({q[0], q[2], q[3]});
    box.materials.insert(box.materials.end(), 2, 0u);
  }
  scene.meshes.push_back(std::move(box));
  pl::CameraDesc camera;
  camera.name = "front";
  camera.eye = Vec3(0.0f, 0.0f, -6.0f);
  camera.target = Vec3(0.0f);
  camera.fovYDegrees = 45.0f;
  scene.cameras.push_back(camera);
  scene.finalize();
  return scene;
}

/// A scene, its BVH and the rays every benchmark on it uses (built once per process).
struct Workload {
  pl::Scene scene;
  std::unique_ptr<pl::Accel> accel;
  std::vector<Ray> primary;     ///< in 4×4-pixel block order (16 consecutive = one packet)
  std::vector<Ray> incoherent;  ///< random surface point, random direction
  std::vector<Ray> shadow;      ///< segment between two random surface points
  std::vector<Ray> bounce;      ///< diffuse bounce from a camera-visible point

  explicit Workload(pl::Scene s) : scene(std::move(s)) {
    accel = std::make_unique<pl::Accel>(scene);
    makePrimaryRays();
    makeRandomRays();
    makeBounceRays();
  }

  /// The pinhole camera ray through image position (px, py) in pixels (the camera module's
  /// convention: vertical field of view, square pixels, row 0 at the top).
  Ray cameraRay(float px, float py) const {
    const pl::CameraDesc& cam = scene.cameras.front();
    const Vec3 forward = glm::normalize(cam.target - cam.eye);
    const Vec3 right = glm::normalize(glm::cross(forward, cam.up));
    const Vec3 up = glm::cross(right, forward);
    const float tanHalf = std::tan(glm::radians(cam.fovYDegrees) * 0.5f);
    const float aspect = static_cast<float>(kWidth) / kHeight;
    const float sx = (2.0f * px / kWidth - 1.0f) * tanHalf * aspect;
    const float sy = (1.0f - 2.0f * py / kHeight) * tanHalf;
    return {cam.eye, glm::normalize(forward + sx * right + sy * up)};
  }

  /// Rays through pixel centres, ordered in 4×4-pixel blocks.
  void makePrimaryRays() {
    primary.reserve(kWidth * kHeight);
    for (int by = 0; by < kHeight; by += kBlock)
      for (int bx = 0; bx < kWidth; bx += kBlock)
        for (int y = by; y < by + kBlock; ++y)
          for (int x = bx; x < bx + kBlock; ++x) primary.push_back(cameraRay(x + 0.5f, y + 0.5f));
  }

  /// Second-bounce rays of a path tracer: from the first hit of a random camera ray, a
  /// cosine-distributed direction about the geometric normal turned towards the camera.
  /// Camera rays that miss are drawn again.
  void makeBounceRays() {
    pl::Pcg32 rng(2027, 13);
    bounce.reserve(kRandomRays);
    while (bounce.size() < static_cast<size_t>(kRandomRays)) {
      const Ray ray = cameraRay(kWidth * rng.uniform(), kHeight * rng.uniform());
      RayHit hit;
      if (!accel->intersect(ray, hit)) continue;
      const pl::Mesh& mesh = scene.meshes[hit.mesh];
      const pl::UVec3 tri = mesh.triangles[hit.triangle];
      const Vec3 p0 = mesh.positions[tri.x], p1 = mesh.positions[tri.y], p2 = mesh.positions[tri.z];
      Vec3 normal = glm::normalize(glm::cross(p1 - p0, p2 - p0));
      if (glm::dot(normal, ray.direction) > 0.0f) normal = -normal;
      const Vec3 position = ray.origin + hit.t * ray.direction;
      const Vec3 d = pl::Frame::fromNormal(normal).toWorld(pl::sampleCosineHemisphere({rng.uniform(), rng.uniform()}));
      bounce.push_back({pl::offsetRayOrigin(position, normal, d), d});
    }
  }

  struct SurfacePoint {
    Vec3 position, normal;
  };
  /// Uniform by area over all triangles.
  SurfacePoint randomSurfacePoint(pl::Pcg32& rng, const pl::Distribution1D& byArea,
                                  const std::vector<std::pair<uint32_t, uint32_t>>& index) const {
    const auto [m, t] = index[byArea.sample(rng.uniform())];
    const pl::Mesh& mesh = scene.meshes[m];
    const pl::UVec3 tri = mesh.triangles[t];
    const pl::Vec2 b = pl::sampleUniformTriangle({rng.uniform(), rng.uniform()});
    const Vec3 p0 = mesh.positions[tri.x], p1 = mesh.positions[tri.y], p2 = mesh.positions[tri.z];
    return {(1.0f - b.x - b.y) * p0 + b.x * p1 + b.y * p2, glm::normalize(glm::cross(p1 - p0, p2 - p0))};
  }

  void makeRandomRays() {
    std::vector<float> areas;
    std::vector<std::pair<uint32_t, uint32_t>> index;
    for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
      const pl::Mesh& mesh = scene.meshes[m];
      for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        const pl::UVec3 tri = mesh.triangles[t];
        areas.push_back(0.5f * glm::length(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                                      mesh.positions[tri.z] - mesh.positions[tri.x])));
        index.emplace_back(m, t);
      }
    }
    const pl::Distribution1D byArea(areas);
    pl::Pcg32 rng(2026, 11);
    incoherent.reserve(kRandomRays);
    shadow.reserve(kRandomRays);
    for (int i = 0; i < kRandomRays; ++i) {
      const SurfacePoint p = randomSurfacePoint(rng, byArea, index);
      const Vec3 d = pl::sampleUniformSphere({rng.uniform(), rng.uniform()});
      incoherent.push_back({pl::offsetRayOrigin(p.position, p.normal, d), d});
      const SurfacePoint q = randomSurfacePoint(rng, byArea, index);
      const Vec3 toQ = q.position - p.position;
      const float distance = glm::length(toQ);
      const Vec3 dir = distance > 0.0f ? toQ / distance : p.normal;
      Ray r{pl::offsetRayOrigin(p.position, p.normal, dir), dir};
      r.tMax = distance * (1.0f - 1e-4f);
      shadow.push_back(r);
    }
  }
};

const Workload& cornell() {
  static const Workload w(pl::makeCornellBox());
  return w;
}
const Workload& millionTriangles() {
  static const Workload w(makeMillionTriangleScene());
  return w;
}
const Workload& workload(int which) { return which == 0 ? cornell() : millionTriangles(); }
const char* const kSceneNames[] = {"cornell", "spheres1M"};

// ---------------------------------------------------------------------------------------
// Benchmarks. state.range(0) selects the scene (0 = Cornell box, 1 = 1M triangles).

/// CPU time consumed by all threads of this process, in seconds.
double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Runs `body(begin, end)` over [0, rays) in parallel once per iteration and reports:
///   Mrays           millions of rays per wall-clock second (the figure to quote)
///   Mrays_per_cpu_s millions of rays per CPU-second of the whole process: on a machine
///                   shared with other jobs this stays meaningful where the wall-clock rate
///                   does not (× the thread count ≈ the rate on an idle machine; a lower
///                   bound, since idle TBB workers spin for a while before sleeping)
template <class Body>
void runRays(benchmark::State& state, size_t rays, const Body& body) {
  pl::ThreadPool pool(0);  // all hardware threads, FTZ/DAZ on every worker
  pl::enableFlushDenormals();
  state.SetLabel(kSceneNames[state.range(0)]);
  const double cpuStart = processCpuSeconds();
  for (auto _ : state) pl::parallelForRange(rays, kGrainRays, body);
  const double cpuSeconds = processCpuSeconds() - cpuStart;
  const double total = static_cast<double>(rays) * static_cast<double>(state.iterations());
  state.SetItemsProcessed(static_cast<int64_t>(total));
  state.counters["Mrays"] = benchmark::Counter(total * 1e-6, benchmark::Counter::kIsRate);
  state.counters["Mrays_per_cpu_s"] = cpuSeconds > 0.0 ? total * 1e-6 / cpuSeconds : 0.0;
  state.counters["threads"] = pool.threads();
}

void BM_PrimaryPackets(benchmark::State& state) {
  const Workload& w = workload(static_cast<int>(state.range(0)));
  std::vector<RayHit> hits(w.primary.size());
  runRays(state, w.primary.size(), [&](uint64_t b, uint64_t e) {
    w.accel->intersectCoherent(std::span(w.primary).subspan(b, e - b), std::span(hits).subspan(b, e - b));
  });
  benchmark::DoNotOptimize(hits.data());
}

void BM_PrimarySingle(benchmark::State& state) {
  const Workload& w = workload(static_cast<int>(state.range(0)));
  std::vector<RayHit> hits(w.primary.size());
  runRays(state, w.primary.size(), [&](uint64_t b, uint64_t e) {
    for (uint64_t i = b; i < e; ++i) w.accel->intersect(w.primary[i], hits[i]);
  });
  benchmark::DoNotOptimize(hits.data());
}

void BM_IncoherentStream(benchmark::State& state) {
  const Workload& w = workload(static_cast<int>(state.range(0)));
  std::vector<RayHit> hits(w.incoherent.size());
  runRays(state, w.incoherent.size(), [&](uint64_t b, uint64_t e) {
    w.accel->intersectIncoherent(std::span(w.incoherent).subspan(b, e - b), std::span(hits).subspan(b, e - b));
  });
  benchmark::DoNotOptimize(hits.data());
}

void BM_IncoherentSingle(benchmark::State& state) {
  const Workload& w = workload(static_cast<int>(state.range(0)));
  std::vector<RayHit> hits(w.incoherent.size());
  runRays(state, w.incoherent.size(), [&](uint64_t b, uint64_t e) {
    for (uint64_t i = b; i < e; ++i) w.accel->intersect(w.incoherent[i], hits[i]);
  });
  benchmark::DoNotOptimize(hits.data());
}

void BM_BounceStream(benchmark::State& state) {
  const Workload& w = workload(static_cast<int>(state.range(0)));
  std::vector<RayHit> hits(w.bounce.size());
  runRays(state, w.bounce.size(), [&](uint64_t b, uint64_t e) {
    w.accel->intersectIncoherent(std::span(w.bounce).subspan(b, e - b), std::span(hits).subspan(b, e - b));
  });
  benchmark::DoNotOptimize(hits.data());
}

void BM_OcclusionStream(benchmark::State& state) {
  const Workload& w = workload(static_cast<int>(state.range(0)));
  std::vector<uint8_t> blocked(w.shadow.size());
  runRays(state, w.shadow.size(), [&](uint64_t b, uint64_t e) {
    w.accel->occludedMany(std::span(w.shadow).subspan(b, e - b), std::span(blocked).subspan(b, e - b));
  });
  benchmark::DoNotOptimize(blocked.data());
}

// Arg(0) = Cornell box, Arg(1) = ~1M triangles. Real time: the work is spread over threads.
BENCHMARK(BM_PrimaryPackets)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PrimarySingle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_IncoherentStream)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_IncoherentSingle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OcclusionStream)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BounceStream)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
