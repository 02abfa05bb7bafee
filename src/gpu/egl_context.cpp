// The headless EGL context (egl_context.h); libepoxy resolves the EGL and GL entry points.
#include "gpu/egl_context.h"

#include <epoxy/egl.h>

#include "core/error.h"

namespace pl::gpu {
namespace {

const char* eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "an unknown EGL error";
  }
}

// OpenGL 4.5 core: the version every shader of src/gpu is written for (#version 450 core).
constexpr EGLint kContextAttributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};

}  // namespace

struct EglContext::Handles {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLSurface surface = EGL_NO_SURFACE;
  EGLContext context = EGL_NO_CONTEXT;
};

EglContext::EglContext() : handles_(std::make_unique<Handles>()) {
  Handles& h = *handles_;
  // Each attempt either leaves a current context in h or returns why it failed.
  auto attempt = [&](EGLDisplay display, bool pbuffer) -> std::string {
    if (display == EGL_NO_DISPLAY) return fmt::format("no display ({})", eglErrorName(eglGetError()));
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) return fmt::format("eglInitialize: {}", eglErrorName(eglGetError()));
    // (A failed display is left initialised: EGL displays are per process, and terminating
    // one would pull it from under another renderer's live context.)
    auto failed = [&](const char* call) { return fmt::format("{}: {}", call, eglErrorName(eglGetError())); };
    if (!eglBindAPI(EGL_OPENGL_API)) return failed("eglBindAPI(EGL_OPENGL_API)");
    EGLConfig config = nullptr;
    EGLSurface surface = EGL_NO_SURFACE;
    if (pbuffer) {
      const EGLint configAttributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
      EGLint count = 0;
      if (!eglChooseConfig(display, configAttributes, &config, 1, &count) || count == 0)
        return failed("eglChooseConfig (pbuffer, OpenGL)");
      const EGLint surfaceAttributes[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
      surface = eglCreatePbufferSurface(display, config, surfaceAttributes);
      if (surface == EGL_NO_SURFACE) return failed("eglCreatePbufferSurface");
    }
    const EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, kContextAttributes);
    if (context == EGL_NO_CONTEXT) return failed("eglCreateContext (OpenGL 4.5 core)");
    if (!eglMakeCurrent(display, surface, surface, context)) return failed("eglMakeCurrent");
    h.display = display;
    h.surface = surface;
    h.context = context;
    return {};
  };
  std::string surfaceless = "EGL_MESA_platform_surfaceless not offered";
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (clientExtensions != nullptr && std::string_view(clientExtensions).find("EGL_MESA_platform_surfaceless") != std::string_view::npos) {
    surfaceless = attempt(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), false);
    if (surfaceless.empty()) {
      platform_ = "surfaceless";
      return;
    }
  }
  const std::string pbuffer = attempt(eglGetDisplay(EGL_DEFAULT_DISPLAY), true);
  if (pbuffer.empty()) {
    platform_ = "pbuffer";
    return;
  }
  fail("GPU renderer: no OpenGL 4.5 core context: surfaceless EGL: {}; pbuffer on the default display: {}", surfaceless,
       pbuffer);
}

EglContext::~EglContext() {
  Handles& h = *handles_;
  eglMakeCurrent(h.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(h.display, h.context);
  if (h.surface != EGL_NO_SURFACE) eglDestroySurface(h.display, h.surface);
  // The display stays initialised (see the constructor): other renderers may share it.
}

void EglContext::makeCurrent() const {
  const Handles& h = *handles_;
  if (!eglMakeCurrent(h.display, h.surface, h.surface, h.context))
    fail("GPU renderer: eglMakeCurrent: {}", eglErrorName(eglGetError()));
}

}  // namespace pl::gpu
