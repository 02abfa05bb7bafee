// The viewer's first-person camera (see fly_camera.h).
#include "viewer/fly_camera.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace pl {

FlyCamera::FlyCamera(const CameraDesc& desc, float speed) : base_(desc), eye_(desc.eye), speed_(speed) {
  const Vec3 view = desc.target - desc.eye;
  distance_ = glm::length(view);
  if (!(distance_ > 0.0f) || !(glm::length(desc.up) > 0.0f)) fail("camera '{}': eye and target coincide or up is zero", desc.name);
  up_ = glm::normalize(desc.up);
  const Vec3 forward = view / distance_;
  Vec3 horizontal = forward - glm::dot(forward, up_) * up_;
  if (!(glm::length(horizontal) > 1e-4f)) fail("camera '{}': looks straight along its up vector", desc.name);
  horizontal0_ = glm::normalize(horizontal);
  horizontal1_ = glm::cross(up_, horizontal0_);  // 90° to the left of horizontal0 about +up
  pitch_ = std::asin(std::clamp(glm::dot(forward, up_), -1.0f, 1.0f));
  const float limit = kMaxPitchDegrees * kPi / 180.0f;
  pitch_ = std::clamp(pitch_, -limit, limit);
}

Vec3 FlyCamera::forward() const {
  const Vec3 horizontal = std::cos(yaw_) * horizontal0_ + std::sin(yaw_) * horizontal1_;
  return std::cos(pitch_) * horizontal + std::sin(pitch_) * up_;
}

void FlyCamera::move(Vec3 rightUpForward, float seconds, float speedFactor) {
  const Vec3 horizontalForward = std::cos(yaw_) * horizontal0_ + std::sin(yaw_) * horizontal1_;
  const Vec3 right = glm::cross(horizontalForward, up_);
  moved_ = true;
  eye_ += (speed_ * speedFactor * seconds) *
          (rightUpForward.x * right + rightUpForward.y * up_ + rightUpForward.z * horizontalForward);
}

void FlyCamera::turn(float yawRadians, float pitchRadians) {
  moved_ = true;
  yaw_ = std::remainder(yaw_ + yawRadians, kTwoPi);
  const float limit = kMaxPitchDegrees * kPi / 180.0f;
  pitch_ = std::clamp(pitch_ + pitchRadians, -limit, limit);
}

CameraDesc FlyCamera::desc() const {
  if (!moved_) return base_;  // exactly the starting camera (no rounding through yaw/pitch)
  CameraDesc d = base_;
  d.eye = eye_;
  d.target = eye_ + distance_ * forward();
  d.up = up_;
  return d;
}

void PathRecorder::start(double seconds, const CameraDesc& camera) {
  recording_ = true;
  start_ = seconds;
  path_ = CameraPath{};
  path_.fps = CameraPath::kDefaultFps;
  sample(seconds, camera, true);
}

void PathRecorder::sample(double seconds, const CameraDesc& camera, bool force) {
  if (!recording_) return;
  const double t = seconds - start_;
  if (!path_.keyframes.empty()) {
    if (!(t > path_.keyframes.back().time)) return;  // times must increase strictly
    if (!force && seconds - last_ < interval_) return;
  }
  path_.keyframes.push_back(CameraKeyframe{t, camera.eye, camera.target, glm::normalize(camera.up), camera.fovYDegrees});
  last_ = seconds;
}

CameraPath PathRecorder::stop(double seconds, const CameraDesc& camera) {
  sample(seconds, camera, true);
  recording_ = false;
  return std::move(path_);
}

}  // namespace pl
