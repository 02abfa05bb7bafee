#pragma once
// The viewer's first-person camera: position + yaw/pitch about the world up vector, moved by
// keys and mouse. No SDL here (the window code feeds it), so it is unit-testable.
//
// Conventions: yaw 0 looks along the horizontal part of the initial view direction; yaw grows
// to the left (counter-clockwise seen from above, about +up); pitch grows upwards and is
// kept within ±kMaxPitchDegrees so the view never flips over the pole. The target stays at
// the initial eye–target distance in front of the eye (a thin lens stays focused there).
#include "camera/camera_path.h"
#include "core/math.h"
#include "scene/scene.h"

namespace pl {

class FlyCamera {
 public:
  static constexpr float kMaxPitchDegrees = 89.0f;

  /// Starts at `desc` (its eye, target and up; fov and lens are kept for pose()).
  /// speed: scene units per second at normal speed.
  FlyCamera(const CameraDesc& desc, float speed);

  /// Moves by (right, up, forward) in the camera's horizontal frame — forward and right
  /// are horizontal (perpendicular to up), up is the world up — times speed·seconds.
  void move(Vec3 rightUpForward, float seconds, float speedFactor = 1.0f);
  /// Turns by yaw (left positive) and pitch (up positive), radians.
  void turn(float yawRadians, float pitchRadians);

  /// The camera description for the current pose (the starting one, unchanged, until the
  /// first move or turn).
  CameraDesc desc() const;
  Vec3 eye() const { return eye_; }
  Vec3 forward() const;
  float speed() const { return speed_; }

 private:
  CameraDesc base_;
  Vec3 eye_;
  Vec3 up_, horizontal0_, horizontal1_;  ///< world up; horizontal frame (yaw 0 and yaw 90°)
  float yaw_ = 0.0f, pitch_ = 0.0f;
  float distance_ = 1.0f;  ///< eye–target distance kept in front of the eye
  float speed_;
  bool moved_ = false;
};

/// Records a flown camera into a camera path (camera/camera_path.h): a keyframe at the start,
/// then at most one every `interval` seconds, and one at the end; times are seconds since
/// the start of the recording. The viewer toggles it with P (or R).
class PathRecorder {
 public:
  explicit PathRecorder(double interval = 0.25) : interval_(interval) {}
  bool recording() const { return recording_; }
  /// Starts a new recording with the camera at `seconds` (any clock, e.g. since program start).
  void start(double seconds, const CameraDesc& camera);
  /// Adds a keyframe if `interval` has passed since the last one (or `force`).
  void sample(double seconds, const CameraDesc& camera, bool force = false);
  /// Ends the recording with a final keyframe and returns the path (fps = kDefaultFps).
  CameraPath stop(double seconds, const CameraDesc& camera);

 private:
  double interval_;
  bool recording_ = false;
  double start_ = 0.0, last_ = 0.0;
  CameraPath path_;
};

}  // namespace pl
