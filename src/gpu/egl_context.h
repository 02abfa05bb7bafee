#pragma once
// Internal to src/gpu: the headless OpenGL context. egl_context.cpp is the only file that
// includes EGL.
#include <memory>
#include <string>

namespace pl::gpu {

/// A current OpenGL 4.5 core context without a window: EGL on Mesa's surfaceless platform
/// (EGL_PLATFORM_SURFACELESS_MESA), else on the default display with a 1×1 pbuffer surface.
/// Rendering goes to framebuffer objects only.
class EglContext {
 public:
  /// Throws pl::Error naming the EGL call and error (EGL_BAD_MATCH, …) when neither display
  /// gives a 4.5 core context.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  /// Makes the context current on the calling thread (a renderer's calls may come from any
  /// one thread at a time).
  void makeCurrent() const;
  /// Which EGL platform gave the context: "surfaceless" or "pbuffer".
  const std::string& platform() const { return platform_; }

 private:
  struct Handles;
  std::unique_ptr<Handles> handles_;
  std::string platform_;
};

}  // namespace pl::gpu
