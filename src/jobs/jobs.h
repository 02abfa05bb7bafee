#pragma once
// Library jobs: one trace, one bake, one render, with everything a front end would otherwise
// have to copy — which camera and settings win (command line over scene file over defaults),
// exposure, tone mapping and image writing, the output checks made before any work, the
// thread count, and the statistics each job reports (toJson gives exactly the --stats JSON the
// docs/user-guide.md documents). The command line (app/) and the Python module (src/python/) are thin front
// ends over these: parse their arguments into the options below → run the job → print.
//
// Every job checks its options and its outputs when constructed (pl::UsageError for a wrong
// request, pl::Error for an unwritable output), before any scene is read; run() does the work
// and writes the outputs its options name (atomically: an interrupted job leaves none half
// written), and returns the result in memory as well. Progress bars follow Progress::setEnabled
// (core/progress.h); Ctrl-C follows core/interrupt.h.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bake/bake.h"
#include "camera/camera.h"
#include "camera/camera_path.h"
#include "camera/exposure.h"
#include "image/image.h"
#include "image/tonemap.h"
#include "lightfield/lightfield.h"
#include "lightfield/render_settings.h"
#include "plf/compression.h"
#include "scene/scene.h"
#include "trace/trace.h"

namespace pl {

class Communicator;

/// How radiance becomes a picture, and from where: image size, camera choice and overrides,
/// exposure, vignetting and tone mapping. Shared by trace, render and view.
struct ViewSettings {
  static constexpr int kMaxImageSide = 16384;  ///< width and height range is 1..kMaxImageSide

  // Image size in pixels.
  int width = 640;
  int height = 480;
  // Camera: `cameraDesc`, else `camera` NAME, else the camera the scene file's settings name, else the scene's
  // first camera, else an automatic camera framing the scene. eye/target/up/fov/aperture/
  // focus distance, when given, override the chosen camera's values.
  std::string camera;
  /// A camera given whole (the Python module's Camera): wins over `camera` and the scene's
  /// cameras, lens included (fNumber 0 = pinhole); the overrides below still apply to it.
  std::optional<CameraDesc> cameraDesc;
  std::vector<float> eye, target, up;  ///< 3 components each when given (scene units)
  float fovDegrees = 0.0f;             ///< vertical; 0 = keep the camera's own
  float fNumberLens = 0.0f;            ///< thin lens f-number (0 = pinhole/keep)
  float focusDistance = 0.0f;          ///< scene units; 0 = keep
  /// Metres per scene unit, sizes the thin lens (camera.h). Unset: 0.001 for the built-in
  /// Cornell box (millimetres), 1 otherwise (glTF is in metres; OBJ/JSON assumed so).
  std::optional<float> sceneUnitMetres;
  // Exposure: compensation EV (scale 2^EV), or f-stop/shutter (s)/ISO (all three).
  std::optional<float> exposureEv;
  std::optional<float> fstop, shutterSeconds, iso;
  bool vignetting = false;
  // Tone mapping for 8-bit output.
  std::string tonemap = "reinhard";  ///< reinhard | linear | clamp
  /// Reinhard key. Unset: 0.18 when no exposure is given (Reinhard's automatic exposure from
  /// the log-average luminance), none when an exposure is given (used as it is).
  std::optional<float> key;
  bool autoKey = false;
  std::optional<float> white;  ///< luminance mapped to 1

  /// The camera these settings select for `scene` (with the overrides applied).
  CameraDesc resolveCamera(const Scene& scene) const;
  /// Metres per scene unit for `scene` (sceneUnitMetres, else the default described above).
  float metresPerUnit(const Scene& scene) const;
  /// Camera(resolveCamera(scene), width, height, vignetting, metresPerUnit(scene)).
  Camera makeCamera(const Scene& scene) const;
  /// The exposure as settings; throws pl::UsageError unless fstop/shutter/iso come all three
  /// or none (photographicExposure, camera/exposure.h).
  ExposureSettings exposureSettings() const;
  /// Multiplier from scene radiance to pixel value (1 when no exposure is given).
  float exposureScale() const;
  /// The tone-mapping settings (default key rule above).
  ToneMapSettings toneMapSettings() const;
  /// Writes radiance (already including vignetting) to path: HDR formats get radiance times
  /// exposureScale(); PNG gets exposure, tone mapping and sRGB encoding. Atomic.
  void writeImage(const std::string& path, const Image& radiance) const;
  /// Fails, before any work is done, unless writeImage can write `path`: an .exr, .hdr, .pfm
  /// or .png name in an existing, writable directory (checkOutputPath, core/file_io.h).
  static void checkImageOutput(const std::string& path, std::string_view option);
  /// Fails, before the images are allocated, unless `frameBuffers` float RGB images of this
  /// size and the buffers of writing one fit in the available memory (requireMemory,
  /// core/memory.h); the message names `what` (e.g. "trace") and --width/--height.
  void requireImageMemory(int frameBuffers, std::string_view what) const;
  /// Fails unless width and height are within 1..kMaxImageSide (`where` starts the message).
  void checkImageSize(std::string_view where) const;
};

// ---------------------------------------------------------------------------------------
// Trace: the reference path tracer (trace/trace.h) from a camera to an image.

struct TraceJobOptions {
  std::string sceneName;     ///< what the stats call the scene (`cornell` or its path)
  std::string output;        ///< image written by run(); empty = none (library use)
  std::string variancePath;  ///< per-pixel variance of the mean (.exr/.hdr/.pfm); empty = none
  std::string statsPath;     ///< the stats as JSON; empty = none
  TraceSettings trace;       ///< spp, max depth, strategy, sampler, seed
  static constexpr int kMaxSpp = 1 << 24;     ///< the most samples per pixel a trace accepts
  static constexpr int kMaxDepth = 100000;     ///< the largest --max-depth cap (or kUnboundedDepth)
  ViewSettings view;
  int threads = 0;  ///< worker threads (0 = all hardware threads)
  // Which values were given by the caller: the scene file's "settings" fill in the others.
  bool sppGiven = true, widthGiven = true, heightGiven = true, cameraGiven = true;
};

/// What `plenoptic trace --stats` writes.
struct TraceJobStats {
  std::string scene, output, camera, strategy, sampler;
  std::string subsurfaceAfterDiffuse;  ///< "walk" or "lambert" (TraceSettings::subsurfaceLambertAfterDiffuse)
  int width = 0, height = 0, spp = 0, maxDepth = 0, threads = 0;
  uint64_t seed = 0;
  TraceStats trace;  ///< timings and counts of the render
  uint64_t triangles = 0, emissiveTriangles = 0;
  std::string toJson() const;  ///< the --stats JSON (2-space indent, trailing newline)
};

struct TraceJobResult {
  Image radiance;  ///< W·sr⁻¹·m⁻², camera weight included, no exposure
  Image variance;  ///< per-pixel variance of the mean (radiance², no exposure)
  TraceJobStats stats;
};

class TraceJob {
 public:
  explicit TraceJob(TraceJobOptions options);  ///< checks the outputs (before any work)
  /// The settings run() uses for `scene`: the caller's, with the scene file's suggestions
  /// where the caller gave none. Throws pl::Error when size or spp end out of range.
  TraceSettings settingsFor(const Scene& scene, ViewSettings& view) const;
  TraceJobResult run(const Scene& scene) const;
  /// Replays one pixel exactly as run() computes it (no outputs written).
  RadianceEstimate runPixel(const Scene& scene, int x, int y, TraceSettings* usedSettings = nullptr,
                            ViewSettings* usedView = nullptr) const;
  const TraceJobOptions& options() const { return options_; }

 private:
  TraceJobOptions options_;
};

// ---------------------------------------------------------------------------------------
// Bake: scene → light field (bake/bake.h), written as .plf (+ its .plv).

struct BakeJobOptions {
  std::string sceneName;       ///< what the stats call the scene
  std::string output;          ///< .plf written by run(); empty = none (library use)
  std::string visibilityPath;  ///< .plv saved / looked for; empty = OUT with .plv (none without OUT)
  std::string statsPath;       ///< empty = none
  std::string preset = "default";
  // Overrides of single preset values (0 = keep the preset's).
  float tixelsAcross = 0.0f;
  uint32_t gatherDirections = 0;
  uint32_t glossyDirRes = 0;  ///< cap on the glossy maps' resolution (BakeSettings::glossyDirRes)
  uint32_t lightSamples = 0;
  float tolerance = 0.0f;
  bool sunMasks = true;  ///< BakeSettings::sunMasks (`--sun-masks`)
  bool punctualHighlights = true;  ///< BakeSettings::punctualHighlights (`--punctual-highlights`)
  bool exactVisibility = false;    ///< BakeSettings::exactVisibility (`--visibility-precision exact`)
  int64_t causticPhotons = -1;  ///< BakeSettings::causticPhotons (`--caustic-photons`); −1 = the preset's, 0 = no caustic pass
  uint32_t subsurfaceWalks = 0;  ///< BakeSettings::subsurfaceWalks (`--subsurface-walks`); 0 = the preset's
  bool reuseVisibility = false;
  /// With reuseVisibility: the previous light field to warm-start from (`--warm-start`,
  /// bake/warm_start.h); empty = the one at `output`, if any. Setting it implies reuseVisibility.
  std::string warmStart;
  /// With reuseVisibility: never warm-start, propagate from zero (`--no-warm-start`): the light
  /// field a full bake would give, bit for bit.
  bool noWarmStart = false;
  /// Ignore what an interrupted bake left to resume from (`--fresh`; BakeOptions::resume).
  bool fresh = false;
  /// The most memory the bake may plan to use (`--max-memory`, parseMemorySize): the memory
  /// guard refuses a bake whose estimate exceeds it, as one that exceeds the available memory;
  /// 0 = the available memory alone.
  uint64_t maxMemory = 0;
  /// `--visibility-memory auto|held|streamed` (BakeOptions::visibilityMemory, parseVisibilityMemory).
  std::string visibilityMemory = "auto";
  std::string compress{valuesCodecName(kDefaultValuesCodec)};  ///< none | lossless | bc1 | hdr (plf/compression.h)
  uint64_t seed = 0;
  int threads = 0;  ///< 0 = all hardware threads
  /// One-line notes (reuse decisions, rates); empty = dropped.
  std::function<void(const std::string&)> log;
  /// The ranks of a distributed bake (distributed/communicator.h); null = one process. Every
  /// rank runs the job; only rank 0 writes the .plf and the stats.
  Communicator* communicator = nullptr;
  /// Receive the parameterisation and the visibility field for relighting (BakeOptions). May be null.
  Parameterisation* keepParameterisation = nullptr;
  VisibilityShard* keepVisibility = nullptr;
};

/// What `plenoptic bake --stats` writes.
struct BakeJobStats {
  std::string scene, output, preset, visibilityFile, compression;
  int threads = 0;
  double seconds = 0.0;  ///< the whole job: loading (path overload), baking and writing
  double loadSeconds = 0.0;  ///< of seconds: loading the scene (path overload; 0 for a given Scene)
  BakeStats bake;
  uint64_t charts = 0, twoSidedCharts = 0, backSideTixels = 0, curvedCharts = 0, curvedTixels = 0, fileBytes = 0;
  uint32_t sunMaskLights = 0;  ///< directional lights with sun masks (LightField::sunMaskLightCount)
  bool warmStart = false;         ///< the previous light field was relit (bake/warm_start.h)
  std::string warmStartReason;    ///< when not: why
  DistributedBakeStats distributed;
  std::string toJson() const;
};

struct BakeJobResult {
  LightField lightField;
  BakeJobStats stats;
};

class BakeJob {
 public:
  explicit BakeJob(BakeJobOptions options);  ///< checks preset, codec and outputs
  /// The bake settings (preset with the overrides and the seed).
  BakeSettings settings() const;
  BakeJobResult run(Scene scene) const;
  BakeJobResult run(const std::string& scenePath) const;  ///< loads the scene, then run(Scene)
  const BakeJobOptions& options() const { return options_; }
  /// The .plv path (explicit, else next to the output, else empty).
  const std::string& visibilityPath() const { return visibilityPath_; }

 private:
  BakeJobResult runFrom(Scene scene, double startedSecondsAgo) const;
  /// Distributed: every rank must name the same scene file (same bytes) and settings; throws
  /// pl::Error on every rank otherwise, before the scene is loaded.
  void checkSameJobOnEveryRank(const std::string& scenePath) const;
  BakeJobOptions options_;
  std::string visibilityPath_;
};

// ---------------------------------------------------------------------------------------
// Render: light field → image (fast renderer, or the reference with `reference`), or a
// walk-through along a camera path → frames / MP4.

struct RenderJobOptions {
  std::string inputName;  ///< what the stats call the light field (its path)
  std::string output;     ///< image, frame pattern (with pathFile) or .mp4; empty = none
  std::string statsPath;  ///< empty = none
  int frames = 1;         ///< render N times (timing); the last frame is written
  static constexpr int kMaxFrames = 100000;
  RenderSettings render;  ///< samples, mirror depth, seed (showProgress is set by run())
  bool reference = false;  ///< the straightforward renderer (render/) instead of the fast one
  /// The GPU renderer (src/gpu, OpenGL 4.5 through headless EGL) instead of the CPU fast one;
  /// refused (pl::Error naming what is missing) for a light field or settings it cannot draw.
  bool gpu = false;
  std::string pathFile;    ///< camera path JSON: a walk-through, one output per frame
  /// The visibility field (.plv) that a path with light keyframes relights from (bake/relight.h);
  /// empty: run(plfPath) takes the .plf's X.plv, run(LightField) refuses such a path.
  std::string visibilityPath;
  ViewSettings view;
  int threads = 0;  ///< 0 = all hardware threads
};

/// What `plenoptic render --stats` writes.
struct RenderJobStats {
  std::string input, output, camera, renderer, path;
  std::string device;  ///< the GPU renderer's GL_RENDERER and GL_VERSION; empty for the CPU ones
  /// The GPU renderer's GPU memory (GpuRenderer::gpuBytes), the light field's part of it
  /// (lightFieldGpuBytes) and the decoded light field and textures it holds there
  /// (lightFieldMemoryBytes); 0 for the CPU renderers.
  uint64_t gpuBytes = 0, gpuLightFieldBytes = 0, lightFieldBytes = 0;
  int width = 0, height = 0, spp = 0, threads = 0, frames = 0;  ///< spp: camera samples per pixel used
  uint32_t mirrorDepth = 0;
  double msPerFrameMedian = 0, msPerFrameMin = 0, msPerFrameMax = 0, fps = 0;
  /// The primary rays alone (FastRenderer::castPrimaryRays; with the GPU renderer its
  /// rasterisation pass, GpuRenderer::drawVisibility) on the same cameras, timed after the
  /// frames when stats are written for the fast or GPU renderer; 0 = not timed.
  double primaryMsMedian = 0, primaryMsMin = 0;
  double gpuMsMedian = 0, gpuMsMin = 0;  ///< the GPU renderer: its own time per frame (GpuRenderer::lastGpuPasses().total())
  /// The GPU renderer's passes' medians (GpuRenderer::lastGpuPasses).
  double gpuVisibilityMsMedian = 0, gpuResolveMsMedian = 0, gpuShadingMsMedian = 0;
  /// The share of a frame's pixels whose camera ray was cast through the GPU's BVH
  /// (GpuRenderer::lastBvhRayShare), median over the frames; -1: not counted (several samples).
  double gpuBvhRayShareMedian = -1;
  double loadSeconds = 0, accelBuildSeconds = 0;
  uint64_t fileBytes = 0;
  /// A path with light keyframes: frames relit, iterations, and the time relighting took
  /// (excluded from the frame times; the Relighter's set-up included).
  int relitFrames = 0;
  uint64_t relightIterations = 0;
  double relightSeconds = 0;
  std::string toJson() const;
};

struct RenderJobResult {
  Image image;  ///< the last frame: radiance, camera weight included, no exposure (empty for a walk-through)
  RenderJobStats stats;
};

class RenderJob {
 public:
  explicit RenderJob(RenderJobOptions options);  ///< checks the outputs (and reads the path)
  RenderJobResult run(const LightField& lightField) const;
  RenderJobResult run(const std::string& plfPath) const;  ///< reads the .plf, then renders
  const RenderJobOptions& options() const { return options_; }

 private:
  RenderJobResult render(const LightField& lightField, double loadSeconds, uint64_t fileBytes,
                         const std::string& visibilityPath) const;
  RenderJobOptions options_;
  std::optional<CameraPath> cameraPath_;
};

}  // namespace pl
