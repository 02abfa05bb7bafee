// The view flags shared by trace, render and view (declared in view_options.h).
#include "app/view_options.h"

#include <cmath>
#include <cstdlib>

#include "camera/exposure.h"
#include "core/error.h"

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

void addCameraOptions(CLI::App& command, ViewSettings& view) {
  constexpr int kMaxSide = ViewSettings::kMaxImageSide;
  command.add_option("--width", view.width, "Image width in pixels")->check(CLI::Range(1, kMaxSide))->capture_default_str();
  command.add_option("--height", view.height, "Image height in pixels")->check(CLI::Range(1, kMaxSide))->capture_default_str();
  command.add_option("--camera", view.camera, "Camera NAME from the scene (default: the scene's first camera, else automatic)");
  command.add_option_function<std::string>("--eye", [&view](const std::string& s) { view.eye = parseVec3("--eye", s); },
                                           "Camera position X,Y,Z (scene units)");
  command.add_option_function<std::string>(
      "--target", [&view](const std::string& s) { view.target = parseVec3("--target", s); },
      "Point the camera looks at, X,Y,Z");
  command.add_option_function<std::string>("--up", [&view](const std::string& s) { view.up = parseVec3("--up", s); },
                                           "Camera up direction X,Y,Z");
  command.add_option("--fov", view.fovDegrees, "Vertical field of view in degrees (0 < fov < 180)")
      ->check(CLI::Range(1e-3f, 179.9f));
  command.add_option("--aperture", view.fNumberLens,
                     "Thin-lens f-number N for depth of field (aperture diameter = focal length / N); "
                     "exposure is set separately with --fstop")
      ->check(CLI::Range(0.1f, 1e4f));
  command.add_option("--focus-distance", view.focusDistance, "Distance in focus, scene units (default: eye to target)")
      ->check(CLI::PositiveNumber);
  command.add_option("--scene-unit", view.sceneUnitMetres,
                     "Metres per scene unit, sizes the lens (default: 0.001 for cornell, 1 otherwise)")
      ->check(CLI::PositiveNumber);
}

void addExposureOptions(CLI::App& command, ViewSettings& view) {
  command.add_option("--exposure", view.exposureEv, "Exposure compensation in EV: pixel = radiance · 2^EV")
      ->check(CLI::Range(-64.0f, 64.0f));
  command.add_option_function<std::string>(
      "--fstop", [&view](const std::string& s) { view.fstop = parsePositive("--fstop", s, false); },
      "Photographic exposure: f-number N (with --shutter and --iso)");
  command.add_option_function<std::string>(
      "--shutter", [&view](const std::string& s) { view.shutterSeconds = parsePositive("--shutter", s, true); },
      "Photographic exposure: shutter time in seconds, e.g. 0.008 or 1/125 (with --fstop and --iso)");
  command.add_option_function<std::string>(
      "--iso", [&view](const std::string& s) { view.iso = parsePositive("--iso", s, false); },
      "Photographic exposure: ISO speed S (with --fstop and --shutter)");
  // Refuse an incomplete set as soon as the command line is parsed, before any rendering.
  command.parse_complete_callback([&view] {
    try {
      (void)photographicExposure(view.fstop, view.shutterSeconds, view.iso, "--fstop/--shutter/--iso");
    } catch (const UsageError& e) {
      throw CLI::ValidationError(e.what());
    }
  });
}

void addRenderSettingsOptions(CLI::App& command, RenderSettings& render) {
  // --samples: the name these commands used first, still accepted.
  command.add_option("--spp,--samples", render.samplesPerPixel,
                     "Camera samples per pixel (0 = 1 at the pixel centre for a pinhole, 16 for a thin lens)")
      ->check(CLI::Range(0, RenderSettings::kMaxSamplesPerPixel))
      ->capture_default_str();
  command.add_option("--mirror-depth", render.mirrorDepth, "Mirror reflections followed (-1 = the bake's own mirror depth)")
      ->check(CLI::Range(-1, RenderSettings::kMaxMirrorDepth))
      ->capture_default_str();
  command
      .add_option_function<std::string>(
          "--texture-lod", [&render](const std::string& s) { render.textureLod = s == "on"; },
          "Albedo textures at the mip level of each sample's ray cone (on, the default) or at full resolution (off)")
      ->check(CLI::IsMember({"on", "off"}))
      ->default_str("on");
}

void addToneMapOptions(CLI::App& command, ViewSettings& view) {
  command.add_option("--tonemap", view.tonemap, "Tone mapping for PNG output: reinhard, linear or clamp")
      ->check(CLI::IsMember({"reinhard", "linear", "clamp"}))
      ->capture_default_str();
  command.add_option_function<std::string>(
      "--key",
      [&view](const std::string& s) {
        if (s == "auto") {
          view.autoKey = true;
        } else {
          view.key = parsePositive("--key", s, false);
        }
      },
      "Reinhard key (log-average luminance maps to it; default 0.18 unless an exposure is given), or 'auto'");
  command.add_option_function<std::string>(
      "--white", [&view](const std::string& s) { view.white = parsePositive("--white", s, false); },
      "White point: the (exposed) luminance mapped to 1 (reinhard, linear)");
}

void addImageOptions(CLI::App& command, ViewSettings& view) {
  addExposureOptions(command, view);
  command.add_flag("--vignetting", view.vignetting, "Natural vignetting: weight each pixel by cos⁴ of its angle off the axis");
  addToneMapOptions(command, view);
}

}  // namespace pl
