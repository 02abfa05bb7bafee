// The view flags shared by trace, render and view (declared in view_options.h).
#include "app/view_options.h"

#include <cmath>
#include <cstdlib>

#include "core/error.h"
#include "core/file_io.h"
#include "core/memory.h"

namespace pl {
namespace {

/// "X,Y,Z" → 3 floats; CLI::ValidationError naming the flag otherwise.
std::vector<float> parseVec3(const std::string& flag, const std::string& text) {
  std::vector<float> values;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    const float v = std::strtof(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(v))
      throw CLI::ValidationError(flag, "expected three comma-separated numbers X,Y,Z, got '" + text + "'");
    values.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (values.size() != 3)
    throw CLI::ValidationError(flag, "expected three comma-separated numbers X,Y,Z, got '" + text + "'");
  return values;
}

/// A positive finite number, or a fraction "1/125" (shutter times are written that way).
float parsePositive(const std::string& flag, const std::string& text, bool allowFraction) {
  const size_t slash = allowFraction ? text.find('/') : std::string::npos;
  auto number = [&](const std::string& s) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !(v > 0.0) || !std::isfinite(v))
      throw CLI::ValidationError(flag, "expected a positive number" + std::string(allowFraction ? " or a fraction like 1/125" : "") +
                                           ", got '" + text + "'");
    return v;
  };
  const double value = slash == std::string::npos ? number(text) : number(text.substr(0, slash)) / number(text.substr(slash + 1));
  return float(value);
}

}  // namespace

void ViewOptions::addCameraOptions(CLI::App& command) {
  command.add_option("--width", width, "Image width in pixels")->check(CLI::Range(1, kMaxImageSide))->capture_default_str();
  command.add_option("--height", height, "Image height in pixels")->check(CLI::Range(1, kMaxImageSide))->capture_default_str();
  command.add_option("--camera", camera, "Camera NAME from the scene (default: the scene's first camera, else automatic)");
  command.add_option_function<std::string>("--eye", [this](const std::string& s) { eye = parseVec3("--eye", s); },
                                           "Camera position X,Y,Z (scene units)");
  command.add_option_function<std::string>("--target", [this](const std::string& s) { target = parseVec3("--target", s); },
                                           "Point the camera looks at, X,Y,Z");
  command.add_option_function<std::string>("--up", [this](const std::string& s) { up = parseVec3("--up", s); },
                                           "Camera up direction X,Y,Z");
  command.add_option("--fov", fovDegrees, "Vertical field of view in degrees (0 < fov < 180)")
      ->check(CLI::Range(1e-3f, 179.9f));
  command.add_option("--aperture", fNumberLens,
                     "Thin-lens f-number N for depth of field (aperture diameter = focal length / N); "
                     "exposure is set separately with --fstop")
      ->check(CLI::Range(0.1f, 1e4f));
  command.add_option("--focus-distance", focusDistance, "Distance in focus, scene units (default: eye to target)")
      ->check(CLI::PositiveNumber);
  command.add_option("--scene-unit", sceneUnitMetres,
                     "Metres per scene unit, sizes the lens (default: 0.001 for cornell, 1 otherwise)")
      ->check(CLI::PositiveNumber);
}

void ViewOptions::addExposureOptions(CLI::App& command) {
  command.add_option("--exposure", exposureEv, "Exposure compensation in EV: pixel = radiance · 2^EV")
      ->check(CLI::Range(-64.0f, 64.0f));
  command.add_option_function<std::string>("--fstop", [this](const std::string& s) { fstop = parsePositive("--fstop", s, false); },
                                           "Photographic exposure: f-number N (with --shutter and --iso)");
  command.add_option_function<std::string>(
      "--shutter", [this](const std::string& s) { shutterSeconds = parsePositive("--shutter", s, true); },
      "Photographic exposure: shutter time in seconds, e.g. 0.008 or 1/125 (with --fstop and --iso)");
  command.add_option_function<std::string>("--iso", [this](const std::string& s) { iso = parsePositive("--iso", s, false); },
                                           "Photographic exposure: ISO speed S (with --fstop and --shutter)");
  // Refuse an incomplete set as soon as the command line is parsed, before any rendering.
  command.parse_complete_callback([this] {
    const int given = int(fstop.has_value()) + int(shutterSeconds.has_value()) + int(iso.has_value());
    if (given != 0 && given != 3)
      throw CLI::ValidationError("--fstop/--shutter/--iso", "give all three (photographic exposure) or none");
  });
}

void ViewOptions::addToneMapOptions(CLI::App& command) {
  command.add_option("--tonemap", tonemap, "Tone mapping for PNG output: reinhard, linear or clamp")
      ->check(CLI::IsMember({"reinhard", "linear", "clamp"}))
      ->capture_default_str();
  command.add_option_function<std::string>(
      "--key",
      [this](const std::string& s) {
        if (s == "auto") {
          autoKey = true;
        } else {
          key = parsePositive("--key", s, false);
        }
      },
      "Reinhard key (log-average luminance maps to it; default 0.18 unless an exposure is given), or 'auto'");
  command.add_option_function<std::string>(
      "--white", [this](const std::string& s) { white = parsePositive("--white", s, false); },
      "White point: the (exposed) luminance mapped to 1 (reinhard, linear)");
}

void ViewOptions::addImageOptions(CLI::App& command) {
  addExposureOptions(command);
  command.add_flag("--vignetting", vignetting, "Natural vignetting: weight each pixel by cos⁴ of its angle off the axis");
  addToneMapOptions(command);
}

CameraDesc ViewOptions::resolveCamera(const Scene& scene) const {
  CameraDesc desc;
  if (!camera.empty()) {
    desc = scene.camera(camera);
  } else if (scene.settings.camera) {  // the scene file's suggestion ("settings": {"camera": ...})
    desc = scene.camera(*scene.settings.camera);
  } else if (!scene.cameras.empty()) {
    desc = scene.cameras.front();
  } else {
    desc = scene.automaticCamera();
  }
  if (eye.size() == 3) desc.eye = Vec3(eye[0], eye[1], eye[2]);
  if (target.size() == 3) desc.target = Vec3(target[0], target[1], target[2]);
  if (up.size() == 3) desc.up = Vec3(up[0], up[1], up[2]);
  if (fovDegrees > 0.0f) {
    desc.fovYDegrees = fovDegrees;
    desc.focalLengthMm = 0.0f;  // a new fov implies the focal length that gives it
  }
  if (fNumberLens > 0.0f) desc.fNumber = fNumberLens;
  if (focusDistance > 0.0f) desc.focusDistance = focusDistance;
  return desc;
}

float ViewOptions::metresPerUnit(const Scene& scene) const {
  if (sceneUnitMetres) return *sceneUnitMetres;
  return scene.sourcePath == "cornell" ? 0.001f : 1.0f;
}

Camera ViewOptions::makeCamera(const Scene& scene) const {
  return Camera(resolveCamera(scene), width, height, vignetting, metresPerUnit(scene));
}

ExposureSettings ViewOptions::exposureSettings() const {
  ExposureSettings settings;
  settings.compensationEv = exposureEv;
  const int given = int(fstop.has_value()) + int(shutterSeconds.has_value()) + int(iso.has_value());
  if (given != 0 && given != 3) fail("--fstop, --shutter and --iso: give all three (photographic exposure) or none");
  if (given == 3) settings.photographic = PhotographicExposure{*fstop, *shutterSeconds, *iso};
  return settings;
}

float ViewOptions::exposureScale() const { return pl::exposureScale(exposureSettings()); }

ToneMapSettings ViewOptions::toneMapSettings() const {
  ToneMapSettings settings;
  settings.op = parseToneMapOperator(tonemap);
  settings.autoKey = autoKey;
  const bool exposureGiven = exposureEv.has_value() || fstop.has_value();
  settings.key = key ? key : (exposureGiven ? std::nullopt : std::optional<float>(kDefaultKey));
  settings.white = white;
  return settings;
}

void ViewOptions::checkImageOutput(const std::string& path, std::string_view option) {
  checkOutputPath(path, {".exr", ".hdr", ".pfm", ".png"}, option);
}

void ViewOptions::requireImageMemory(int frameBuffers, std::string_view what) const {
  // Per pixel: `frameBuffers` float RGB images (12 B each) and, while writing, the exposed
  // copy (12 B) and the encoder's buffer (at most 12 B: float RGB for EXR and PFM; half
  // floats, RGBE and 8-bit PNG take less). Measured peak RSS of `trace cornell --spp 1` at
  // 2048² (estimate 48 B/px, 192 MiB): 220 MiB writing .png (50 B/px above the 17 MiB of a
  // 64² run), 113 MiB writing .exr without exposure (no exposed copy: 23 B/px).
  constexpr uint64_t kRgbBytes = 3 * sizeof(float), kWriteBytesPerPixel = 2 * kRgbBytes;
  const uint64_t pixels = uint64_t(width) * uint64_t(height);
  requireMemory(pixels * (uint64_t(frameBuffers) * kRgbBytes + kWriteBytesPerPixel),
                fmt::format("{} at {}x{}", what, width, height), "lower --width/--height");
}

void ViewOptions::writeImage(const std::string& path, const Image& radiance) const {
  const float scale = exposureScale();
  const bool hdr = isHdrExtension(path);
  if (!hdr && fileExtensionLower(path) != ".png")
    fail("{}: unknown output type '{}' (use .exr, .hdr, .pfm or .png)", path, fileExtensionLower(path));
  if (scale == 1.0f && hdr) {
    writeHdrImage(path, radiance);
    return;
  }
  Image exposed = radiance;
  for (Rgb& p : exposed.pixels) p *= scale;
  if (hdr) {
    writeHdrImage(path, exposed);
  } else {
    writePng(path, toneMap(exposed, toneMapSettings()));
  }
}

}  // namespace pl
