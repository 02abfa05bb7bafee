#pragma once
// Basic vector math for plenoptic, on top of GLM.
//
// Conventions used everywhere:
//  - Right-handed world space, units are whatever the scene file uses (metres for glTF,
//    millimetres for the built-in Cornell box). Radiometry does not care about the unit of
//    length as long as it is consistent (radiance is invariant; irradiance from a point light
//    scales as 1/d² in the scene's unit).
//  - Directions are unit vectors pointing *away* from the surface point (both wo and wi).
//  - Colours are linear Rec.709 RGB.
#include <glm/glm.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pl {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using DVec3 = glm::dvec3;
using Mat2 = glm::mat2;
using Mat3 = glm::mat3;
using Mat4 = glm::mat4;
using UVec3 = glm::uvec3;
using Rgb = glm::vec3;  ///< linear Rec.709 RGB (radiance in W·sr⁻¹·m⁻² unless stated)

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kTwoPi = 2.0f * kPi;
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();
inline constexpr double kPiD = 3.14159265358979323846;

/// Relative luminance of linear Rec.709 RGB (ITU-R BT.709 weights).
inline float luminance(const Rgb& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

inline float maxComponent(const Vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
inline bool isFinite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
inline bool isBlack(const Rgb& c) { return c.r == 0.0f && c.g == 0.0f && c.b == 0.0f; }

/// A ray o + t·d for t in (tMin, tMax). d need not be normalised for intersection, but every
/// renderer in plenoptic passes unit directions so that t is a distance.
struct Ray {
  Vec3 origin{0.0f};
  Vec3 direction{0.0f, 0.0f, 1.0f};
  float tMin = 0.0f;
  float tMax = kInfinity;
};

/// Orthonormal frame (s, t, n). Local coordinates have n = +z: a local direction's z is
/// cos θ with respect to the normal.
struct Frame {
  Vec3 s{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1};

  /// Builds a frame around unit normal n (Duff et al. 2017, "Building an Orthonormal Basis,
  /// Revisited"): continuous everywhere except the sign flip at n.z = 0.
  static Frame fromNormal(const Vec3& normal) {
    Frame f;
    f.n = normal;
    const float sign = std::copysign(1.0f, normal.z);
    const float a = -1.0f / (sign + normal.z);
    const float b = normal.x * normal.y * a;
    f.s = Vec3(1.0f + sign * normal.x * normal.x * a, sign * b, -sign * normal.x);
    f.t = Vec3(b, sign + normal.y * normal.y * a, -normal.y);
    return f;
  }
  Vec3 toLocal(const Vec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
  Vec3 toWorld(const Vec3& v) const { return v.x * s + v.y * t + v.z * n; }
};

/// Mirror reflection of w (pointing away from the surface) about normal n.
inline Vec3 reflect(const Vec3& w, const Vec3& n) { return 2.0f * glm::dot(w, n) * n - w; }

/// log2(x) for x > 0 within 0.0078 (exact at powers of two): the exponent of x plus
/// t + 0.347·t·(1 − t) for its mantissa 1 + t (the quadratic through log2's ends with the
/// least maximum error). 128 for +∞ (as for the largest floats); −∞ for 0, negative numbers and
/// NaN. Monotonic. The renderers' texture level of detail (lookup.h albedoTextureLod): libm's
/// log2f there was 3 % of a Sponza frame.
inline float approximateLog2(float x) {
  if (!(x > 0.0f)) return -std::numeric_limits<float>::infinity();
  const uint32_t bits = std::bit_cast<uint32_t>(x);
  const float t = std::bit_cast<float>((bits & 0x007fffffu) | 0x3f800000u) - 1.0f;  // mantissa − 1, in [0, 1)
  return float(int(bits >> 23) - 127) + t + 0.347f * t * (1.0f - t);
}

}  // namespace pl
