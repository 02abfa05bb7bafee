// Pinhole and thin-lens cameras (conventions and the aperture in scene units: camera.h).
//
// Natural vignetting, the cos⁴ law (tri-Ace, "Physically based rendering", the "Solve it with
// Lambert" slides). The flux a sensor pixel of area A_p receives through an aperture of
// area A_a at distance L_a (sensor to aperture) is
//     Φ_pixel = ∫_pixel ∫_aperture L(x_a → x_p) · cos θ_p · cos θ_a / r² dA_a dA_p,
// θ_p the angle at the sensor (between its normal, the optical axis, and the ray), θ_a the
// angle at the aperture (whose plane is also perpendicular to the axis, so θ_a = θ_p = θ),
// and r = L_a / cos θ the distance between the two points. Hence
//     Φ_pixel = (1/L_a²) ∫_pixel ∫_aperture L · cos⁴θ dA_a dA_p       (the talk's final result)
// ≈ L · cos⁴θ · A_a · A_p / L_a² for a small pixel and aperture: one cos from the sensor's
// foreshortening, one from the aperture's, two from the inverse square of the longer
// oblique distance. A_a/L_a² ∝ 1/N² is the f-number's share (exposure.h); A_p is the same
// for every pixel; cos⁴θ is what remains per pixel: the weight returned with each ray when
// vignetting is on. θ is taken on the chief ray (through the lens centre): for apertures
// small against the lens-to-sensor distance all rays to one pixel share it, and it keeps the
// weight free of lens-sampling noise.
#include "camera/camera.h"

#include <cmath>

#include "core/error.h"
#include "core/sampling.h"

namespace pl {

float focalLengthMmForFov(float fovYDegrees) {
  return 0.5f * kFullFrameSensorHeightMm / std::tan(glm::radians(fovYDegrees) * 0.5f);
}

float fovForFocalLengthMm(float focalLengthMm) {
  return glm::degrees(2.0f * std::atan(0.5f * kFullFrameSensorHeightMm / focalLengthMm));
}

Camera::Camera(const CameraDesc& desc, int width, int height, bool vignetting, float metresPerUnit)
    : desc_(desc), width_(width), height_(height), vignetting_(vignetting) {
  const std::string name = desc.name.empty() ? std::string("(unnamed)") : desc.name;
  if (width < 1 || height < 1) fail("camera '{}': image size {}x{} must be at least 1x1", name, width, height);
  if (!isFinite(desc.eye) || !isFinite(desc.target) || !isFinite(desc.up))
    fail("camera '{}': eye, target and up must be finite", name);
  const Vec3 view = desc.target - desc.eye;
  const float viewLength = glm::length(view);
  if (!(viewLength > 0.0f)) fail("camera '{}': eye and target coincide ({}, {}, {})", name, desc.eye.x, desc.eye.y, desc.eye.z);
  forward_ = view / viewLength;
  const Vec3 side = glm::cross(forward_, desc.up);
  if (!(glm::length(side) > 1e-6f * glm::length(desc.up)))
    fail("camera '{}': up vector ({}, {}, {}) is parallel to the view direction", name, desc.up.x, desc.up.y, desc.up.z);
  right_ = glm::normalize(side);
  up_ = glm::cross(right_, forward_);
  eye_ = desc.eye;
  if (!(desc.fovYDegrees > 0.0f && desc.fovYDegrees < 180.0f))
    fail("camera '{}': vertical field of view {}° must be in (0°, 180°)", name, desc.fovYDegrees);
  tanHalfFovY_ = std::tan(glm::radians(desc.fovYDegrees) * 0.5f);
  aspect_ = float(width) / float(height);

  focalLengthMm_ = desc.focalLengthMm > 0.0f ? desc.focalLengthMm : focalLengthMmForFov(desc.fovYDegrees);
  if (desc.fNumber < 0.0f || !std::isfinite(desc.fNumber))
    fail("camera '{}': f-number {} must be positive (or 0 for a pinhole)", name, desc.fNumber);
  if (desc.fNumber > 0.0f) {
    if (!(metresPerUnit > 0.0f && std::isfinite(metresPerUnit)))
      fail("camera '{}': scene unit {} m must be positive", name, metresPerUnit);
    if (!(desc.focusDistance >= 0.0f)) fail("camera '{}': focus distance {} must be positive (or 0 for the distance to the target)", name, desc.focusDistance);
    const float focalLength = focalLengthMm_ * 0.001f / metresPerUnit;  // scene units
    focusDistance_ = desc.focusDistance > 0.0f ? desc.focusDistance : viewLength;
    if (!(focusDistance_ > focalLength))
      fail("camera '{}': focus distance {} must exceed the focal length {} ({} mm at {} m per scene unit)", name,
           focusDistance_, focalLength, focalLengthMm_, metresPerUnit);
    apertureRadius_ = focalLength / (2.0f * desc.fNumber);
  }
}

Camera::Sample Camera::generateRay(Vec2 film, Vec2 lens) const {
  const float sx = (2.0f * film.x / float(width_) - 1.0f) * tanHalfFovY_ * aspect_;
  const float sy = (1.0f - 2.0f * film.y / float(height_)) * tanHalfFovY_;
  // Camera-space direction with unit forward component: cos θ = 1/|toFilm|.
  const Vec3 toFilm = forward_ + sx * right_ + sy * up_;
  const float invLength = 1.0f / glm::length(toFilm);
  Sample sample;
  if (vignetting_) {
    const float cosTheta = invLength;
    const float cos2 = cosTheta * cosTheta;
    sample.weight = cos2 * cos2;
  }
  if (apertureRadius_ <= 0.0f) {
    sample.ray.origin = eye_;
    sample.ray.direction = toFilm * invLength;
    return sample;
  }
  // Where the chief ray meets the plane of focus (distance d_f along the axis).
  const Vec3 focusPoint = eye_ + toFilm * focusDistance_;
  const Vec2 disk = apertureRadius_ * sampleConcentricDisk(lens);
  const Vec3 lensPoint = eye_ + disk.x * right_ + disk.y * up_;
  sample.ray.origin = lensPoint;
  sample.ray.direction = glm::normalize(focusPoint - lensPoint);
  return sample;
}

bool Camera::project(const Vec3& world, Vec2& film) const {
  const Vec3 v = world - eye_;
  const float depth = glm::dot(v, forward_);
  if (!(depth > 0.0f)) return false;
  const float sx = glm::dot(v, right_) / depth;
  const float sy = glm::dot(v, up_) / depth;
  film.x = (sx / (tanHalfFovY_ * aspect_) + 1.0f) * 0.5f * float(width_);
  film.y = (1.0f - sy / tanHalfFovY_) * 0.5f * float(height_);
  return true;
}

}  // namespace pl
