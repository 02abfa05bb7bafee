// How radiance becomes a picture (ViewSettings, jobs.h): camera choice, exposure, tone
// mapping, image writing.
#include <fmt/format.h>

#include "core/error.h"
#include "core/file_io.h"
#include "core/memory.h"
#include "image/frame_output.h"
#include "jobs/jobs.h"

namespace pl {

CameraDesc ViewSettings::resolveCamera(const Scene& scene) const {
  CameraDesc desc;
  if (cameraDesc) {
    desc = *cameraDesc;
  } else if (!camera.empty()) {
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

float ViewSettings::metresPerUnit(const Scene& scene) const {
  if (sceneUnitMetres) return *sceneUnitMetres;
  return scene.sourcePath == "cornell" ? 0.001f : 1.0f;
}

Camera ViewSettings::makeCamera(const Scene& scene) const {
  return Camera(resolveCamera(scene), width, height, vignetting, metresPerUnit(scene));
}

ExposureSettings ViewSettings::exposureSettings() const {
  ExposureSettings settings;
  settings.compensationEv = exposureEv;
  settings.photographic = photographicExposure(fstop, shutterSeconds, iso, "--fstop, --shutter and --iso");
  return settings;
}

float ViewSettings::exposureScale() const { return pl::exposureScale(exposureSettings()); }

ToneMapSettings ViewSettings::toneMapSettings() const {
  ToneMapSettings settings;
  settings.op = parseToneMapOperator(tonemap);
  settings.autoKey = autoKey;
  const bool exposureGiven = exposureEv.has_value() || fstop.has_value();
  settings.key = key ? key : (exposureGiven ? std::nullopt : std::optional<float>(kDefaultKey));
  settings.white = white;
  return settings;
}

void ViewSettings::checkImageOutput(const std::string& path, std::string_view option) {
  checkOutputPath(path, kWrittenImageExtensions, option);
}

void ViewSettings::requireImageMemory(int frameBuffers, std::string_view what) const {
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

void ViewSettings::writeImage(const std::string& path, const Image& radiance) const {
  writeFrame(path, radiance, exposureScale(), toneMapSettings());
}

void ViewSettings::checkImageSize(std::string_view where) const {
  if (width < 1 || width > kMaxImageSide || height < 1 || height > kMaxImageSide)
    fail("{}image size {}x{} is out of range (width and height must be 1..{})", where, width, height, kMaxImageSide);
}

}  // namespace pl
