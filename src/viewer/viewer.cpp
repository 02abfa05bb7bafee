// The interactive viewer (see viewer.h): the one file of plenoptic that includes SDL.
#include "viewer/viewer.h"

#include <SDL.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/timing.h"
#include "image/display.h"
#include "image/frame_output.h"
#include "image/image.h"
#include "realtime/realtime.h"
#include "viewer/fly_camera.h"
#include "viewer/hud_text.h"

namespace pl {
namespace {

using Clock = std::chrono::steady_clock;

constexpr float kExposureStepEv = 0.5f;
constexpr float kFastFactor = 4.0f, kSlowFactor = 0.25f;
constexpr float kRadiansPerPixel = 0.004f;  ///< mouse look sensitivity
constexpr int kHudScale = 2;
constexpr size_t kTimingWindow = 60;  ///< frames averaged for the HUD's fps

/// Owns SDL's window, renderer and streaming texture; releases them in reverse order.
class Window {
 public:
  Window(const std::string& title, int width, int height) {
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
      const char* driver = std::getenv("SDL_VIDEODRIVER");
      fail("view: cannot initialise SDL video{}: {} (no display? run under xvfb-run, or set SDL_VIDEODRIVER=dummy "
           "for a headless run)",
           driver ? fmt::format(" (SDL_VIDEODRIVER={})", driver) : std::string(), SDL_GetError());
    }
    window_ = SDL_CreateWindow(title.c_str(), SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, width, height,
                               SDL_WINDOW_RESIZABLE);
    if (!window_) fail("view: cannot open a {}x{} window: {}", width, height, SDL_GetError());
    renderer_ = SDL_CreateRenderer(window_, -1, SDL_RENDERER_ACCELERATED);
    if (!renderer_) renderer_ = SDL_CreateRenderer(window_, -1, SDL_RENDERER_SOFTWARE);
    if (!renderer_) fail("view: cannot create an SDL renderer: {}", SDL_GetError());
  }
  ~Window() {
    if (texture_) SDL_DestroyTexture(texture_);
    if (renderer_) SDL_DestroyRenderer(renderer_);
    if (window_) SDL_DestroyWindow(window_);
    SDL_Quit();
  }
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  /// The size to render at: the window's drawable size.
  void outputSize(int& width, int& height) const {
    if (SDL_GetRendererOutputSize(renderer_, &width, &height) != 0 || width < 1 || height < 1)
      SDL_GetWindowSize(window_, &width, &height);
  }
  /// A streaming texture of the given size (re-created after a resize).
  SDL_Texture* texture(int width, int height) {
    if (texture_ && width == textureWidth_ && height == textureHeight_) return texture_;
    if (texture_) SDL_DestroyTexture(texture_);
    texture_ = SDL_CreateTexture(renderer_, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_STREAMING, width, height);
    if (!texture_) fail("view: cannot create a {}x{} texture: {}", width, height, SDL_GetError());
    textureWidth_ = width;
    textureHeight_ = height;
    return texture_;
  }
  void present() {
    SDL_RenderClear(renderer_);
    SDL_RenderCopy(renderer_, texture_, nullptr, nullptr);
    SDL_RenderPresent(renderer_);
  }

 private:
  SDL_Window* window_ = nullptr;
  SDL_Renderer* renderer_ = nullptr;
  SDL_Texture* texture_ = nullptr;
  int textureWidth_ = 0, textureHeight_ = 0;
};

ToneMapOperator nextOperator(ToneMapOperator op) {
  switch (op) {
    case ToneMapOperator::Reinhard: return ToneMapOperator::Linear;
    case ToneMapOperator::Linear: return ToneMapOperator::Clamp;
    case ToneMapOperator::Clamp: return ToneMapOperator::Reinhard;
  }
  return ToneMapOperator::Reinhard;
}

}  // namespace

bool displayAvailable() {
  // No X11 or Wayland display in the environment: nothing to open a window on. Deciding this
  // before SDL_Init keeps SDL's own complaints (e.g. about XDG_RUNTIME_DIR) off the terminal.
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!x11 || !*x11) && (!wayland || !*wayland)) return false;
  if (SDL_Init(SDL_INIT_VIDEO) != 0) return false;
  // SDL falls back to its headless drivers when no display is reachable: those do not count.
  const char* driver = SDL_GetCurrentVideoDriver();
  const std::string name = driver ? driver : "";
  bool ok = !name.empty() && name != "dummy" && name != "offscreen";
  if (ok) {
    SDL_Window* window = SDL_CreateWindow("plenoptic", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, 16, 16, SDL_WINDOW_HIDDEN);
    ok = window != nullptr;
    if (window) SDL_DestroyWindow(window);
  }
  SDL_Quit();
  return ok;
}

ViewerResult runViewer(const LightField& lightField, const Accel& accel, const ViewerOptions& options) {
  if (options.width < 1 || options.height < 1) fail("view: window size {}x{} is invalid", options.width, options.height);
  if (options.frames < 0) fail("view: --frames must be ≥ 0, got {}", options.frames);
  if (!options.screenshotPath.empty() && options.frames == 0 && !options.path)
    fail("view: --screenshot needs --frames N or --path (it is written after the last frame)");
  isFramePattern(options.screenshotPattern, "screenshot pattern");  // validates it

  Vec3 lo, hi;
  lightField.scene.bounds(lo, hi);
  const float speed = options.speed > 0.0f ? options.speed : 0.25f * std::max(glm::length(hi - lo), 1e-6f);
  FlyCamera fly(options.camera, speed);
  const FastRenderer renderer(lightField, accel);
  DisplayEncoder display;
  Window window(options.title, options.width, options.height);

  float exposureEv = 0.0f;  // the +/− offset on top of options.exposureScale
  ToneMapSettings toneMap = options.toneMap;
  const int totalFrames = options.frames > 0 ? options.frames : options.path ? options.path->frameCount() : 0;
  Image radiance;
  std::vector<double> frameMs, renderMs;
  std::vector<double> recentMs;
  int screenshots = 0;
  bool dragging = false, quit = false;
  PathRecorder recorder(options.recordInterval);
  const Clock::time_point sessionStart = Clock::now();
  auto secondsAt = [&](Clock::time_point t) { return std::chrono::duration<double>(t - sessionStart).count(); };
  std::string message;  // a transient HUD line (saved files)
  Clock::time_point messageUntil;
  auto stopRecording = [&](Clock::time_point now) {
    const CameraPath path = recorder.stop(secondsAt(now), fly.desc());
    saveCameraPath(options.recordPath, path);
    message = fmt::format("saved {} keyframes to {}", path.keyframes.size(), options.recordPath);
    fmt::print("{}\n", message);
    messageUntil = Clock::now() + std::chrono::seconds(3);
  };

  Clock::time_point previous = Clock::now();
  for (int frame = 0; !quit && (totalFrames == 0 || frame < totalFrames); ++frame) {
    const Clock::time_point frameStart = Clock::now();
    const float dt = std::min(float(std::chrono::duration<double>(frameStart - previous).count()), 0.25f);
    previous = frameStart;

    SDL_Event event;
    while (SDL_PollEvent(&event)) {
      switch (event.type) {
        case SDL_QUIT: quit = true; break;
        case SDL_MOUSEBUTTONDOWN:
          if (event.button.button == SDL_BUTTON_LEFT) dragging = true;
          break;
        case SDL_MOUSEBUTTONUP:
          if (event.button.button == SDL_BUTTON_LEFT) dragging = false;
          break;
        case SDL_MOUSEMOTION:
          if (dragging && !options.path)
            fly.turn(-float(event.motion.xrel) * kRadiansPerPixel, -float(event.motion.yrel) * kRadiansPerPixel);
          break;
        case SDL_KEYDOWN: {
          const SDL_Keycode key = event.key.keysym.sym;
          if (key == SDLK_ESCAPE) quit = true;
          if (key == SDLK_PLUS || key == SDLK_EQUALS || key == SDLK_KP_PLUS) exposureEv += kExposureStepEv;
          if (key == SDLK_MINUS || key == SDLK_KP_MINUS) exposureEv -= kExposureStepEv;
          if (key == SDLK_t) toneMap.op = nextOperator(toneMap.op);
          if (key == SDLK_F12 && !radiance.empty()) {
            const std::string path = formatFramePath(options.screenshotPattern, screenshots++);
            writeFrame(path, radiance, options.exposureScale * std::exp2(exposureEv), toneMap);
            message = "wrote " + path;
            fmt::print("{}\n", message);
            messageUntil = Clock::now() + std::chrono::seconds(3);
          }
          if ((key == SDLK_p || key == SDLK_r) && event.key.repeat == 0) {
            if (recorder.recording()) {
              stopRecording(frameStart);
            } else {
              recorder.start(secondsAt(frameStart), fly.desc());
            }
          }
          break;
        }
        default: break;
      }
    }

    // Camera: the scripted path, or keys (held state) for movement.
    if (options.path) {
      const CameraPose pose = options.path->at(options.path->frameTime(frame));
      fly = FlyCamera(applyPose(options.camera, pose), speed);
    } else {
      const Uint8* keys = SDL_GetKeyboardState(nullptr);
      const Vec3 direction(float(keys[SDL_SCANCODE_D]) - float(keys[SDL_SCANCODE_A]),
                           float(keys[SDL_SCANCODE_E]) - float(keys[SDL_SCANCODE_Q]),
                           float(keys[SDL_SCANCODE_W]) - float(keys[SDL_SCANCODE_S]));
      if (direction != Vec3(0.0f)) {
        const SDL_Keymod mod = SDL_GetModState();
        const float factor = (mod & KMOD_SHIFT) ? kFastFactor : (mod & KMOD_CTRL) ? kSlowFactor : 1.0f;
        fly.move(direction, dt, factor);
      }
    }
    recorder.sample(secondsAt(frameStart), fly.desc());

    int width = 0, height = 0;
    window.outputSize(width, height);
    const Camera camera(fly.desc(), width, height, options.vignetting, options.metresPerUnit);
    const Clock::time_point renderStart = Clock::now();
    renderer.render(camera, options.render, radiance);
    renderMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - renderStart).count());

    SDL_Texture* texture = window.texture(width, height);
    void* locked = nullptr;
    int pitch = 0;
    if (SDL_LockTexture(texture, nullptr, &locked, &pitch) != 0) fail("view: cannot lock the texture: {}", SDL_GetError());
    uint32_t* pixels = static_cast<uint32_t*>(locked);
    const float exposureScale = options.exposureScale * std::exp2(exposureEv);
    display.encode(radiance, exposureScale, toneMap, pixels, pitch);

    // HUD: fps over the last frames, frame time, camera, exposure, tone mapping.
    const double meanMs = recentMs.empty() ? 0.0 : [&] {
      double sum = 0.0;
      for (double ms : recentMs) sum += ms;
      return sum / double(recentMs.size());
    }();
    const Vec3 eye = fly.eye();
    std::vector<std::string> lines = {
        fmt::format("{:.1f} FPS  {:.2f} MS/FRAME  (RENDER {:.2f} MS)  {}X{}", meanMs > 0 ? 1e3 / meanMs : 0.0, meanMs,
                    renderMs.back(), width, height),
        fmt::format("EYE {:.3g} {:.3g} {:.3g}", eye.x, eye.y, eye.z),
        fmt::format("EXPOSURE {:+.1f} EV  TONEMAP {}{}", exposureEv, toneMapOperatorName(toneMap.op),
                    recorder.recording() ? "  [REC]" : ""),
    };
    if (!message.empty() && frameStart < messageUntil) lines.push_back(message);
    int hudWidth = 0;
    for (const std::string& line : lines) hudWidth = std::max(hudWidth, hudTextWidth(line, kHudScale));
    const int hudHeight = int(lines.size()) * kLineAdvance * kHudScale + 6;
    darkenRect(pixels, pitch, width, height, 0, 0, hudWidth + 12, hudHeight);
    for (size_t i = 0; i < lines.size(); ++i)
      drawHudText(pixels, pitch, width, height, 6, 4 + int(i) * kLineAdvance * kHudScale, lines[i], kHudScale,
                  0xFFFFFFFFu);
    SDL_UnlockTexture(texture);
    window.present();

    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count();
    frameMs.push_back(ms);
    recentMs.push_back(ms);
    if (recentMs.size() > kTimingWindow) recentMs.erase(recentMs.begin());
  }
  if (recorder.recording()) stopRecording(Clock::now());
  if (!options.screenshotPath.empty() && !radiance.empty())
    writeFrame(options.screenshotPath, radiance, options.exposureScale * std::exp2(exposureEv), toneMap);

  ViewerResult result;
  result.frames = int(frameMs.size());
  result.msPerFrameMedian = median(frameMs);
  result.renderMsMedian = median(renderMs);
  return result;
}

std::vector<std::string> runDemoWalkthrough(const LightField& lightField, const Accel& accel, const CameraDesc& camera,
                                            float metresPerUnit, const std::string& outputDirectory) {
  std::vector<std::string> done;
  if (displayAvailable()) {
    ViewerOptions options;
    options.width = 1024;
    options.height = 768;
    options.camera = camera;
    options.metresPerUnit = metresPerUnit;
    options.recordPath = outputDirectory + "/walk-path.json";
    options.screenshotPattern = outputDirectory + "/screenshot-%04d.png";
    options.title = "plenoptic demo (W/A/S/D/Q/E move, drag to look, Esc quits)";
    const ViewerResult result = runViewer(lightField, accel, options);
    done.push_back(fmt::format("viewer: {} frames, median {:.2f} ms/frame", result.frames, result.msPerFrameMedian));
    return done;
  }
  const FastRenderer renderer(lightField, accel);
  const CameraPath path = orbitPath(camera);
  WalkthroughOptions options;
  options.width = 640;
  options.height = 480;
  options.metresPerUnit = metresPerUnit;
  options.output = outputDirectory + "/frames/%04d.png";
  const WalkthroughResult frames = renderWalkthrough(path, camera, options, renderer, RenderSettings{});
  done.push_back(fmt::format("no display: rendered a {}-frame walk-through to {} (median {:.2f} ms/frame = {:.0f} fps)",
                             frames.frames, options.output, frames.msPerFrameMedian, frames.fps));
  if (!findFfmpeg().empty()) {
    options.output = outputDirectory + "/walk.mp4";
    options.showProgress = false;
    renderWalkthrough(path, camera, options, renderer, RenderSettings{});
    done.push_back("video: " + options.output);
  } else {
    done.push_back("ffmpeg is not installed: no MP4 (the PNG frames are there)");
  }
  return done;
}

}  // namespace pl
