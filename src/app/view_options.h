#pragma once
// Options shared by every command that turns radiance into pictures (trace, render, view):
// image size, camera choice, exposure, vignetting and tone mapping. Declared once here so
// the commands agree on names, ranges and defaults.
#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "camera/camera.h"
#include "camera/exposure.h"
#include "image/image.h"
#include "image/tonemap.h"
#include "scene/scene.h"

namespace pl {

struct ViewOptions {
  static constexpr int kMaxImageSide = 16384;  ///< --width/--height range is 1..kMaxImageSide

  // Image size in pixels.
  int width = 640;
  int height = 480;
  // Camera: --camera NAME, or --eye/--target/--up/--fov; otherwise the camera the scene
  // file's settings name, otherwise the scene's first camera, otherwise an automatic camera
  // framing the scene. --eye/--target/--up/--fov/--aperture/--focus-distance override the
  // chosen camera's values.
  std::string camera;
  std::vector<float> eye, target, up;  ///< 3 components each when given
  float fovDegrees = 0.0f;             ///< vertical; 0 = keep the camera's own
  float fNumberLens = 0.0f;            ///< --aperture N: thin lens f-number (0 = pinhole/keep)
  float focusDistance = 0.0f;          ///< --focus-distance D (scene units; 0 = keep)
  /// --scene-unit M: metres per scene unit, sizes the thin lens (camera.h). Unset: 0.001 for
  /// the built-in Cornell box (millimetres), 1 otherwise (glTF is in metres; OBJ/JSON assumed so).
  std::optional<float> sceneUnitMetres;
  // Exposure: --exposure EV (compensation, scale 2^EV), or --fstop/--shutter/--iso (all three).
  std::optional<float> exposureEv;
  std::optional<float> fstop, shutterSeconds, iso;
  bool vignetting = false;
  // Tone mapping for 8-bit output.
  std::string tonemap = "reinhard";  ///< reinhard | linear | clamp
  /// --key A|auto: Reinhard key. Unset: 0.18 when no exposure flag is given (Reinhard's
  /// automatic exposure from the log-average luminance), none when an exposure is given
  /// (the camera's exposure is then used as it is). See toneMapSettings().
  std::optional<float> key;
  bool autoKey = false;       ///< --key auto
  std::optional<float> white;  ///< luminance mapped to 1

  /// Adds --width/--height and the camera flags.
  void addCameraOptions(CLI::App& command);
  /// Adds the exposure, vignetting and tone-mapping flags (addExposureOptions +
  /// --vignetting + addToneMapOptions).
  void addImageOptions(CLI::App& command);
  /// --exposure, --fstop, --shutter, --iso (checked all-or-none when parsing completes).
  void addExposureOptions(CLI::App& command);
  /// --tonemap, --key, --white.
  void addToneMapOptions(CLI::App& command);

  /// The camera these options select for `scene` (with overrides from the flags applied).
  CameraDesc resolveCamera(const Scene& scene) const;
  /// Metres per scene unit for `scene` (--scene-unit, else the default described above).
  float metresPerUnit(const Scene& scene) const;
  /// Camera(resolveCamera(scene), width, height, vignetting, metresPerUnit(scene)).
  Camera makeCamera(const Scene& scene) const;

  /// The exposure flags as settings; throws pl::Error unless --fstop/--shutter/--iso come
  /// all three or none.
  ExposureSettings exposureSettings() const;
  /// Multiplier from scene radiance to pixel value (1 when no exposure flag was given).
  float exposureScale() const;
  /// The tone-mapping flags as settings (default key rule above).
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
};

}  // namespace pl
