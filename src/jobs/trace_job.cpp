// TraceJob (jobs.h): `plenoptic trace` as a library call.
#include <nlohmann/json.hpp>

#include <utility>

#include "accel/accel.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/parallel.h"
#include "jobs/jobs.h"

namespace pl {
std::string TraceJobStats::toJson() const {
  nlohmann::json json;
  json["command"] = "trace";
  json["scene"] = scene;
  json["output"] = output;
  json["camera"] = camera;
  json["width"] = width;
  json["height"] = height;
  json["spp"] = spp;
  json["max_depth"] = maxDepth;
  json["strategy"] = strategy;
  json["sampler"] = sampler;
  json["subsurface_after_diffuse"] = subsurfaceAfterDiffuse;
  json["seed"] = seed;
  json["threads"] = threads;
  json["seconds"] = trace.seconds;
  json["paths"] = trace.paths;
  json["paths_per_second"] = trace.pathsPerSecond();
  json["rays"] = trace.rays;
  json["rays_per_second"] = trace.raysPerSecond();
  json["nan_samples"] = trace.nanSamples;
  json["triangles"] = triangles;
  json["emissive_triangles"] = emissiveTriangles;
  return json.dump(2) + "\n";
}

TraceJob::TraceJob(TraceJobOptions options) : options_(std::move(options)) {
  // Every output is checked before the scene is even loaded (core/file_io.h).
  if (!options_.output.empty()) ViewSettings::checkImageOutput(options_.output, "-o");
  if (!options_.variancePath.empty()) checkOutputPath(options_.variancePath, kHdrImageExtensions, "--variance");
  if (!options_.statsPath.empty()) checkOutputPath(options_.statsPath, {}, "--stats");
  checkDistinctOutputs(
      {{"-o", options_.output}, {"--variance", options_.variancePath}, {"--stats", options_.statsPath}});
}

TraceSettings TraceJob::settingsFor(const Scene& scene, ViewSettings& view) const {
  // The scene file's suggested settings, where the caller is silent.
  TraceSettings settings = options_.trace;
  view = options_.view;
  const SceneSettings& suggested = scene.settings;
  if (!options_.widthGiven && suggested.width) view.width = *suggested.width;
  if (!options_.heightGiven && suggested.height) view.height = *suggested.height;
  if (!options_.cameraGiven && suggested.camera) view.camera = *suggested.camera;
  if (!options_.sppGiven && suggested.spp) settings.spp = *suggested.spp;
  view.checkImageSize(options_.sceneName + ": ");
  if (settings.spp < 1 || settings.spp > TraceJobOptions::kMaxSpp)
    fail("{}: {} samples per pixel is out of range (1..{})", options_.sceneName, settings.spp, TraceJobOptions::kMaxSpp);
  if (settings.maxDepth != kUnboundedDepth && (settings.maxDepth < 0 || settings.maxDepth > TraceJobOptions::kMaxDepth))
    failUsage("{}: maximum depth {} is out of range (0..{}, or {} for no cap)", options_.sceneName, settings.maxDepth,
              TraceJobOptions::kMaxDepth, kUnboundedDepth);
  return settings;
}

RadianceEstimate TraceJob::runPixel(const Scene& scene, int x, int y, TraceSettings* usedSettings,
                                    ViewSettings* usedView) const {
  const ThreadPool pool(options_.threads);
  ViewSettings view;
  const TraceSettings settings = settingsFor(scene, view);
  const Accel accel(scene);
  const PathTracer tracer(scene, accel);
  const RadianceEstimate estimate = tracer.renderPixel(view.makeCamera(scene), settings, x, y);
  if (usedSettings) *usedSettings = settings;
  if (usedView) *usedView = view;
  return estimate;
}

TraceJobResult TraceJob::run(const Scene& scene) const {
  const ThreadPool pool(options_.threads);
  ViewSettings view;
  const TraceSettings settings = settingsFor(scene, view);
  // The radiance and variance images.
  view.requireImageMemory(2, "trace");

  const Accel accel(scene);
  const PathTracer tracer(scene, accel);
  const CameraDesc cameraDesc = view.resolveCamera(scene);
  const Camera camera = view.makeCamera(scene);
  TraceResult traced = tracer.render(camera, settings);

  if (!options_.output.empty()) view.writeImage(options_.output, traced.radiance);
  if (!options_.variancePath.empty()) writeHdrImage(options_.variancePath, traced.variance);

  TraceJobResult result;
  TraceJobStats& stats = result.stats;
  stats.scene = options_.sceneName;
  stats.output = options_.output;
  stats.camera = cameraDesc.name;
  stats.width = view.width;
  stats.height = view.height;
  stats.spp = settings.spp;
  stats.maxDepth = settings.maxDepth;
  stats.strategy = strategyName(settings.strategy);
  stats.sampler = samplerName(settings.sampler);
  stats.subsurfaceAfterDiffuse = settings.subsurfaceLambertAfterDiffuse ? "lambert" : "walk";
  stats.seed = settings.seed;
  stats.threads = pool.threads();
  stats.trace = traced.stats;
  stats.triangles = scene.triangleCount();
  stats.emissiveTriangles = tracer.emissiveTriangleCount();
  if (!options_.statsPath.empty()) writeFileAtomically(options_.statsPath, stats.toJson());
  result.radiance = std::move(traced.radiance);
  result.variance = std::move(traced.variance);
  return result;
}

}  // namespace pl
