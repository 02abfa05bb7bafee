// Path tracer throughput: paths (camera samples) per second on the built-in Cornell box at
// 512×512, all threads, default settings (MIS, Russian roulette after 3 bounces, no depth
// cap). One iteration renders the whole image at 4 spp (≈ 1 M paths); Google Benchmark
// repeats it and reports the median. Run:
//   build/bench/trace_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <time.h>

#include "accel/accel.h"
#include "camera/camera.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "scene/scene.h"
#include "trace/trace.h"

namespace {

/// CPU time of the whole process (all threads), seconds. paths per CPU-second does not depend
/// on how many cores other processes leave us, so it is the figure to compare across runs on
/// a shared machine; multiply by the core count for the idle-machine rate.
double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

void BM_TraceCornell512(benchmark::State& state) {
  pl::Progress::setEnabled(false);
  pl::ThreadPool pool(0);  // all hardware threads
  const pl::Scene scene = pl::makeCornellBox();
  const pl::Accel accel(scene);
  const pl::PathTracer tracer(scene, accel);
  const pl::Camera camera(scene.cameras.front(), 512, 512);
  pl::TraceSettings settings;
  settings.spp = static_cast<int>(state.range(0));
  settings.showProgress = false;
  uint64_t paths = 0, rays = 0;
  const double cpuStart = processCpuSeconds();
  for (auto _ : state) {
    const pl::TraceResult result = tracer.render(camera, settings);
    benchmark::DoNotOptimize(result.radiance.pixels.data());
    paths += result.stats.paths;
    rays += result.stats.rays;
    ++settings.seed;  // a fresh image each iteration
  }
  const double cpuSeconds = processCpuSeconds() - cpuStart;
  state.SetItemsProcessed(static_cast<int64_t>(paths));
  state.counters["paths_per_cpu_s"] = static_cast<double>(paths) / cpuSeconds;
  state.counters["paths_per_s"] = benchmark::Counter(static_cast<double>(paths), benchmark::Counter::kIsRate);
  state.counters["rays_per_s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
  state.counters["rays_per_path"] = static_cast<double>(rays) / static_cast<double>(paths ? paths : 1);
  state.counters["threads"] = pool.threads();
}
BENCHMARK(BM_TraceCornell512)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
