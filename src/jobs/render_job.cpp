// RenderJob (jobs.h): `plenoptic render` as a library call.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <utility>

#include "accel/accel.h"
#include "bake/relight.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "gpu/gpu.h"
#include "image/frame_output.h"
#include "jobs/jobs.h"
#include "plf/plf_file.h"
#include "realtime/realtime.h"
#include "realtime/walkthrough.h"
#include "render/render.h"

namespace pl {

std::string RenderJobStats::toJson() const {
  nlohmann::json json;
  json["command"] = "render";
  json["input"] = input;
  json["output"] = output;
  json["camera"] = camera;
  json["width"] = width;
  json["height"] = height;
  json["spp"] = spp;
  json["samples_per_pixel"] = spp;  // the former name of "spp", still written for one release (CHANGELOG.md)
  json["mirror_depth"] = mirrorDepth;
  json["threads"] = threads;
  json["renderer"] = renderer;
  if (!device.empty()) json["device"] = device;
  if (gpuBytes > 0) {
    json["gpu_bytes"] = gpuBytes;
    json["gpu_light_field_bytes"] = gpuLightFieldBytes;
    json["light_field_bytes"] = lightFieldBytes;
  }
  if (!path.empty()) json["path"] = path;
  json["frames"] = frames;
  json["ms_per_frame_median"] = msPerFrameMedian;
  json["ms_per_frame_min"] = msPerFrameMin;
  json["ms_per_frame_max"] = msPerFrameMax;
  json["fps"] = fps;
  if (gpuMsMedian > 0.0) {
    json["gpu_ms_median"] = gpuMsMedian;
    json["gpu_ms_min"] = gpuMsMin;
    json["gpu_visibility_ms_median"] = gpuVisibilityMsMedian;
    json["gpu_resolve_ms_median"] = gpuResolveMsMedian;
    json["gpu_shading_ms_median"] = gpuShadingMsMedian;
    if (gpuBvhRayShareMedian >= 0.0) json["gpu_bvh_ray_share_median"] = gpuBvhRayShareMedian;
  }
  if (primaryMsMedian > 0.0) {
    json["primary_ms_median"] = primaryMsMedian;
    json["primary_ms_min"] = primaryMsMin;
    json["ratio_to_primary"] = msPerFrameMedian / primaryMsMedian;
  }
  json["load_seconds"] = loadSeconds;
  json["accel_build_seconds"] = accelBuildSeconds;
  json["file_bytes"] = fileBytes;
  if (relitFrames > 0)
    json["relight"] = {{"frames", relitFrames}, {"iterations", relightIterations}, {"seconds", relightSeconds}};
  return json.dump(2) + "\n";
}

RenderJob::RenderJob(RenderJobOptions options) : options_(std::move(options)) {
  const RenderJobOptions& o = options_;
  o.view.checkImageSize("");
  if (o.gpu && o.reference) failUsage("--reference and --renderer gpu cannot be combined");
  if (o.frames < 1 || o.frames > RenderJobOptions::kMaxFrames)
    failUsage("--frames {} is out of range (1..{})", o.frames, RenderJobOptions::kMaxFrames);
  // Every output is checked before the light field is read (core/file_io.h).
  const bool video = !o.output.empty() && isVideoOutput(o.output);
  const bool sequence = !o.output.empty() && isFramePattern(o.output);
  if (o.pathFile.empty() && (video || sequence))
    failUsage("-o {}: a frame pattern or .mp4 output needs a camera path (--path PATH.json)", o.output);
  if (!o.pathFile.empty() && !video && !sequence)
    failUsage("-o {}: a camera path renders many frames: give a frame pattern like frames/%04d.png or an .mp4 file",
              o.output);
  if (!o.pathFile.empty() && o.frames != 1)
    failUsage("--frames cannot be combined with --path (the path sets the frames)");
  if (sequence) {
    // Frames go into the pattern's directory, created if needed.
    const std::filesystem::path parent = std::filesystem::path(o.output).parent_path();
    std::error_code error;
    if (!parent.empty()) std::filesystem::create_directories(parent, error);
    if (error) fail("-o {}: cannot create directory '{}': {}", o.output, parent.string(), error.message());
  }
  if (video) checkOutputPath(o.output, {".mp4"}, "-o");
  else if (!o.output.empty()) ViewSettings::checkImageOutput(o.output, "-o");
  if (!o.statsPath.empty()) checkOutputPath(o.statsPath, {}, "--stats");
  checkDistinctOutputs({{"-o", o.output}, {"--stats", o.statsPath}});
  if (!o.pathFile.empty()) cameraPath_ = loadCameraPath(o.pathFile);
  if (cameraPath_ && cameraPath_->animatesLights() && o.gpu)
    failUsage("--path {}: light keyframes are relit for the CPU renderers; leave out --renderer gpu", o.pathFile);
  if (video && findFfmpeg().empty())
    fail("-o {}: MP4 output needs ffmpeg, which is not installed (not found on PATH); write an image sequence "
         "instead, e.g. -o frames/%04d.png",
         o.output);
}

RenderJobResult RenderJob::run(const std::string& plfPath) const {
  const auto loadStart = SteadyClock::now();
  const LightField lightField = readLightField(plfPath);
  const double loadSeconds = secondsSince(loadStart);
  const std::string visibility = options_.visibilityPath.empty() ? visibilityPathFor(plfPath) : options_.visibilityPath;
  return render(lightField, loadSeconds, std::filesystem::file_size(plfPath), visibility);
}

RenderJobResult RenderJob::run(const LightField& lightField) const {
  return render(lightField, 0.0, 0, options_.visibilityPath);
}

RenderJobResult RenderJob::render(const LightField& lightField, double loadSeconds, uint64_t fileBytes,
                                  const std::string& visibilityPath) const {
  const RenderJobOptions& o = options_;
  const ThreadPool pool(o.threads);
  const ViewSettings& view = o.view;
  // The frame (two for a walk-through: the one being rendered and the one being written); the
  // light field, read by now, is already taken from the available memory.
  view.requireImageMemory(cameraPath_ ? 2 : 1, "render");
  const auto accelStart = SteadyClock::now();
  const Accel accel(lightField.scene);
  const double accelSeconds = secondsSince(accelStart);
  const CameraDesc cameraDesc = view.resolveCamera(lightField.scene);
  const Camera camera(cameraDesc, view.width, view.height, view.vignetting, view.metresPerUnit(lightField.scene));
  const FastRenderer fastRenderer(lightField, accel);
  // The GPU renderer refuses here, before any frame, what it cannot draw yet (gpu.h).
  std::optional<GpuRenderer> gpuRenderer;
  if (o.gpu) {
    gpuRenderer.emplace(lightField);
    gpuRenderer->checkSettings(o.render, camera);
  }

  // Light keyframes: every frame relit from the visibility field (bake/relight.h), then drawn
  // from `relit` by a renderer built for it.
  std::optional<Relighter> relighter;
  std::optional<LightField> relit;
  std::optional<FastRenderer> relitRenderer;
  double relightSeconds = 0.0;
  uint64_t relightIterations = 0;
  if (cameraPath_ && cameraPath_->animatesLights()) {
    const auto start = SteadyClock::now();
    std::vector<Light> lights = lightField.scene.lights;
    cameraPath_->lightsAt(cameraPath_->startTime(), lights);  // the keyframes' errors before any work
    if (visibilityPath.empty())
      fail("{}: the camera path animates lights, which needs the light field's visibility field (.plv)", o.pathFile);
    relighter.emplace(lightField, visibilityPath);
    relit.emplace(relighter->lightField());
    relightSeconds += secondsSince(start);
  }
  auto relightFor = [&](double time) {
    const auto start = SteadyClock::now();
    std::vector<Light> lights = lightField.scene.lights;
    cameraPath_->lightsAt(time, lights);
    for (uint32_t l = 0; l < lights.size(); ++l) relighter->setLight(l, lights[l]);
    relightIterations += relighter->relight().iterations;
    relitRenderer.reset();
    relighter->update(*relit);
    relitRenderer.emplace(*relit, accel);
    relightSeconds += secondsSince(start);
  };

  RenderSettings settings = o.render;
  settings.showProgress = o.frames == 1 && o.reference;
  RenderJobResult result;
  Image& image = result.image;
  std::vector<double> frameMs, primaryMs, gpuMs, gpuVisibilityMs, gpuResolveMs, gpuShadingMs, gpuBvhRayShare;
  // With --stats, the fast renderer's first pass alone (FastRenderer::castPrimaryRays) is
  // timed on every frame's camera after the last frame (interleaving it with the frames would
  // evict their light-field data from the caches and slow them down).
  const bool timePrimary = !o.statsPath.empty() && !o.reference;
  std::vector<Camera> frameCameras;
  // One frame through the chosen renderer; frame time excludes writing files.
  auto renderFrame = [&](const Camera& frameCamera) {
    const auto start = SteadyClock::now();
    if (o.reference) {
      image = renderLightField(relit ? *relit : lightField, accel, frameCamera, settings);
    } else if (gpuRenderer) {
      gpuRenderer->render(frameCamera, settings, image);
      const GpuPassMilliseconds passes = gpuRenderer->lastGpuPasses();
      gpuMs.push_back(passes.total());
      gpuVisibilityMs.push_back(passes.visibility);
      gpuResolveMs.push_back(passes.resolve);
      gpuShadingMs.push_back(passes.shading);
      if (const std::optional<double> share = gpuRenderer->lastBvhRayShare()) gpuBvhRayShare.push_back(*share);
    } else {
      (relitRenderer ? *relitRenderer : fastRenderer).render(frameCamera, settings, image);
    }
    frameMs.push_back(1e3 * secondsSince(start));
    if (timePrimary) frameCameras.push_back(frameCamera);
  };
  int frames = o.frames;
  if (!cameraPath_) {
    for (int frame = 0; frame < o.frames; ++frame) renderFrame(camera);
    if (!o.output.empty()) view.writeImage(o.output, image);
  } else {
    // The walk-through (realtime/walkthrough.h): frame k at time t₀ + k/fps, the path's pose
    // on the resolved camera (which keeps its lens and, without a path fov, its fov).
    WalkthroughOptions walk;
    walk.output = o.output;
    walk.width = view.width;
    walk.height = view.height;
    walk.vignetting = view.vignetting;
    walk.metresPerUnit = view.metresPerUnit(lightField.scene);
    walk.exposureScale = view.exposureScale();
    walk.toneMap = view.toneMapSettings();
    int frame = 0;
    const WalkthroughResult walked =
        renderWalkthrough(*cameraPath_, cameraDesc, walk, [&](const Camera& frameCamera, Image& frameImage) {
          if (relighter) relightFor(cameraPath_->frameTime(frame));
          ++frame;
          renderFrame(frameCamera);
          std::swap(frameImage, image);
        });
    frames = walked.frames;
    image = Image();  // the frames went to their files; the swapped buffer is not the last one
  }

  std::vector<float> depth;
  for (const Camera& frameCamera : frameCameras) {
    const auto start = SteadyClock::now();
    if (gpuRenderer) gpuRenderer->drawVisibility(frameCamera);
    else fastRenderer.castPrimaryRays(frameCamera, settings, depth);
    primaryMs.push_back(1e3 * secondsSince(start));
  }

  RenderJobStats& stats = result.stats;
  stats.input = o.inputName;
  stats.output = o.output;
  stats.camera = cameraDesc.name;
  stats.width = view.width;
  stats.height = view.height;
  stats.spp = effectiveSamplesPerPixel(settings, camera.isThinLens());
  stats.mirrorDepth = effectiveMirrorDepth(settings, lightField.settings.mirrorDepth);
  stats.threads = pool.threads();
  stats.renderer = o.reference ? "reference" : gpuRenderer ? "gpu" : "fast";
  if (gpuRenderer) {
    stats.device = gpuRenderer->deviceName();
    stats.gpuBytes = gpuRenderer->gpuBytes();
    stats.gpuLightFieldBytes = gpuRenderer->lightFieldGpuBytes();
    stats.lightFieldBytes = lightFieldMemoryBytes(lightField);
  }
  stats.path = o.pathFile;
  stats.frames = frames;
  stats.msPerFrameMedian = median(frameMs);
  stats.msPerFrameMin = *std::min_element(frameMs.begin(), frameMs.end());
  stats.msPerFrameMax = *std::max_element(frameMs.begin(), frameMs.end());
  stats.fps = stats.msPerFrameMedian > 0.0 ? 1e3 / stats.msPerFrameMedian : 0.0;
  if (!gpuMs.empty()) {
    stats.gpuMsMedian = median(gpuMs);
    stats.gpuMsMin = *std::min_element(gpuMs.begin(), gpuMs.end());
    stats.gpuVisibilityMsMedian = median(gpuVisibilityMs);
    stats.gpuResolveMsMedian = median(gpuResolveMs);
    stats.gpuShadingMsMedian = median(gpuShadingMs);
    if (!gpuBvhRayShare.empty()) stats.gpuBvhRayShareMedian = median(gpuBvhRayShare);
  }
  if (!primaryMs.empty()) {
    stats.primaryMsMedian = median(primaryMs);
    stats.primaryMsMin = *std::min_element(primaryMs.begin(), primaryMs.end());
  }
  stats.loadSeconds = loadSeconds;
  stats.accelBuildSeconds = accelSeconds;
  stats.fileBytes = fileBytes;
  if (relighter) {
    stats.relitFrames = frames;
    stats.relightIterations = relightIterations;
    stats.relightSeconds = relightSeconds;
  }
  if (!o.statsPath.empty()) writeFileAtomically(o.statsPath, stats.toJson());
  return result;
}

}  // namespace pl
