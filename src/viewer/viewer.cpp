// The interactive viewer (see viewer.h): the one file of plenoptic that includes SDL.
#include "viewer/viewer.h"

#include <SDL.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cctype>
#include <cstdlib>
#include <memory>
#include <optional>
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
#include "viewer/live_relight.h"

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

/// The relighting key of an SDL key (viewer.h), if it is one.
std::optional<RelightKey> relightKeyOf(SDL_Keycode code) {
  switch (code) {
    case SDLK_TAB: return RelightKey::NextSource;
    case SDLK_o: return RelightKey::ToggleSource;
    case SDLK_LEFTBRACKET: return RelightKey::Dimmer;
    case SDLK_RIGHTBRACKET: return RelightKey::Brighter;
    case SDLK_c: return RelightKey::NextColour;
    case SDLK_j: return RelightKey::SunLeft;
    case SDLK_l: return RelightKey::SunRight;
    case SDLK_i: return RelightKey::SunUp;
    case SDLK_k: return RelightKey::SunDown;
    case SDLK_m: return RelightKey::NextMaterial;
    case SDLK_COMMA: return RelightKey::Darker;
    case SDLK_PERIOD: return RelightKey::Lighter;
    default: return std::nullopt;
  }
}

/// The relighting key of a character of ViewerOptions::relightKeys ('\t' = Tab; any case).
std::optional<RelightKey> relightKeyOfChar(char c) {
  return relightKeyOf(c == '\t' ? SDLK_TAB : SDL_Keycode(std::tolower(static_cast<unsigned char>(c))));
}

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

namespace {

/// Refuses options the loop cannot honour, before the window opens.
void checkViewerOptions(const ViewerOptions& options) {
  if (options.width < 1 || options.height < 1) fail("view: window size {}x{} is invalid", options.width, options.height);
  if (options.frames < 0) fail("view: --frames must be ≥ 0, got {}", options.frames);
  if (!options.screenshotPath.empty() && options.frames == 0 && !options.path && options.relightKeys.empty())
    fail("view: --screenshot needs --frames N or --path (it is written after the last frame)");
  isFramePattern(options.screenshotPattern, "screenshot pattern");  // validates it
  for (char c : options.relightKeys)
    if (!relightKeyOfChar(c))
      fail("view: '{}' in the relighting keys is not one (Tab O [ ] C J L I K M , .)", c);
  if (!options.relightKeys.empty() && options.visibilityPath.empty())
    fail("view: relighting keys need the light field's visibility field (.plv)");
}

/// Scene units per second: the option, or a quarter of the scene's diagonal.
float flySpeed(const Scene& scene, const ViewerOptions& options) {
  if (options.speed > 0.0f) return options.speed;
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  return 0.25f * std::max(glm::length(hi - lo), 1e-6f);
}

/// One viewer session: what the walk-through loop carries from frame to frame, and the steps
/// of a frame — input, camera, render and display, HUD — in the order runViewer calls them.
class ViewerSession {
 public:
  ViewerSession(const LightField& lightField, const Accel& accel, const ViewerOptions& options)
      : options_(options),
        speed_(flySpeed(lightField.scene, options)),
        fly_(options.camera, speed_),
        renderer_(lightField, accel),
        window_(options.title, options.width, options.height),
        toneMap_(options.toneMap),
        recorder_(options.recordInterval),
        start_(Clock::now()) {
    if (!options.visibilityPath.empty()) {
      live_ = std::make_unique<LiveRelight>(lightField, accel, options.visibilityPath);
      for (char c : options.relightKeys)
        live_->press(*relightKeyOfChar(c));
    }
  }

  bool quit() const { return quit_; }
  /// Whether the scripted relighting keys (ViewerOptions::relightKeys) are done: converged,
  /// or refused.
  bool relightDone() const {
    if (!live_) return true;
    const RelightStatus status = live_->status();
    return !status.message.empty() || (status.ready && !status.running && status.converged && live_->showsNewest());
  }

  /// SDL's queued events: quit, mouse look, exposure, tone mapping, screenshots, recording.
  void handleEvents(Clock::time_point frameStart) {
    SDL_Event event;
    while (SDL_PollEvent(&event)) {
      switch (event.type) {
        case SDL_QUIT: quit_ = true; break;
        case SDL_MOUSEBUTTONDOWN:
          if (event.button.button == SDL_BUTTON_LEFT) dragging_ = true;
          break;
        case SDL_MOUSEBUTTONUP:
          if (event.button.button == SDL_BUTTON_LEFT) dragging_ = false;
          break;
        case SDL_MOUSEMOTION:
          if (dragging_ && !options_.path)
            fly_.turn(-float(event.motion.xrel) * kRadiansPerPixel, -float(event.motion.yrel) * kRadiansPerPixel);
          break;
        case SDL_KEYDOWN: handleKey(event.key, frameStart); break;
        default: break;
      }
    }
  }

  /// The camera of frame `frame`: the scripted path's pose, or the held movement keys over dt
  /// seconds; the recorder (when recording) samples it.
  void moveCamera(int frame, float dt, Clock::time_point frameStart) {
    if (options_.path) {
      const CameraPose pose = options_.path->at(options_.path->frameTime(frame));
      fly_ = FlyCamera(applyPose(options_.camera, pose), speed_);
    } else {
      const Uint8* keys = SDL_GetKeyboardState(nullptr);
      const Vec3 direction(float(keys[SDL_SCANCODE_D]) - float(keys[SDL_SCANCODE_A]),
                           float(keys[SDL_SCANCODE_E]) - float(keys[SDL_SCANCODE_Q]),
                           float(keys[SDL_SCANCODE_W]) - float(keys[SDL_SCANCODE_S]));
      if (direction != Vec3(0.0f)) {
        const SDL_Keymod mod = SDL_GetModState();
        const float factor = (mod & KMOD_SHIFT) ? kFastFactor : (mod & KMOD_CTRL) ? kSlowFactor : 1.0f;
        fly_.move(direction, dt, factor);
      }
    }
    recorder_.sample(secondsAt(frameStart), fly_.desc());
  }

  /// Renders the frame at the window's size, encodes it into the window's texture with the
  /// HUD on top, and presents it.
  void renderAndPresent(Clock::time_point frameStart) {
    int width = 0, height = 0;
    window_.outputSize(width, height);
    const Camera camera(fly_.desc(), width, height, options_.vignetting, options_.metresPerUnit);
    if (live_) live_->update();
    const FastRenderer& renderer = live_ && live_->renderer() ? *live_->renderer() : renderer_;
    const Clock::time_point renderStart = Clock::now();
    renderer.render(camera, options_.render, radiance_);
    renderMs_.push_back(std::chrono::duration<double, std::milli>(Clock::now() - renderStart).count());

    SDL_Texture* texture = window_.texture(width, height);
    void* locked = nullptr;
    int pitch = 0;
    if (SDL_LockTexture(texture, nullptr, &locked, &pitch) != 0) fail("view: cannot lock the texture: {}", SDL_GetError());
    uint32_t* pixels = static_cast<uint32_t*>(locked);
    display_.encode(radiance_, exposureScale(), toneMap_, pixels, pitch);
    drawHud(pixels, pitch, width, height, frameStart);
    SDL_UnlockTexture(texture);
    window_.present();
  }

  /// Counts the frame's time (the HUD's fps averages the last kTimingWindow frames).
  void endFrame(Clock::time_point frameStart) {
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count();
    frameMs_.push_back(ms);
    if (live_ && live_->status().running) relightMs_.push_back(ms);
    recentMs_.push_back(ms);
    if (recentMs_.size() > kTimingWindow) recentMs_.erase(recentMs_.begin());
  }

  /// Saves a recording still running and the requested screenshot; the session's timings.
  ViewerResult finish() {
    if (recorder_.recording()) stopRecording(Clock::now());
    if (!options_.screenshotPath.empty() && !radiance_.empty())
      writeFrame(options_.screenshotPath, radiance_, exposureScale(), toneMap_);
    ViewerResult result;
    result.frames = int(frameMs_.size());
    result.msPerFrameMedian = median(frameMs_);
    result.renderMsMedian = median(renderMs_);
    if (live_) {
      const RelightStatus status = live_->status();
      result.relightFrames = int(relightMs_.size());
      result.relightMsPerFrameMedian = relightMs_.empty() ? 0.0 : median(relightMs_);
      result.relightFirstFrameSeconds = status.firstFrameSeconds;
      result.relightSeconds = status.seconds;
      result.relightSunMaskSeconds = status.sunMaskSeconds;
      result.relightFirstShotSeconds = status.firstShotSeconds;
      result.relightIterations = status.iteration;
      result.relightConverged = status.converged && !status.running;
      result.relightMessage = status.message;
    }
    return result;
  }

 private:
  double secondsAt(Clock::time_point t) const { return std::chrono::duration<double>(t - start_).count(); }
  /// The starting exposure with the +/− offset.
  float exposureScale() const { return options_.exposureScale * std::exp2(exposureEv_); }

  void handleKey(const SDL_KeyboardEvent& key, Clock::time_point frameStart) {
    const SDL_Keycode code = key.keysym.sym;
    if (code == SDLK_ESCAPE) quit_ = true;
    if (code == SDLK_PLUS || code == SDLK_EQUALS || code == SDLK_KP_PLUS) exposureEv_ += kExposureStepEv;
    if (code == SDLK_MINUS || code == SDLK_KP_MINUS) exposureEv_ -= kExposureStepEv;
    if (code == SDLK_t) toneMap_.op = nextOperator(toneMap_.op);
    if (code == SDLK_h) relightHud_ = !relightHud_;
    if (const std::optional<RelightKey> relight = relightKeyOf(code); relight && live_) live_->press(*relight);
    if (code == SDLK_F12 && !radiance_.empty()) {
      const std::string path = formatFramePath(options_.screenshotPattern, screenshots_++);
      writeFrame(path, radiance_, exposureScale(), toneMap_);
      showMessage("wrote " + path);
    }
    if ((code == SDLK_p || code == SDLK_r) && key.repeat == 0) {
      if (recorder_.recording()) {
        stopRecording(frameStart);
      } else {
        recorder_.start(secondsAt(frameStart), fly_.desc());
      }
    }
  }

  void stopRecording(Clock::time_point now) {
    const CameraPath path = recorder_.stop(secondsAt(now), fly_.desc());
    saveCameraPath(options_.recordPath, path);
    showMessage(fmt::format("saved {} keyframes to {}", path.keyframes.size(), options_.recordPath));
  }

  /// Prints `text` and shows it on the HUD for 3 seconds.
  void showMessage(std::string text) {
    message_ = std::move(text);
    fmt::print("{}\n", message_);
    messageUntil_ = Clock::now() + std::chrono::seconds(3);
  }

  /// The HUD: fps over the last frames, frame time, camera, exposure, tone mapping and the
  /// transient message, on a darkened box at the top left.
  void drawHud(uint32_t* pixels, int pitch, int width, int height, Clock::time_point frameStart) const {
    const double meanMs = recentMs_.empty() ? 0.0 : [&] {
      double sum = 0.0;
      for (double ms : recentMs_) sum += ms;
      return sum / double(recentMs_.size());
    }();
    const Vec3 eye = fly_.eye();
    std::vector<std::string> lines = {
        fmt::format("{:.1f} FPS  {:.2f} MS/FRAME  (RENDER {:.2f} MS)  {}X{}", meanMs > 0 ? 1e3 / meanMs : 0.0, meanMs,
                    renderMs_.back(), width, height),
        fmt::format("EYE {:.3g} {:.3g} {:.3g}", eye.x, eye.y, eye.z),
        fmt::format("EXPOSURE {:+.1f} EV  TONEMAP {}{}", exposureEv_, toneMapOperatorName(toneMap_.op),
                    recorder_.recording() ? "  [REC]" : ""),
    };
    if (live_ && relightHud_)
      for (std::string& line : live_->hudLines()) lines.push_back(std::move(line));
    if (!message_.empty() && frameStart < messageUntil_) lines.push_back(message_);
    int hudWidth = 0;
    for (const std::string& line : lines) hudWidth = std::max(hudWidth, hudTextWidth(line, kHudScale));
    const int hudHeight = int(lines.size()) * kLineAdvance * kHudScale + 6;
    darkenRect(pixels, pitch, width, height, 0, 0, hudWidth + 12, hudHeight);
    for (size_t i = 0; i < lines.size(); ++i)
      drawHudText(pixels, pitch, width, height, 6, 4 + int(i) * kLineAdvance * kHudScale, lines[i], kHudScale,
                  0xFFFFFFFFu);
  }

  const ViewerOptions& options_;
  const float speed_;
  FlyCamera fly_;
  const FastRenderer renderer_;
  DisplayEncoder display_;
  Window window_;
  float exposureEv_ = 0.0f;  ///< the +/− offset on top of options.exposureScale
  ToneMapSettings toneMap_;
  Image radiance_;  ///< the last frame
  std::vector<double> frameMs_, renderMs_, recentMs_, relightMs_;
  std::unique_ptr<LiveRelight> live_;  ///< the relighting keys' (null without a visibility field)
  bool relightHud_ = true;
  int screenshots_ = 0;
  bool dragging_ = false, quit_ = false;
  PathRecorder recorder_;
  const Clock::time_point start_;
  std::string message_;  ///< a transient HUD line (saved files)
  Clock::time_point messageUntil_;
};

}  // namespace

ViewerResult runViewer(const LightField& lightField, const Accel& accel, const ViewerOptions& options) {
  checkViewerOptions(options);
  ViewerSession session(lightField, accel, options);
  const int totalFrames = options.frames > 0 ? options.frames : options.path ? options.path->frameCount() : 0;
  // Scripted relighting keys without a frame count: until the relighting is done.
  const bool untilRelit = totalFrames == 0 && !options.relightKeys.empty();
  Clock::time_point previous = Clock::now();
  for (int frame = 0; !session.quit() && (totalFrames == 0 || frame < totalFrames) && !(untilRelit && session.relightDone());
       ++frame) {
    const Clock::time_point frameStart = Clock::now();
    const float dt = std::min(float(std::chrono::duration<double>(frameStart - previous).count()), 0.25f);
    previous = frameStart;
    session.handleEvents(frameStart);
    session.moveCamera(frame, dt, frameStart);
    session.renderAndPresent(frameStart);
    session.endFrame(frameStart);
  }
  return session.finish();
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
