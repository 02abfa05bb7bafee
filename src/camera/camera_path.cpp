// Camera paths (see camera_path.h).
#include "camera/camera_path.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/file_io.h"

namespace pl {
namespace {

using Json = nlohmann::json;

Vec3 readVec3(const Json& value, const std::string& where, const char* key) {
  if (!value.is_array() || value.size() != 3)
    fail("{}: '{}' must be an array of 3 numbers, got {}", where, key, value.dump());
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    if (!value[size_t(i)].is_number()) fail("{}: '{}' must be an array of 3 numbers, got {}", where, key, value.dump());
    v[i] = value[size_t(i)].get<float>();
    if (!std::isfinite(v[i])) fail("{}: '{}' has a non-finite component", where, key);
  }
  return v;
}

double readNumber(const Json& value, const std::string& where, const char* key) {
  if (!value.is_number()) fail("{}: '{}' must be a number, got {}", where, key, value.dump());
  const double v = value.get<double>();
  if (!std::isfinite(v)) fail("{}: '{}' must be finite", where, key);
  return v;
}

/// Centripetal Catmull–Rom (Barry–Goldman pyramid) on the segment p1 → p2 at u ∈ [0, 1].
Vec3 centripetalCatmullRom(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, float u) {
  const float d12 = glm::length(p2 - p1);
  if (!(d12 > 0.0f)) return p1;  // standing still
  // A phantom neighbour coinciding with its end point would give a zero knot interval:
  // mirror the segment instead (the same rule as at the ends of the path).
  if (!(glm::length(p1 - p0) > 1e-6f * d12)) p0 = 2.0f * p1 - p2;
  if (!(glm::length(p3 - p2) > 1e-6f * d12)) p3 = 2.0f * p2 - p1;
  // Knots t_{i+1} = t_i + |P_{i+1} − P_i|^α with α = ½.
  const float t0 = 0.0f;
  const float t1 = t0 + std::sqrt(glm::length(p1 - p0));
  const float t2 = t1 + std::sqrt(d12);
  const float t3 = t2 + std::sqrt(glm::length(p3 - p2));
  const float t = t1 + u * (t2 - t1);
  const Vec3 a1 = ((t1 - t) * p0 + (t - t0) * p1) / (t1 - t0);
  const Vec3 a2 = ((t2 - t) * p1 + (t - t1) * p2) / (t2 - t1);
  const Vec3 a3 = ((t3 - t) * p2 + (t - t2) * p3) / (t3 - t2);
  const Vec3 b1 = ((t2 - t) * a1 + (t - t0) * a2) / (t2 - t0);
  const Vec3 b2 = ((t3 - t) * a2 + (t - t1) * a3) / (t3 - t1);
  return ((t2 - t) * b1 + (t - t1) * b2) / (t2 - t1);
}

/// Uniform Catmull–Rom (cubic Hermite, tangents (f2 − f0)/2 and (f3 − f1)/2) at u ∈ [0, 1].
float uniformCatmullRom(float f0, float f1, float f2, float f3, float u) {
  const float m1 = 0.5f * (f2 - f0), m2 = 0.5f * (f3 - f1);
  const float u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * f1 + (u3 - 2 * u2 + u) * m1 + (-2 * u3 + 3 * u2) * f2 + (u3 - u2) * m2;
}

}  // namespace

int CameraPath::frameCount() const {
  // The small slack absorbs rounding of durations like 2.0 s · 30 fps = 59.999999….
  return int(std::floor(duration() * fps + 1e-6)) + 1;
}

CameraPose CameraPath::at(double time) const {
  const size_t count = keyframes.size();
  CameraPose pose;
  if (count == 1 || time <= keyframes.front().time) {
    const CameraKeyframe& k = keyframes.front();
    return CameraPose{k.eye, k.target, k.up, k.fovYDegrees};
  }
  if (time >= keyframes.back().time) {
    const CameraKeyframe& k = keyframes.back();
    return CameraPose{k.eye, k.target, k.up, k.fovYDegrees};
  }
  // Segment i: keyframes[i].time ≤ time < keyframes[i+1].time.
  const auto next = std::upper_bound(keyframes.begin(), keyframes.end(), time,
                                     [](double t, const CameraKeyframe& k) { return t < k.time; });
  const size_t i = size_t(next - keyframes.begin()) - 1;
  const CameraKeyframe& k1 = keyframes[i];
  const CameraKeyframe& k2 = keyframes[i + 1];
  const float u = float((time - k1.time) / (k2.time - k1.time));
  const bool hasPrevious = i > 0, hasNext = i + 2 < count;
  // Phantom end points mirrored through the end keyframes.
  const auto neighbours = [&](auto member, auto& p0, auto& p3) {
    p0 = hasPrevious ? keyframes[i - 1].*member : 2.0f * (k1.*member) - k2.*member;
    p3 = hasNext ? keyframes[i + 2].*member : 2.0f * (k2.*member) - k1.*member;
  };
  Vec3 p0, p3;
  neighbours(&CameraKeyframe::eye, p0, p3);
  pose.eye = centripetalCatmullRom(p0, k1.eye, k2.eye, p3, u);
  neighbours(&CameraKeyframe::target, p0, p3);
  pose.target = centripetalCatmullRom(p0, k1.target, k2.target, p3, u);
  const Vec3 up = (1.0f - u) * k1.up + u * k2.up;
  pose.up = glm::length(up) > 1e-6f ? glm::normalize(up) : k1.up;
  if (k1.fovYDegrees && k2.fovYDegrees) {
    const float f1 = *k1.fovYDegrees, f2 = *k2.fovYDegrees;
    const float f0 = hasPrevious ? *keyframes[i - 1].fovYDegrees : 2.0f * f1 - f2;
    const float f3 = hasNext ? *keyframes[i + 2].fovYDegrees : 2.0f * f2 - f1;
    pose.fovYDegrees = std::clamp(uniformCatmullRom(f0, f1, f2, f3, u), 1.0f, 179.0f);
  }
  return pose;
}

namespace {

/// A keyframe's "lights": an array of {"light": index, parameter: number or [x, y, z], ...}.
std::vector<LightKeyframe> readLightKeyframes(const Json& value, const std::string& where) {
  if (!value.is_array()) fail("{}: 'lights' must be an array of objects", where);
  std::vector<LightKeyframe> out;
  for (size_t j = 0; j < value.size(); ++j) {
    LightKeyframe light;
    light.where = fmt::format("{}: lights[{}]", where, j);
    const Json& entry = value[j];
    if (!entry.is_object() || !entry.contains("light"))
      fail("{}: expected an object with \"light\" (the light's index)", light.where);
    for (const auto& [key, field] : entry.items()) {
      if (key == "light") {
        const double index = readNumber(field, light.where, "light");
        if (!(index >= 0.0 && index < 65536.0 && index == std::floor(index)))
          fail("{}: 'light' must be a light's index (0, 1, …), got {}", light.where, field.dump());
        light.light = uint32_t(index);
      } else if (field.is_array()) {
        light.parameters[key] = readVec3(field, light.where, key.c_str());
      } else {
        light.parameters[key] = float(readNumber(field, light.where, key.c_str()));
      }
    }
    out.push_back(std::move(light));
  }
  return out;
}

/// Linear interpolation; a number beside three numbers (a grey emission beside a colour) is
/// taken as three equal ones.
LightParameterValue lerpParameter(const LightParameterValue& a, const LightParameterValue& b, float t) {
  if (std::holds_alternative<float>(a) && std::holds_alternative<float>(b))
    return std::get<float>(a) + (std::get<float>(b) - std::get<float>(a)) * t;
  auto vec = [](const LightParameterValue& v) { return std::holds_alternative<float>(v) ? Vec3(std::get<float>(v)) : std::get<Vec3>(v); };
  return vec(a) + (vec(b) - vec(a)) * t;
}

}  // namespace

bool CameraPath::animatesLights() const {
  return std::any_of(keyframes.begin(), keyframes.end(), [](const CameraKeyframe& k) { return !k.lights.empty(); });
}

void CameraPath::lightsAt(double time, std::vector<Light>& lights) const {
  // Per (light, parameter): the keyframes that set it, in time order.
  struct Key {
    double time;
    const LightParameterValue* value;
    const std::string* where;
  };
  std::map<std::pair<uint32_t, std::string>, std::vector<Key>> tracks;
  for (const CameraKeyframe& k : keyframes)
    for (const LightKeyframe& l : k.lights) {
      if (l.light >= lights.size()) fail("{}: light {} does not exist (the scene has {})", l.where, l.light, lights.size());
      for (const auto& [name, value] : l.parameters) tracks[{l.light, name}].push_back({k.time, &value, &l.where});
    }
  for (const auto& [id, keys] : tracks) {
    const auto next = std::upper_bound(keys.begin(), keys.end(), time, [](double t, const Key& k) { return t < k.time; });
    LightParameterValue value = *keys.front().value;
    if (next == keys.end()) {
      value = *keys.back().value;
    } else if (next != keys.begin()) {
      const Key& a = *(next - 1);
      value = lerpParameter(*a.value, *next->value, float((time - a.time) / (next->time - a.time)));
    }
    Light& light = lights[id.first];
    const std::string& where = *keys.front().where;
    setLightParameters(light, {{id.second, value}}, where, {.anglesInDegrees = true});
    if (const std::string problem = lightProblem(light); !problem.empty())
      fail("{}: at time {}: {} light {} {}", where, time, lightTypeName(light), id.first, problem);
    const Rgb emission = lightEmission(light);
    if (emission.r < 0.0f || emission.g < 0.0f || emission.b < 0.0f)
      fail("{}: at time {}: light {}'s {} must not be negative", where, time, id.first, lightEmissionName(light));
    normaliseLightDirections(light);
    prepareLight(light);
  }
}

CameraPath parseCameraPath(const std::string& text, const std::string& source) {
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::exception& e) {  // parse_error, or out_of_range for a number beyond a double (1e400)
    fail("{}: not valid JSON: {}", source, e.what());
  }
  if (!root.is_object()) fail("{}: expected a JSON object with \"keyframes\"", source);
  CameraPath path;
  for (const auto& [key, value] : root.items()) {
    if (key == "fps") {
      path.fps = readNumber(value, source, "fps");
      if (!(path.fps > 0.0) || path.fps > CameraPath::kMaxFps)
        fail("{}: 'fps' must be in (0, {}], got {}", source, CameraPath::kMaxFps, path.fps);
    } else if (key != "keyframes") {
      fail("{}: unknown key '{}' (expected \"fps\" and \"keyframes\")", source, key);
    }
  }
  if (!root.contains("keyframes")) fail("{}: missing \"keyframes\"", source);
  const Json& keys = root["keyframes"];
  if (!keys.is_array() || keys.empty()) fail("{}: \"keyframes\" must be a non-empty array", source);
  for (size_t i = 0; i < keys.size(); ++i) {
    const std::string where = fmt::format("{}: keyframe {}", source, i);
    const Json& k = keys[i];
    if (!k.is_object()) fail("{}: expected an object, got {}", where, k.dump());
    CameraKeyframe frame;
    bool hasTime = false, hasEye = false, hasTarget = false;
    for (const auto& [key, value] : k.items()) {
      if (key == "time") {
        frame.time = readNumber(value, where, "time");
        hasTime = true;
      } else if (key == "eye") {
        frame.eye = readVec3(value, where, "eye");
        hasEye = true;
      } else if (key == "target") {
        frame.target = readVec3(value, where, "target");
        hasTarget = true;
      } else if (key == "up") {
        frame.up = readVec3(value, where, "up");
        if (!(glm::length(frame.up) > 0.0f)) fail("{}: 'up' must not be zero", where);
        frame.up = glm::normalize(frame.up);
      } else if (key == "fov") {
        const double fov = readNumber(value, where, "fov");
        if (!(fov > 0.0 && fov < 180.0)) fail("{}: 'fov' must be in (0, 180) degrees, got {}", where, fov);
        frame.fovYDegrees = float(fov);
      } else if (key == "lights") {
        frame.lights = readLightKeyframes(value, where);
      } else {
        fail("{}: unknown key '{}' (expected time, eye, target, fov, up, lights)", where, key);
      }
    }
    if (!hasTime) fail("{}: missing 'time'", where);
    if (!hasEye) fail("{}: missing 'eye'", where);
    if (!hasTarget) fail("{}: missing 'target'", where);
    if (!(glm::length(frame.target - frame.eye) > 0.0f)) fail("{}: 'eye' and 'target' coincide", where);
    const Vec3 forward = glm::normalize(frame.target - frame.eye);
    if (!(glm::length(glm::cross(forward, frame.up)) > 1e-4f)) fail("{}: 'up' is parallel to the view direction", where);
    if (!path.keyframes.empty() && !(frame.time > path.keyframes.back().time))
      fail("{}: time {} is not after the previous keyframe's {} (times must increase)", where, frame.time,
           path.keyframes.back().time);
    path.keyframes.push_back(frame);
  }
  if (path.duration() * path.fps > 1e7) fail("{}: the path has more than 10 million frames", source);
  // Missing fovs: carry the previous one forward, the first given one backward.
  std::optional<float> fov;
  for (const CameraKeyframe& k : path.keyframes)
    if (k.fovYDegrees) {
      fov = k.fovYDegrees;
      break;
    }
  for (CameraKeyframe& k : path.keyframes) {
    if (k.fovYDegrees) fov = k.fovYDegrees;
    k.fovYDegrees = fov;
  }
  return path;
}

CameraPath loadCameraPath(const std::string& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "{}: cannot open camera path file", path);
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) fail("{}: read error", path);
  return parseCameraPath(text.str(), path);
}

std::string cameraPathToJson(const CameraPath& path) {
  Json root;
  root["fps"] = path.fps;
  Json keys = Json::array();
  for (const CameraKeyframe& k : path.keyframes) {
    Json key;
    key["time"] = k.time;
    key["eye"] = {k.eye.x, k.eye.y, k.eye.z};
    key["target"] = {k.target.x, k.target.y, k.target.z};
    key["up"] = {k.up.x, k.up.y, k.up.z};
    if (k.fovYDegrees) key["fov"] = *k.fovYDegrees;
    for (const LightKeyframe& l : k.lights) {
      Json light;
      light["light"] = l.light;
      for (const auto& [name, value] : l.parameters) {
        if (const float* f = std::get_if<float>(&value)) light[name] = *f;
        else light[name] = {std::get<Vec3>(value).x, std::get<Vec3>(value).y, std::get<Vec3>(value).z};
      }
      key["lights"].push_back(light);
    }
    keys.push_back(key);
  }
  root["keyframes"] = keys;
  return root.dump(2) + "\n";
}

void saveCameraPath(const std::string& path, const CameraPath& cameraPath) {
  writeFileAtomically(path, cameraPathToJson(cameraPath));
}

CameraDesc applyPose(CameraDesc base, const CameraPose& pose) {
  base.eye = pose.eye;
  base.target = pose.target;
  base.up = pose.up;
  if (pose.fovYDegrees) {
    base.fovYDegrees = *pose.fovYDegrees;
    base.focalLengthMm = 0.0f;  // a new fov implies the focal length that gives it
  }
  return base;
}

CameraPath orbitPath(const CameraDesc& camera, double seconds, double fps, float degrees) {
  if (!(seconds > 0.0) || !(fps > 0.0)) fail("orbit path: duration and fps must be positive");
  const Vec3 up = glm::normalize(camera.up);
  const Vec3 offset = camera.eye - camera.target;
  CameraPath path;
  path.fps = fps;
  // Angles of the 5 keyframes: 0, +a, 0, −a, 0 (a smooth swing with Catmull–Rom).
  const float angles[5] = {0.0f, degrees, 0.0f, -degrees, 0.0f};
  for (int k = 0; k < 5; ++k) {
    const float a = angles[k] * kPi / 180.0f;
    // Rodrigues' rotation of the eye offset about the up axis through the target.
    const Vec3 rotated = offset * std::cos(a) + glm::cross(up, offset) * std::sin(a) + up * glm::dot(up, offset) * (1.0f - std::cos(a));
    path.keyframes.push_back(CameraKeyframe{seconds * double(k) / 4.0, camera.target + rotated, camera.target, up, camera.fovYDegrees});
  }
  return path;
}

}  // namespace pl
