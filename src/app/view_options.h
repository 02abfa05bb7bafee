#pragma once
// Options shared by every command that turns radiance into pictures (trace, render, view):
// image size, camera choice, exposure, vignetting and tone mapping. Declared once here so
// the commands agree on names, ranges and defaults.
#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

#include "image/image.h"
#include "scene/scene.h"

namespace pl {

struct ViewOptions {
  // Image size in pixels.
  int width = 640;
  int height = 480;
  // Camera: --camera NAME, or --eye/--target/--up/--fov; otherwise the scene's first camera,
  // otherwise an automatic camera framing the scene.
  std::string camera;
  std::vector<float> eye, target, up;  ///< 3 components each when given
  float fovDegrees = 0.0f;             ///< vertical; 0 = keep the camera's own
  float fNumberLens = 0.0f;            ///< --aperture N: thin lens f-number (0 = pinhole/keep)
  float focusDistance = 0.0f;          ///< --focus-distance D (scene units; 0 = keep)
  // Exposure: --exposure EV (compensation, scale 2^EV), or --fstop/--shutter/--iso.
  std::optional<float> exposureEv;
  std::optional<float> fstop, shutterSeconds, iso;
  bool vignetting = false;
  // Tone mapping for 8-bit output.
  std::string tonemap = "reinhard";  ///< reinhard | linear | clamp
  std::optional<float> key;          ///< Reinhard key; default automatic-from-log-average? see tonemap.h
  std::optional<float> white;        ///< luminance mapped to 1

  /// Adds --width/--height and the camera flags.
  void addCameraOptions(CLI::App& command);
  /// Adds the exposure, vignetting and tone-mapping flags.
  void addImageOptions(CLI::App& command);

  /// The camera these options select for `scene` (with overrides from the flags applied).
  CameraDesc resolveCamera(const Scene& scene) const;
  /// Multiplier from scene radiance to pixel value (1 when no exposure flag was given).
  float exposureScale() const;
  /// Writes radiance (already including vignetting) to path: HDR formats get radiance times
  /// exposureScale(); PNG gets exposure, tone mapping and sRGB encoding. Atomic.
  void writeImage(const std::string& path, const Image& radiance) const;
};

}  // namespace pl
