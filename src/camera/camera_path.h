#pragma once
// Camera paths: keyframed walk-throughs for `plenoptic render --path` and the viewer's
// recorder.
//
// File format (JSON):
//   {"fps": 30,
//    "keyframes": [{"time": 0, "eye": [x, y, z], "target": [x, y, z], "fov": 40, "up": [0, 1, 0]},
//                  ...]}
// time in seconds (strictly increasing), eye/target in scene units, fov the vertical field of
// view in degrees (0 < fov < 180). "fps" (default 30, 0 < fps ≤ 1000), "fov" and "up"
// (default [0, 1, 0]) are optional; a keyframe without "fov" keeps the previous keyframe's
// (the first given one before that), and a path without any "fov" uses the camera the
// command would otherwise use. Unknown keys are refused (they are usually typos).
//
// Frames: frame k (k = 0 … frameCount−1) shows time t₀ + k/fps, t₀ the first keyframe's
// time; frameCount = ⌊(t_last − t₀)·fps⌋ + 1, so a path of duration D at 30 fps gives 30·D+1
// frames, the last one on (or just before) the last keyframe.
//
// Interpolation. eye and target each follow a centripetal Catmull–Rom spline (α = ½; Yuksel,
// Schaefer & Keyser 2011, "Parameterization and applications of Catmull–Rom curves": no
// cusps or self-intersections within a segment, unlike the uniform variant)
// through the keyframe positions. Between keyframes i and i+1 the spline's own parameter
// runs linearly with time from the knot of i to the knot of i+1, so the curve passes through
// every keyframe at its time and is C¹ in its parameter. The end segments use phantom
// points mirrored through the end keyframes (P₋₁ = 2P₀ − P₁), and a repeated position
// (the camera standing still) makes that segment constant. fov uses the uniform Catmull–Rom
// spline (cubic Hermite with tangents (f_{i+1} − f_{i−1})/2) clamped to [1°, 179°]; up is
// interpolated linearly and renormalised. Times outside the keyframes clamp to the ends.
//
// Light keyframes (time of day; `render --path` relights between frames, bake/relight.h): a
// keyframe may also set parameters of the scene's lights,
//   "lights": [{"light": 0, "direction": [x, y, z], "irradiance": [r, g, b]}, ...]
// "light" the index of the light in the scene, the other keys its parameters as a JSON scene
// names them (docs/scenes.md: position, direction, intensity or irradiance — a number is
// grey —, inner_angle and outer_angle in degrees, radius). A parameter is interpolated
// linearly in time between the keyframes that set it (a direction then renormalised), held
// before the first and after the last of them; what no keyframe sets keeps the scene's value.
#include <optional>
#include <string>
#include <vector>

#include "core/math.h"
#include "light/lights.h"
#include "scene/scene.h"

namespace pl {

/// One light's parameters set by a keyframe.
struct LightKeyframe {
  uint32_t light = 0;         ///< index into the scene's lights
  LightParameters parameters;  ///< by the JSON scene's names; angles in degrees
  std::string where;           ///< "<file>: keyframe 2: lights[0]", for errors
};

struct CameraKeyframe {
  double time = 0.0;  ///< seconds
  Vec3 eye{0.0f, 0.0f, 1.0f};
  Vec3 target{0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  std::optional<float> fovYDegrees;  ///< after loading: set on all keyframes or on none
  std::vector<LightKeyframe> lights;  ///< light keyframes (header comment)
};

/// Where the camera is at one instant.
struct CameraPose {
  Vec3 eye{0.0f, 0.0f, 1.0f};
  Vec3 target{0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  std::optional<float> fovYDegrees;  ///< unset: keep the base camera's
};

struct CameraPath {
  static constexpr double kDefaultFps = 30.0;
  static constexpr double kMaxFps = 1000.0;
  double fps = kDefaultFps;
  std::vector<CameraKeyframe> keyframes;  ///< at least one, strictly increasing times

  double startTime() const { return keyframes.front().time; }
  double duration() const { return keyframes.back().time - keyframes.front().time; }
  int frameCount() const;
  double frameTime(int frame) const { return startTime() + double(frame) / fps; }
  /// The interpolated pose at `time` (seconds; clamped to the keyframes' range).
  CameraPose at(double time) const;
  /// Whether some keyframe sets a light's parameters.
  bool animatesLights() const;
  /// `lights` (the scene's) with the light keyframes' parameters at `time`. Throws pl::Error
  /// naming the keyframe for a light index out of range, a parameter the light's type does not
  /// have, or a value out of range (lightProblem).
  void lightsAt(double time, std::vector<Light>& lights) const;
};

/// Parses the JSON text of a path file; `source` names it in error messages
/// ("<source>: keyframe 2: 'eye' must be an array of 3 numbers").
CameraPath parseCameraPath(const std::string& json, const std::string& source);
/// Reads and parses a path file (pl::Error naming the file for any problem).
CameraPath loadCameraPath(const std::string& path);
/// The path as JSON text in the file format above.
std::string cameraPathToJson(const CameraPath& path);
/// Writes the path file atomically (temporary file + rename).
void saveCameraPath(const std::string& path, const CameraPath& cameraPath);

/// `base` with the pose's eye, target, up and (if set) fov; the lens settings stay.
CameraDesc applyPose(CameraDesc base, const CameraPose& pose);

/// A path for demos: the eye swings around the camera's target by ±degrees about its up axis
/// and back (5 keyframes over `seconds`), at the camera's own fov.
CameraPath orbitPath(const CameraDesc& camera, double seconds = 4.0, double fps = CameraPath::kDefaultFps,
                     float degrees = 25.0f);

}  // namespace pl
