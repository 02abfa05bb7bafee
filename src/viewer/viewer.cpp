// The interactive viewer (see viewer.h): the one file of plenoptic that includes SDL.
#include "viewer/viewer.h"

#include <SDL.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <cmath>
#include <cctype>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "accel/accel.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "image/display.h"
#include "image/frame_output.h"
#include "gpu/gpu.h"
#include "image/image.h"
#include "realtime/realtime.h"
#include "viewer/core_share.h"
#include "viewer/fly_camera.h"
#include "viewer/hud_text.h"
#include "viewer/live_relight.h"
#include "viewer/render_scale.h"

namespace pl {
namespace {

using Clock = std::chrono::steady_clock;

constexpr float kExposureStepEv = 0.5f;
constexpr float kFastFactor = 4.0f, kSlowFactor = 0.25f;
constexpr float kRadiansPerPixel = 0.004f;  ///< mouse look sensitivity
constexpr int kHudScale = 2;
constexpr size_t kTimingWindow = 60;  ///< frames averaged for the HUD's fps

/// Owns SDL's window and what draws into it — an SDL renderer with streaming textures (the
/// frame, and the HUD over it), or an OpenGL 4.5 core context in which the GPU renderer draws
/// and presents (GpuRenderer::present) — and releases them in reverse order.
class Window {
 public:
  /// How the window shows its frames.
  enum class Mode {
    OpenGl,       ///< its own OpenGL context, the GPU renderer's (else Software: no OpenGL in SDL's driver)
    Software,     ///< SDL's software renderer (the GPU renderer keeps its headless context current)
    Accelerated,  ///< SDL's accelerated renderer where there is one (the CPU renderer's frames)
  };

  /// vsync: where the window has its OpenGL context, swap at the display's vertical sync.
  Window(const std::string& title, int width, int height, Mode mode, bool vsync) : title_(title), vsync_(vsync) {
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
      const char* driver = std::getenv("SDL_VIDEODRIVER");
      fail("view: cannot initialise SDL video{}: {} (no display? run under xvfb-run, or set SDL_VIDEODRIVER=dummy "
           "for a headless run)",
           driver ? fmt::format(" (SDL_VIDEODRIVER={})", driver) : std::string(), SDL_GetError());
    }
    open(width, height, mode);
  }
  ~Window() {
    close();
    SDL_Quit();
  }
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  /// Re-opens the window (same size) to show its frames another way: the GPU renderer could
  /// not draw in its OpenGL context, or not at all.
  void reopen(Mode mode) {
    int width = 0, height = 0;
    SDL_GetWindowSize(window_, &width, &height);
    close();
    open(width, height, mode);
  }
  /// Whether the window has its OpenGL context (current on this thread), and whether its swaps
  /// wait for the vertical sync (SDL_GL_GetSwapInterval: what the driver took).
  bool openGl() const { return glContext_ != nullptr; }
  bool vsync() const { return glContext_ != nullptr && SDL_GL_GetSwapInterval() != 0; }

  /// The size to render at: the window's drawable size.
  void outputSize(int& width, int& height) const {
    if (glContext_) {
      SDL_GL_GetDrawableSize(window_, &width, &height);
    } else if (SDL_GetRendererOutputSize(renderer_, &width, &height) != 0) {
      width = height = 0;
    }
    if (width < 1 || height < 1) SDL_GetWindowSize(window_, &width, &height);
  }
  /// Locks the frame's pixels at width × height (re-made when the size differs): 0xAARRGGBB
  /// words, `pitch` bytes per row, until present().
  uint32_t* lockFrame(int width, int height, int& pitch) { return lock(frame_, width, height, pitch, false); }
  /// Locks the HUD's pixels (blended over the frame's top-left corner at the window's scale).
  uint32_t* lockHud(int width, int height, int& pitch) { return lock(hud_, width, height, pitch, true); }
  /// Shows the frame stretched over the window (width × height, its outputSize when the frame
  /// was rendered) and the HUD over it. With the OpenGL context, `gpu` draws them there — the
  /// frame it encoded and kept (frameOnGpu), else the locked one — and the window swaps its
  /// buffers. `capture`, when given, gets what the window shows (read back before the swap).
  void present(GpuRenderer* gpu, bool frameOnGpu, int width, int height, Image8* capture = nullptr) {
    std::vector<uint32_t> shown;
    if (glContext_) {
      gpu->present(frameOnGpu ? DisplayPixels{} : pixelsOf(frame_), pixelsOf(hud_), width, height);
      if (capture) shown = gpu->readPresented(width, height);
      SDL_GL_SwapWindow(window_);
    } else {
      SDL_UnlockTexture(frame_.texture);
      SDL_RenderClear(renderer_);
      SDL_RenderCopy(renderer_, frame_.texture, nullptr, nullptr);
      if (hud_.texture) {
        SDL_UnlockTexture(hud_.texture);
        const SDL_Rect rect{0, 0, hud_.width, hud_.height};
        SDL_RenderCopy(renderer_, hud_.texture, nullptr, &rect);
      }
      if (capture) {
        shown.resize(size_t(width) * size_t(height));
        const SDL_Rect rect{0, 0, width, height};
        if (SDL_RenderReadPixels(renderer_, &rect, SDL_PIXELFORMAT_ARGB8888, shown.data(), 4 * width) != 0)
          fail("view: cannot read the window's pixels: {}", SDL_GetError());
      }
      SDL_RenderPresent(renderer_);
    }
    if (!capture) return;
    capture->width = width;
    capture->height = height;
    capture->rgb.resize(3 * shown.size());
    for (size_t i = 0; i < shown.size(); ++i) {
      capture->rgb[3 * i] = uint8_t(shown[i] >> 16);
      capture->rgb[3 * i + 1] = uint8_t(shown[i] >> 8);
      capture->rgb[3 * i + 2] = uint8_t(shown[i]);
    }
  }

 private:
  /// A frame or the HUD: an SDL streaming texture, or (with the OpenGL context) words in memory.
  struct Layer {
    SDL_Texture* texture = nullptr;
    std::vector<uint32_t> words;
    int width = 0, height = 0;
  };

  void open(int width, int height, Mode mode) {
    if (mode == Mode::OpenGl) {
      if (openGlWindow(width, height)) return;
      mode = Mode::Software;
    }
    window_ = SDL_CreateWindow(title_.c_str(), SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, width, height,
                               SDL_WINDOW_RESIZABLE);
    if (!window_) fail("view: cannot open a {}x{} window: {}", width, height, SDL_GetError());
    // (SDL's software renderer draws into the window surface, which SDL itself would back
    // with an OpenGL texture on X11 unless told not to.)
    if (mode == Mode::Software) SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
    if (mode == Mode::Accelerated) renderer_ = SDL_CreateRenderer(window_, -1, SDL_RENDERER_ACCELERATED);
    if (!renderer_) renderer_ = SDL_CreateRenderer(window_, -1, SDL_RENDERER_SOFTWARE);
    if (!renderer_) fail("view: cannot create an SDL renderer: {}", SDL_GetError());
    // A frame rendered below the window's size is upscaled bilinearly.
    SDL_SetHint(SDL_HINT_RENDER_SCALE_QUALITY, "linear");
  }
  /// A window with an OpenGL 4.5 core context made current, swapping at the vertical sync
  /// (adaptive, else plain) or not (vsync_); false, with nothing left open, where SDL's video
  /// driver has no OpenGL (dummy, offscreen) or no such context.
  bool openGlWindow(int width, int height) {
    SDL_GL_ResetAttributes();
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 4);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 5);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_GL_SetAttribute(SDL_GL_DEPTH_SIZE, 0);
    window_ = SDL_CreateWindow(title_.c_str(), SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, width, height,
                               SDL_WINDOW_RESIZABLE | SDL_WINDOW_OPENGL);
    if (window_) glContext_ = SDL_GL_CreateContext(window_);
    if (glContext_ && SDL_GL_MakeCurrent(window_, glContext_) == 0) {
      if (!vsync_ || SDL_GL_SetSwapInterval(-1) != 0) SDL_GL_SetSwapInterval(vsync_ ? 1 : 0);
      return true;
    }
    close();
    return false;
  }
  void close() {
    for (Layer* layer : {&hud_, &frame_}) {
      if (layer->texture) SDL_DestroyTexture(layer->texture);
      *layer = Layer{};
    }
    if (renderer_) SDL_DestroyRenderer(renderer_);
    if (glContext_) SDL_GL_DeleteContext(glContext_);
    if (window_) SDL_DestroyWindow(window_);
    renderer_ = nullptr;
    glContext_ = nullptr;
    window_ = nullptr;
  }
  uint32_t* lock(Layer& layer, int width, int height, int& pitch, bool blend) {
    const bool resized = width != layer.width || height != layer.height;
    layer.width = width;
    layer.height = height;
    if (glContext_) {
      layer.words.resize(size_t(width) * size_t(height));
      pitch = 4 * width;
      return layer.words.data();
    }
    if (!layer.texture || resized) {
      if (layer.texture) SDL_DestroyTexture(layer.texture);
      layer.texture = SDL_CreateTexture(renderer_, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_STREAMING, width, height);
      if (!layer.texture) fail("view: cannot create a {}x{} texture: {}", width, height, SDL_GetError());
      SDL_SetTextureBlendMode(layer.texture, blend ? SDL_BLENDMODE_BLEND : SDL_BLENDMODE_NONE);
    }
    void* pixels = nullptr;
    if (SDL_LockTexture(layer.texture, nullptr, &pixels, &pitch) != 0) fail("view: cannot lock a texture: {}", SDL_GetError());
    return static_cast<uint32_t*>(pixels);
  }
  static DisplayPixels pixelsOf(const Layer& layer) {
    if (layer.words.empty()) return {};
    return {layer.words.data(), layer.width, layer.height, 4 * layer.width};
  }

  std::string title_;
  bool vsync_ = false;
  SDL_Window* window_ = nullptr;
  SDL_GLContext glContext_ = nullptr;
  SDL_Renderer* renderer_ = nullptr;
  Layer frame_, hud_;
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
  if (!(options.targetFps >= 0.0) || options.targetFps > 1000.0)
    fail("view: --target-fps must be within 0..1000, got {}", options.targetFps);
  if (!options.screenshotPath.empty() && options.frames == 0 && !options.path && options.relightKeys.empty())
    fail("view: --screenshot needs --frames N or --path (it is written after the last frame)");
  if (!options.windowShotPath.empty() && options.frames == 0 && !options.path)
    fail("view: --window-shot needs --frames N or --path (it is the last frame's window)");
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

/// `text` on one line (a shader's multi-line driver log joined with " | ").
std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (size_t i = text.find('\n'); i != std::string::npos; i = text.find('\n', i)) text.replace(i, 1, " | ");
  return text;
}

/// Why the viewer does not try the GPU renderer (Automatic: a feature it does not draw, no
/// OpenGL 4.5 core context, a software rasteriser), or empty; throws where the GPU renderer was
/// asked for and cannot draw this light field.
std::string gpuRefusal(const LightField& lightField, const ViewerOptions& options) {
  if (options.renderer == ViewerRendererChoice::Cpu) return {};
  const bool asked = options.renderer == ViewerRendererChoice::Gpu;
  if (const std::string feature = gpuUnsupportedFeature(lightField); !feature.empty()) {
    const std::string refused = fmt::format("the GPU renderer does not draw {} yet", feature);
    if (asked) fail("view: {} (use --renderer cpu)", refused);
    return refused;
  }
  if (asked) return {};
  const GpuProbe probe = probeGpu();
  if (!probe.available) return oneLine(probe.error);
  if (probe.software)
    return fmt::format("OpenGL here is a software rasteriser ({}), slower than the CPU renderer "
                       "(--renderer gpu takes it anyway)",
                       probe.device);
  return {};
}

/// How the session's window is opened: with an OpenGL context for the GPU renderer to draw
/// in, unless it will not be tried.
Window::Mode windowModeFor(const ViewerOptions& options, const std::string& gpuRefused) {
  return options.renderer != ViewerRendererChoice::Cpu && gpuRefused.empty() ? Window::Mode::OpenGl
                                                                             : Window::Mode::Accelerated;
}

/// The light-field renderer of a session: the GPU one or the CPU fast one, chosen as viewer.h
/// says. The GPU one draws in the window's OpenGL context where the window has one and it can;
/// else in its own headless context (the window re-opened to show its frames through SDL).
class FrameRenderer {
 public:
  FrameRenderer(const LightField& lightField, const Accel& accel, const ViewerOptions& options,
                const std::string& gpuRefused, Window& window) {
    const bool triedGpu = windowModeFor(options, gpuRefused) == Window::Mode::OpenGl;
    fallback_ = triedGpu ? tryGpu(lightField, options, window) : gpuRefused;
    if (gpu_) {
      device_ = gpu_->deviceName();
      name_ = fmt::format("gpu ({})", device_);
      return;
    }
    // (The window was opened for the GPU renderer: in OpenGL, or for SDL's software renderer.)
    if (triedGpu) window.reopen(Window::Mode::Accelerated);
    if (!fallback_.empty()) fmt::print(stderr, "plenoptic: warning: view uses the CPU renderer: {}\n", fallback_);
    cpu_ = std::make_unique<FastRenderer>(lightField, accel);
    name_ = "cpu";
  }

  bool gpu() const { return gpu_ != nullptr; }
  /// The GPU renderer, where the session has it (Window::present draws with it).
  GpuRenderer* gpuRenderer() const { return gpu_.get(); }
  /// Whether it renders several jittered samples per pixel (the refinement of a still view).
  bool multiSample(const Camera& camera) const {
    RenderSettings two;
    two.samplesPerPixel = 2;
    return !gpu_ || gpu_->unsupportedSetting(two, camera).empty();
  }
  const std::string& name() const { return name_; }
  const std::string& device() const { return device_; }
  const std::string& fallback() const { return fallback_; }
  void render(const Camera& camera, const RenderSettings& settings, Image& image) {
    if (gpu_) {
      gpu_->render(camera, settings, image);
    } else {
      cpu_->render(camera, settings, image);
    }
  }
  /// The GPU renderer's frame kept on the GPU (GpuRenderer::draw): shown by encodeDisplay,
  /// read back by readRadiance. Only with the GPU renderer.
  void drawOnGpu(const Camera& camera, const RenderSettings& settings) { gpu_->draw(camera, settings); }
  void readRadiance(Image& image) { gpu_->readRadiance(image); }
  /// GpuRenderer::encodeDisplay (`pixels` null: the words stay on the GPU for present).
  void encodeDisplay(DisplayEncoder& encoder, float exposureScale, const ToneMapSettings& settings, uint32_t* pixels,
                     int pitchBytes, bool average) {
    gpu_->encodeDisplay(encoder, exposureScale, settings, pixels, pitchBytes, average);
  }
  void accumulate(bool restart) { gpu_->accumulate(restart); }
  /// The GPU's own time for its last frame read back, pass by pass (GpuRenderer::lastGpuPasses).
  GpuPassMilliseconds gpuPasses() const { return gpu_->lastGpuPasses(); }
  void readAverage(Image& image) { gpu_->readAverage(image); }

 private:
  /// Sets gpu_ when the GPU renderer can draw — in the window's OpenGL context, else in its
  /// own; returns why not (Automatic) or throws (Gpu).
  std::string tryGpu(const LightField& lightField, const ViewerOptions& options, Window& window) {
    const bool asked = options.renderer == ViewerRendererChoice::Gpu;
    const Camera camera(options.camera, options.width, options.height, options.vignetting, options.metresPerUnit);
    auto make = [&](GpuContext context) {
      gpu_ = std::make_unique<GpuRenderer>(lightField, context);
      gpu_->checkSettings(options.render, camera);  // what this driver lacks
      gpu_->prepareDisplay();                       // the display pass's shaders compile here
    };
    if (window.openGl()) {
      try {
        make(GpuContext::Current);
        return {};
      } catch (const Error& e) {
        gpu_.reset();
        fmt::print(stderr, "plenoptic: warning: view draws on the GPU in a context of its own, its frames read back: {}\n",
                   oneLine(e.what()));
        window.reopen(Window::Mode::Software);
      }
    }
    try {
      make(GpuContext::Headless);
    } catch (const Error& e) {
      gpu_.reset();
      if (asked) throw;
      return oneLine(e.what());
    }
    return {};
  }

  std::unique_ptr<GpuRenderer> gpu_;
  std::unique_ptr<FastRenderer> cpu_;
  std::string name_, device_, fallback_;
};

/// What the window shows (ViewerSession::renderFrame's states).
enum class Shown {
  Nothing,  ///< no frame yet (or the window was resized)
  Scaled,   ///< the view at a reduced internal resolution (the camera is moving)
  Base,     ///< the view at full resolution and the settings' samples per pixel
  Refined,  ///< the average of refinement batches at full resolution
};

/// One viewer session: what the walk-through loop carries from frame to frame, and the steps
/// of a frame — input, camera, render and display, HUD — in the order runViewer calls them.
class ViewerSession {
 public:
  ViewerSession(const LightField& lightField, const Accel& accel, const ViewerOptions& options)
      : options_(options),
        speed_(flySpeed(lightField.scene, options)),
        fly_(options.camera, speed_),
        gpuRefused_(gpuRefusal(lightField, options)),
        window_(options.title, options.width, options.height, windowModeFor(options, gpuRefused_), options.vsync),
        renderer_(lightField, accel, options, gpuRefused_, window_),
        toneMap_(options.toneMap),
        recorder_(options.recordInterval),
        start_(Clock::now()) {
    if (!options.visibilityPath.empty()) {
      live_ = std::make_unique<LiveRelight>(lightField, accel, options.visibilityPath, kViewerShare);
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

  /// Renders what the frame needs (renderFrame) at the window's size, encodes it into the
  /// window's texture, draws the HUD, and presents them; with `capture` (the last frame, for
  /// --window-shot) keeps what the window shows. Returns whether anything was rendered.
  bool renderAndPresent(Clock::time_point frameStart, bool capture) {
    int width = 0, height = 0;
    window_.outputSize(width, height);
    const Clock::time_point renderStart = Clock::now();
    const bool relit = live_ && live_->update();
    // The cores' share of this frame (core_share.h): while the relighter works and the CPU
    // draws, one core is the relighter's and the frames hold kRelightTargetFps.
    share_ = coreShare(kViewerShare, parallelThreads(), live_ && live_->busy(),
                       !renderer_.gpu() || (live_ && live_->renderer()), options_.targetFps);
    const double scale = renderFrame(width, height, relit);
    const bool rendered = scale > 0.0;
    auto renderDone = [&] { renderMs_.push_back(std::chrono::duration<double, std::milli>(Clock::now() - renderStart).count()); };
    int pitch = 0;
    if (frameOnGpu_) {
      // The GPU's frame becomes the window's pixels there: kept there where the window has the
      // renderer's context, else read back. The read-back of the curve's statistics, or of the
      // pixels, waits for the frame, so the render time ends after it.
      uint32_t* pixels = window_.openGl() ? nullptr : window_.lockFrame(frame_.width, frame_.height, pitch);
      renderer_.encodeDisplay(display_, exposureScale(), toneMap_, pixels, pitch, refiningOnGpu_);
      if (rendered) {
        renderDone();
        gpuPasses_ = renderer_.gpuPasses();
        gpuMs_.push_back(gpuPasses_.total());
      }
    } else {
      if (rendered) renderDone();
      uint32_t* pixels = window_.lockFrame(frame_.width, frame_.height, pitch);
      display_.encode(frame_, exposureScale(), toneMap_, pixels, pitch);
    }
    drawHud(width, height, frameStart);
    window_.present(renderer_.gpuRenderer(), frameOnGpu_, width, height, capture ? &windowShot_ : nullptr);
    // The frame-rate controller learns from frames at the settings' own samples per pixel.
    if (rendered && shown_ != Shown::Refined)
      scales_(share_).record(scale, std::chrono::duration<double, std::milli>(Clock::now() - renderStart).count());
    return rendered;
  }

  /// Counts a frame that rendered (the HUD's fps averages the last kTimingWindow of them);
  /// after one that did not (nothing left to refine) an interactive session waits for input.
  void endFrame(Clock::time_point frameStart, bool rendered) {
    if (rendered && share_.minFrameSeconds > 0.0)
      std::this_thread::sleep_until(frameStart + std::chrono::duration<double>(share_.minFrameSeconds));
    if (!rendered) {
      if (options_.frames == 0 && !options_.path) SDL_WaitEventTimeout(nullptr, kIdleWaitMs);
      return;
    }
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count();
    frameMs_.push_back(ms);
    if (live_ && live_->status().running) relightMs_.push_back(ms);
    recentMs_.push_back(ms);
    if (recentMs_.size() > kTimingWindow) recentMs_.erase(recentMs_.begin());
  }

  /// Saves a recording still running and the requested screenshot; the session's timings.
  ViewerResult finish() {
    if (recorder_.recording()) stopRecording(Clock::now());
    if (!options_.screenshotPath.empty() && shown_ != Shown::Nothing)
      writeFrame(options_.screenshotPath, baseFrame(), exposureScale(), toneMap_);
    if (!options_.windowShotPath.empty() && windowShot_.width > 0) writePng(options_.windowShotPath, windowShot_);
    ViewerResult result;
    result.frames = int(frameMs_.size());
    result.msPerFrameMedian = median(frameMs_);
    result.renderMsMedian = median(renderMs_);
    result.gpuMsMedian = gpuMs_.empty() ? 0.0 : median(gpuMs_);
    result.renderer = renderer_.name();
    result.device = renderer_.device();
    result.fallback = renderer_.fallback();
    result.presentation = window_.openGl() ? "opengl" : "sdl";
    result.vsync = window_.vsync();
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
  static constexpr int kIdleWaitMs = 50;
  /// The viewer's core-sharing policy while relighting (core_share.h; docs/benchmarks.md
  /// "Relighting" has the measurements that chose it).
  static constexpr RelightShare kViewerShare = RelightShare::Split;

  double secondsAt(Clock::time_point t) const { return std::chrono::duration<double>(t - start_).count(); }
  /// The starting exposure with the +/− offset.
  float exposureScale() const { return options_.exposureScale * std::exp2(exposureEv_); }
  Camera cameraAt(int width, int height) const {
    return Camera(fly_.desc(), width, height, options_.vignetting, options_.metresPerUnit);
  }
  int baseSpp() const { return effectiveSamplesPerPixel(options_.render, cameraAt(1, 1).isThinLens()); }

  /// Renders into frame_ what the window should show next at width × height, and returns the
  /// scale it rendered at (0: nothing rendered, frame_ is still right):
  ///   the camera moved (or the size changed, or no frame yet): the view at the controller's
  ///     scale (1 with the GPU renderer or when still);
  ///   still after a scaled frame: the view at full resolution;
  ///   still after that: one refinement batch of jittered samples (seed + batch
  ///     number), averaged with the earlier ones, until kRefinedSamples per pixel;
  ///   then nothing.
  double renderFrame(int width, int height, bool relit) {
    const CameraDesc desc = fly_.desc();
    const bool moved = relit || shown_ == Shown::Nothing || width != shownWidth_ || height != shownHeight_ ||
                       desc.eye != shownDesc_.eye || desc.target != shownDesc_.target || desc.up != shownDesc_.up ||
                       desc.fovYDegrees != shownDesc_.fovYDegrees;
    const bool first = shown_ == Shown::Nothing;
    shownDesc_ = desc;
    shownWidth_ = width;
    shownHeight_ = height;
    if (moved || shown_ == Shown::Scaled) {
      // The very first frame is at full resolution: the controller has no frame time yet.
      const double scale = moved && !first ? scales_(share_).scale(true) : 1.0;
      int w = width, h = height;
      scaledSize(width, height, scale, w, h);
      drawShown(cameraAt(w, h), options_.render);
      shown_ = scale < 1.0 ? Shown::Scaled : Shown::Base;
      batches_ = 0;
      return scale;
    }
    // Refinement: batches of max(2, spp) jittered samples (one sample per pixel is the pixel
    // centre); a base frame of ≥ 2 samples is the first batch.
    const int spp = baseSpp(), batchSpp = std::max(2, spp);
    const bool baseIsBatch = spp == batchSpp;
    const int done = shown_ == Shown::Refined ? batches_ * batchSpp : baseIsBatch ? spp : 0;
    if (done + batchSpp > std::max(spp, ViewerOptions::kRefinedSamples) || !renderer_.multiSample(cameraAt(1, 1)))
      return 0.0;
    RenderSettings batch = options_.render;
    batch.samplesPerPixel = batchSpp;
    if (shown_ == Shown::Base ? gpuDraws() : refiningOnGpu_) {
      // On the GPU: the batches summed there, their average shown from there. A base frame the
      // GPU drew (drawShown) is still its last frame, for it is the first batch: nothing else
      // draws on the GPU while the base is shown, and a relit light field, once drawn, stays.
      if (shown_ == Shown::Base) {
        batches_ = baseIsBatch ? 1 : 0;
        if (baseIsBatch) renderer_.accumulate(true);
      }
      batch.seed = options_.render.seed + uint64_t(batches_) + 1;
      drawWithShare(share_, [&] {
        renderer_.drawOnGpu(cameraAt(width, height), batch);
        renderer_.accumulate(batches_ == 0);
      });
      ++batches_;
      frameOnGpu_ = refiningOnGpu_ = true;
      shown_ = Shown::Refined;
      return 1.0;
    }
    if (shown_ == Shown::Base) {
      accumulation_ = baseIsBatch ? shownRadiance() : Image(width, height);
      batches_ = baseIsBatch ? 1 : 0;
    }
    batch.seed = options_.render.seed + uint64_t(batches_) + 1;
    draw(cameraAt(width, height), batch, batchImage_);
    ++batches_;
    const float weight = 1.0f / float(batches_);
    for (size_t i = 0; i < frame_.pixels.size(); ++i) {
      accumulation_.pixels[i] += batchImage_.pixels[i];
      frame_.pixels[i] = accumulation_.pixels[i] * weight;
    }
    shown_ = Shown::Refined;
    return 1.0;
  }

  /// Renders the view the window shows next: with the GPU renderer its frame stays on the GPU
  /// (frameOnGpu_), where renderAndPresent turns it into the window's pixels; else into frame_.
  void drawShown(const Camera& camera, const RenderSettings& settings) {
    refiningOnGpu_ = false;
    if (gpuDraws()) {
      drawWithShare(share_, [&] { renderer_.drawOnGpu(camera, settings); });
      if (frame_.width != camera.width() || frame_.height != camera.height()) frame_ = Image(camera.width(), camera.height());
      frameOnGpu_ = true;
      return;
    }
    draw(camera, settings, frame_);
  }
  /// Whether the session's frames are the GPU renderer's (not the CPU one's, nor a relit light
  /// field's).
  bool gpuDraws() const { return renderer_.gpu() && !(live_ && live_->renderer()); }

  /// frame_, the shown view's radiance: read back first where it is still on the GPU (its last
  /// frame, or the refinement's average).
  const Image& shownRadiance() {
    if (frameOnGpu_) {
      if (refiningOnGpu_) {
        renderer_.readAverage(frame_);
      } else {
        renderer_.readRadiance(frame_);
      }
      frameOnGpu_ = false;
    }
    return frame_;
  }

  /// Renders with the relit light field's CPU renderer once live relighting has published one
  /// (the GPU renderer draws the baked light field only), else with the session's renderer.
  /// The shown frame, if still on the GPU, is read back first: the GPU renderer holds one.
  void draw(const Camera& camera, const RenderSettings& settings, Image& image) {
    if (&image != &frame_) shownRadiance();
    if (&image == &frame_) frameOnGpu_ = refiningOnGpu_ = false;
    drawWithShare(share_, [&] {
      if (const FastRenderer* relit = live_ ? live_->renderer() : nullptr) {
        relit->render(camera, settings, image);
      } else {
        renderer_.render(camera, settings, image);
      }
    });
  }

  /// The shown view at full resolution and the settings' samples per pixel: what `plenoptic
  /// render` writes (rendered for the purpose when the window shows a scaled or refined frame).
  const Image& baseFrame() {
    if (shown_ == Shown::Base) return shownRadiance();
    draw(cameraAt(shownWidth_, shownHeight_), options_.render, screenshot_);
    return screenshot_;
  }

  void handleKey(const SDL_KeyboardEvent& key, Clock::time_point frameStart) {
    const SDL_Keycode code = key.keysym.sym;
    if (code == SDLK_ESCAPE) quit_ = true;
    if (code == SDLK_PLUS || code == SDLK_EQUALS || code == SDLK_KP_PLUS) exposureEv_ += kExposureStepEv;
    if (code == SDLK_MINUS || code == SDLK_KP_MINUS) exposureEv_ -= kExposureStepEv;
    if (code == SDLK_t) toneMap_.op = nextOperator(toneMap_.op);
    if (code == SDLK_h) relightHud_ = !relightHud_;
    if (const std::optional<RelightKey> relight = relightKeyOf(code); relight && live_) live_->press(*relight);
    if (code == SDLK_F12 && shown_ != Shown::Nothing) {
      const std::string path = formatFramePath(options_.screenshotPattern, screenshots_++);
      writeFrame(path, baseFrame(), exposureScale(), toneMap_);
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

  /// The HUD, at the window's resolution whatever the frame's: fps over the last frames, frame
  /// time, the renderer, render scale and samples, camera, exposure, tone mapping and the
  /// transient message, white on a half-transparent black box at the top left.
  void drawHud(int width, int height, Clock::time_point frameStart) {
    const double meanMs = recentMs_.empty() ? 0.0 : [&] {
      double sum = 0.0;
      for (double ms : recentMs_) sum += ms;
      return sum / double(recentMs_.size());
    }();
    const Vec3 eye = fly_.eye();
    const int spp = shown_ == Shown::Refined ? batches_ * std::max(2, baseSpp()) : baseSpp();
    std::vector<std::string> lines = {
        fmt::format("{:.1f} FPS  {:.2f} MS/FRAME  (RENDER {:.2f} MS)  {}X{}", meanMs > 0 ? 1e3 / meanMs : 0.0, meanMs,
                    renderMs_.empty() ? 0.0 : renderMs_.back(), width, height),
        fmt::format("{} RENDERER  SCALE {:.0f}% ({}X{})  {} SPP{}{}", renderer_.gpu() && !(live_ && live_->renderer()) ? "GPU" : "CPU",
                    100.0 * double(frame_.width) / double(width), frame_.width, frame_.height, spp,
                    share_.targetFps > 0 ? fmt::format("  TARGET {:g} FPS", share_.targetFps)
                    : window_.vsync()    ? "  VSYNC"
                                         : "",
                    share_.renderThreads > 0 ? fmt::format("  {} THREAD{} (RELIGHT 1)", share_.renderThreads,
                                                           share_.renderThreads > 1 ? "S" : "")
                                             : ""),
        frameOnGpu_ && gpuPasses_.total() > 0.0
            ? fmt::format("GPU {:.2f} MS: VISIBILITY {:.2f}  RESOLVE {:.2f}  SHADING {:.2f}", gpuPasses_.total(),
                          gpuPasses_.visibility, gpuPasses_.resolve, gpuPasses_.shading)
            : std::string(),
        fmt::format("EYE {:.3g} {:.3g} {:.3g}", eye.x, eye.y, eye.z),
        fmt::format("EXPOSURE {:+.1f} EV  TONEMAP {}{}", exposureEv_, toneMapOperatorName(toneMap_.op),
                    recorder_.recording() ? "  [REC]" : ""),
    };
    std::erase(lines, std::string());
    if (live_ && relightHud_)
      for (std::string& line : live_->hudLines()) lines.push_back(std::move(line));
    if (!message_.empty() && frameStart < messageUntil_) lines.push_back(message_);
    int hudWidth = 0;
    for (const std::string& line : lines) hudWidth = std::max(hudWidth, hudTextWidth(line, kHudScale));
    hudWidth = std::min(hudWidth + 12, width);
    const int hudHeight = std::min(int(lines.size()) * kLineAdvance * kHudScale + 6, height);
    int pitch = 0;
    uint32_t* pixels = window_.lockHud(hudWidth, hudHeight, pitch);
    for (int y = 0; y < hudHeight; ++y)
      std::fill_n(reinterpret_cast<uint32_t*>(reinterpret_cast<uint8_t*>(pixels) + size_t(y) * size_t(pitch)), hudWidth,
                  kHudBackdrop);
    for (size_t i = 0; i < lines.size(); ++i)
      drawHudText(pixels, pitch, hudWidth, hudHeight, 6, 4 + int(i) * kLineAdvance * kHudScale, lines[i], kHudScale,
                  0xFFFFFFFFu);
  }
  static constexpr uint32_t kHudBackdrop = 0x80000000u;  ///< black at half opacity (ARGB)

  const ViewerOptions& options_;
  const float speed_;
  FlyCamera fly_;
  const std::string gpuRefused_;  ///< why the GPU renderer is not tried (gpuRefusal)
  Window window_;                 ///< (before renderer_: its OpenGL context outlives the GPU renderer)
  FrameRenderer renderer_;
  DisplayEncoder display_;
  ShareScale scales_;
  CoreShare share_;  ///< the frame's (renderAndPresent)
  float exposureEv_ = 0.0f;  ///< the +/− offset on top of options.exposureScale
  ToneMapSettings toneMap_;
  Image frame_;         ///< what the window shows (radiance; scaled, base or refined), its size
  /// frame_'s pixels are on the GPU, not read back: the GPU renderer's last frame, or with
  /// refiningOnGpu_ the average of the refinement batches it accumulated.
  bool frameOnGpu_ = false, refiningOnGpu_ = false;
  Image accumulation_;  ///< the sum of the refinement batches
  Image batchImage_, screenshot_;
  Image8 windowShot_;  ///< the last frame's window as shown (--window-shot)
  Shown shown_ = Shown::Nothing;
  CameraDesc shownDesc_;
  int shownWidth_ = 0, shownHeight_ = 0;
  int batches_ = 0;  ///< refinement batches in accumulation_
  std::vector<double> frameMs_, renderMs_, recentMs_, relightMs_;
  std::vector<double> gpuMs_;       ///< the GPU's own time of each frame it drew and showed
  GpuPassMilliseconds gpuPasses_;   ///< the last such frame's, pass by pass (the HUD's GPU line)
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
    const bool rendered = session.renderAndPresent(frameStart, frame + 1 == totalFrames && !options.windowShotPath.empty());
    session.endFrame(frameStart, rendered);
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
