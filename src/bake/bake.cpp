// The bake driver and its presets (see bake.h).
#include "bake/bake.h"

#include <chrono>
#include <future>

#include "accel/accel.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "bake/parameterisation.h"
#include "bake/propagation.h"
#include "bake/visibility.h"

namespace pl {

BakeSettings bakePreset(const std::string& name) {
  BakeSettings s;
  s.preset = name;
  s.tixelsPerUnit = 0.0f;  // density from the scene's room scale (sceneScale)
  if (name == "draft") {
    s.tixelsAcrossScene = 20;
    s.gatherDirections = 144;
    s.glossyDirRes = 8;
    s.areaLightSamples = 16;
    s.tolerance = 5e-3f;
  } else if (name == "default") {
    s.tixelsAcrossScene = 40;
    s.gatherDirections = 256;
    s.glossyDirRes = 16;
    s.areaLightSamples = 32;
    s.tolerance = 1e-3f;
  } else if (name == "high") {
    s.tixelsAcrossScene = 60;
    s.gatherDirections = 576;
    s.glossyDirRes = 24;
    s.areaLightSamples = 64;
    s.tolerance = 2e-4f;
  } else {
    fail("unknown bake preset '{}' (choose draft, default or high)", name);
  }
  s.maxTixelsPerChartSide = 16384;
  s.maxIterations = 200;
  s.mirrorDepth = 256;
  return s;
}

uint64_t bakeMemoryEstimate(uint64_t tixels, uint64_t values, const BakeSettings& settings) {
  const uint64_t directions = uint64_t(gatherGridSide(settings.gatherDirections)) * gatherGridSide(settings.gatherDirections);
  const uint64_t visibility = tixels * (directions * sizeof(VisibilityEntry) + sizeof(uint64_t));
  constexpr uint64_t kQuadBytes = 64, kChangeBytes = 4, kValueArrays = 3;
  // Writing the .plv compresses it a batch of blocks at a time beside the field.
  const uint64_t writeBuffers = visibilityWriteBufferBytes(gatherGridSide(settings.gatherDirections));
  return visibility + writeBuffers + values * kValueArrays * sizeof(Rgb) + tixels * (kQuadBytes + kChangeBytes);
}

std::vector<std::string> bakePresetNames() { return {"draft", "default", "high"}; }

LightField bake(Scene scene, const BakeSettings& settings, const BakeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto note = [&](const std::string& text) {
    if (options.log) options.log(text);
  };
  LightField lf;
  lf.scene = std::move(scene);
  lf.settings = settings;
  const Accel accel(lf.scene);
  const Parameterisation param = buildParameterisation(lf.scene, accel, settings);
  const uint64_t hash = visibilityHash(lf.scene, param, settings);
  {
    uint64_t byKind[3] = {0, 0, 0}, tixelsByKind[3] = {0, 0, 0};
    for (const Chart& c : param.charts) {
      ++byKind[size_t(c.kind)];
      tixelsByKind[size_t(c.kind)] += c.tixelCount();
    }
    note(fmt::format("parameterisation: {} charts ({} diffuse, {} glossy, {} specular), {} tixels ({} diffuse, {} glossy), "
                     "{} values; room scale {:.4g}, tixel size {:.4g} (scene units)",
                     param.charts.size(), byKind[0], byKind[1], byKind[2], param.tixelCount, tixelsByKind[0],
                     tixelsByKind[1], param.valueCount, param.sceneScale, param.baseTixelSize));
  }
  if (options.checkMemory) options.checkMemory(bakeMemoryEstimate(param.tixelCount, param.valueCount, settings));

  VisibilityField visibility;
  bool reused = false;
  auto computeAndSave = [&] {
    visibility = computeVisibility(lf.scene, accel, param, settings);
    note(fmt::format("visibility: {} rays in {:.2f} s ({:.1f} Mrays/s), {:.1f} MB", visibility.rays, visibility.seconds,
                     visibility.seconds > 0 ? visibility.rays / visibility.seconds * 1e-6 : 0.0, visibility.bytes() / 1e6));
    if (!options.visibilityPath.empty()) writeVisibility(options.visibilityPath, visibility);
  };
  PropagationResult prop;
  if (options.reuseVisibility && !options.visibilityPath.empty()) {
    // The saved field is read on its own thread while propagation starts with the shadow rays
    // of the first shot, which do not need it; propagation waits for it after them.
    std::string why;
    double readSeconds = 0.0;
    std::future<bool> read = std::async(std::launch::async, [&] {
      const auto readStart = std::chrono::steady_clock::now();
      const bool ok = readVisibility(options.visibilityPath, hash, visibility, &why);
      readSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - readStart).count();
      return ok;
    });
    prop = propagate(lf.scene, accel, param, [&]() -> const VisibilityField& {
      reused = read.get();
      if (reused) {
        note(fmt::format("visibility: reusing {} ({} tixels × {} directions, read in {:.2f} s, overlapping the shadow rays)",
                         options.visibilityPath, visibility.tixelCount, visibility.directionsPerTixel(), readSeconds));
      } else {
        note(fmt::format("visibility: recomputing, because {}", why));
        computeAndSave();
      }
      return visibility;
    }, settings);
  } else {
    computeAndSave();
    prop = propagate(lf.scene, accel, param, visibility, settings);
  }
  note(fmt::format("propagation: {} iterations, residual {:.2e}, {:.2f} s (first shot {:.2f} s, {} shadow rays)",
                   prop.iterations, prop.residual, prop.seconds, prop.firstShotSeconds, prop.shadowRays));

  lf.charts = param.charts;
  lf.triangleChart = param.triangleChart;
  lf.values = std::move(prop.values);
  lf.stats.visibilitySeconds = reused ? 0.0 : visibility.seconds;
  lf.stats.propagationSeconds = prop.seconds;
  lf.stats.iterations = prop.iterations;
  lf.stats.residual = prop.residual;
  lf.stats.tixels = param.tixelCount;
  lf.stats.values = param.valueCount;
  lf.stats.visibilityRays = reused ? 0 : visibility.rays;
  lf.stats.reusedVisibility = reused;
  lf.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  lf.stats.peakRssBytes = peakRssBytes();
  return lf;
}

}  // namespace pl
