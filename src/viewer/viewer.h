#pragma once
// `plenoptic view`: an interactive walk-through of a baked light field in an SDL2 window,
// rendered by the GPU renderer (gpu/gpu.h) or the CPU fast renderer (realtime/realtime.h).
// SDL is behind viewer.cpp only.
//
// The renderer (ViewerRendererChoice): by default the GPU renderer when a hardware OpenGL 4.5
// core context exists and it draws this light field with these settings; otherwise the CPU
// renderer, with one warning line on stderr saying why (no EGL or GL 4.5 context, a software
// rasteriser such as llvmpipe — slower than the CPU renderer, a shader that does not compile,
// a feature the GPU renderer does not draw yet). Asked for explicitly, the GPU renderer
// refuses with that error instead. Either way a frame is radiance encoded (exposure, tone
// mapping, sRGB) into the window's 8-bit pixels by one rule, DisplayEncoder's (image/display.h):
// the CPU renderer's frame by the CPU; the GPU renderer's on the GPU (GpuRenderer::encodeDisplay:
// the curve resolved on the CPU from the frame's subsample, each pixel's word computed there).
// The GPU renderer draws in the window's own OpenGL 4.5 core context where SDL's video driver
// gives one (GpuContext::Current), and presents the frame and the HUD there
// (GpuRenderer::present): nothing of the frame comes back to the CPU. Elsewhere (SDL's dummy
// and offscreen drivers have no OpenGL) it draws in its headless EGL context, its 4 bytes per
// pixel are read back and SDL's software renderer blits them (not SDL's accelerated one: no
// second OpenGL context may compete for the thread). The CPU renderer's frames are blitted by
// SDL's renderer. Screenshots are the radiance read back and written as `plenoptic render`
// writes it; --window-shot writes what the window shows, read back from it.
//
// Frame rate: with the CPU renderer, while the camera moves each frame is rendered at the
// reduced internal resolution RenderScaleController (render_scale.h) picks for the frame-rate
// target and upscaled (bilinear) to the window (the GPU renderer draws every frame at full
// resolution). While the live relighting works, the cores are shared by core_share.h (Split):
// the CPU renderer on the pool's threads − 1 at kRelightTargetFps, the relighter on one core. When the camera stops, the frame is rendered at full resolution, then (both
// renderers) refined with batches of jittered samples averaged up to kRefinedSamples per
// pixel (the GPU renderer's summed and shown on the GPU: GpuRenderer::accumulate); then the
// loop waits for input. Screenshots are always the full-resolution frame at the --spp samples (what
// `render` writes), rendered for the purpose when the window shows a scaled or refined one.
//
// Controls:
//   W/S, A/D, Q/E   move forward/back, left/right, down/up (E up, Q down, along the world up)
//   Shift / Ctrl    4× faster / 4× slower
//   mouse drag      look around (left button held)
//   + / −           exposure ±0.5 EV          T   cycle tone mapping (reinhard → linear → clamp)
//   F12             screenshot (PNG: exposure + tone mapping as `plenoptic render` writes it)
//   P or R          start/stop recording the flown path (saved as camera-path JSON)
//   Esc             quit (a recording in progress is saved first)
// Relighting (when the light field's visibility field is at hand; live_relight.h): Tab selects
// a light or the emitters, O switches it, [ / ] dims / brightens it, C recolours it, J/L and
// I/K turn the sun, M selects a material and , / . darken / lighten its albedo; the light
// field re-propagates in the background and the view shows each iteration.
//   H               show or hide the relighting lines of the HUD
// The window is resizable; the image is rendered at the window's size. The HUD shows fps,
// frame time (render + display), the renderer, the render scale and samples per pixel, with
// the GPU renderer the GPU's own time for the frame pass by pass, camera position, exposure and
// tone mapping.
//
// Headless use (tests, CI): `frames` > 0 runs that many frames of the loop and quits;
// `screenshotPath` is then written from the last frame's view; `path` drives the camera (frame k at the path's time
// t₀ + k/fps, independent of the wall clock). Works under SDL_VIDEODRIVER=dummy (no window
// on screen, SDL's software framebuffer) or offscreen, or xvfb-run.
#include <optional>
#include <string>
#include <vector>

#include "camera/camera_path.h"
#include "camera/exposure.h"
#include "image/tonemap.h"
#include "lightfield/lightfield.h"
#include "lightfield/render_settings.h"
#include "realtime/walkthrough.h"

namespace pl {

class Accel;

/// Which light-field renderer the viewer draws with (`view --renderer`).
enum class ViewerRendererChoice {
  Automatic,  ///< the GPU one where it can (see the top of this file), else the CPU one
  Gpu,        ///< the GPU one, or an error saying why not
  Cpu,        ///< the CPU fast renderer
};

struct ViewerOptions {
  int width = 1024, height = 768;    ///< initial window (and image) size
  CameraDesc camera;                 ///< starting camera
  bool vignetting = false;
  float metresPerUnit = 1.0f;        ///< scene unit in metres (sizes a thin lens; camera.h)
  float exposureScale = 1.0f;        ///< radiance → pixel value at the start (exposure.h)
  ToneMapSettings toneMap;           ///< at the start; T changes the operator
  RenderSettings render;             ///< samples, mirror depth, seed
  ViewerRendererChoice renderer = ViewerRendererChoice::Automatic;
  double targetFps = 30.0;           ///< CPU renderer: frame rate held while moving; 0 = always full resolution
  /// With the GPU renderer in the window's OpenGL context: swap at the display's vertical sync
  /// (adaptive where the driver offers it: a late frame is shown at once), or as soon as a
  /// frame is drawn (the frame rate is then the renderer's, as benchmarks want).
  bool vsync = true;
  static constexpr int kRefinedSamples = 16;  ///< samples per pixel a still view is refined to
  int frames = 0;                    ///< > 0: quit after this many frames
  std::string screenshotPath;        ///< written after the last frame (.png or .exr/.hdr/.pfm)
  /// The last frame's window as it shows it, HUD included, written as PNG on exit (frames or
  /// path needed): the pixels read back from the window (its OpenGL back buffer, or SDL's).
  std::string windowShotPath;
  std::optional<CameraPath> path;    ///< scripted camera (overrides keys and mouse)
  std::string recordPath = "walk-path.json";     ///< where P/R saves the flown path
  std::string screenshotPattern = "screenshot-%04d.png";  ///< F12 (frame pattern, numbered from 0)
  float speed = 0.0f;                ///< scene units per second; 0 = a quarter of the scene diagonal
  double recordInterval = 0.25;      ///< seconds between recorded keyframes
  std::string title = "plenoptic";
  /// The .plv the relighting keys re-propagate from; empty = no relighting (live_relight.h).
  std::string visibilityPath;
  /// Relighting keys pressed at the first frame (headless runs and benchmarks): the characters
  /// of the keys above ("\t" for Tab), e.g. "JJJ]".
  std::string relightKeys;
};

/// What a viewer session did (for messages and tests).
struct ViewerResult {
  int frames = 0;
  double msPerFrameMedian = 0.0;  ///< render + display + present
  /// The renderer alone (frames that rendered); with the GPU renderer until its frame's pixels
  /// are read back (its display pass included), the GPU working apart from the CPU until then.
  double renderMsMedian = 0.0;
  /// With the GPU renderer, the GPU's own time for a frame (its passes by timestamp queries,
  /// GpuRenderer::lastGpuPasses; the read-back and display pass excluded); 0 otherwise.
  double gpuMsMedian = 0.0;
  std::string renderer;           ///< "gpu (DEVICE)" or "cpu"
  std::string device;             ///< with the GPU renderer, DEVICE: GpuRenderer::deviceName
  std::string fallback;           ///< why the CPU renderer was taken in Automatic mode; empty otherwise
  /// How frames reached the window: "opengl" (the GPU renderer drew them in the window's own
  /// OpenGL context) or "sdl" (blitted by SDL's renderer: the CPU renderer's, or the GPU
  /// renderer's read back from its headless context).
  std::string presentation;
  bool vsync = false;  ///< the window's swaps waited for the vertical sync (presentation "opengl" only)
  /// With relighting: frames drawn while the propagation ran, their median time, and the
  /// last relight's times and state (seconds; live_relight.h RelightStatus).
  int relightFrames = 0;
  double relightMsPerFrameMedian = 0.0;
  double relightFirstFrameSeconds = 0.0, relightSeconds = 0.0;
  double relightSunMaskSeconds = 0.0, relightFirstShotSeconds = 0.0;  ///< of relightFirstFrameSeconds
  uint32_t relightIterations = 0;
  bool relightConverged = false;
  std::string relightMessage;
};

/// Opens the window and runs until Esc/close, or for options.frames frames. Throws pl::Error
/// when SDL cannot open a window (the message names the video driver and suggests
/// SDL_VIDEODRIVER=dummy or xvfb-run), for bad options, and when the GPU renderer was asked
/// for and cannot draw (gpu/gpu.h's message).
ViewerResult runViewer(const LightField& lightField, const Accel& accel, const ViewerOptions& options);

/// True when SDL can open a window on a real display here (x11, wayland, ...; SDL's headless
/// "dummy" and "offscreen" drivers do not count). `make demo` uses it to choose between the
/// viewer and a rendered walk-through.
bool displayAvailable();

/// The walk-through step of `plenoptic demo` / `make demo`: with a display (displayAvailable)
/// it opens the viewer on `lightField` from `camera` until Esc; otherwise it renders
/// orbitPath(camera) (4 s at 30 fps, 640×480) with the fast renderer to
/// outputDirectory/frames/%04d.png and, when ffmpeg is installed, outputDirectory/walk.mp4.
/// Returns one line per thing done, for the demo to print.
std::vector<std::string> runDemoWalkthrough(const LightField& lightField, const Accel& accel, const CameraDesc& camera,
                                            float metresPerUnit, const std::string& outputDirectory);

}  // namespace pl
