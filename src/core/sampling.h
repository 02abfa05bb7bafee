#pragma once
// Warping functions from the unit square to common domains, each with its pdf.
// All pdfs are with respect to solid angle (directions) or area (disk, triangle).
#include "core/math.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace pl {

/// Concentric map (Shirley–Chiu) of u ∈ [0,1)² to the unit disk; pdf = 1/π per unit area.
inline Vec2 sampleConcentricDisk(Vec2 u) {
  const Vec2 o = 2.0f * u - Vec2(1.0f);
  if (o.x == 0.0f && o.y == 0.0f) return Vec2(0.0f);
  float r, theta;
  if (std::abs(o.x) > std::abs(o.y)) {
    r = o.x;
    theta = (kPi / 4.0f) * (o.y / o.x);
  } else {
    r = o.y;
    theta = (kPi / 2.0f) - (kPi / 4.0f) * (o.x / o.y);
  }
  return r * Vec2(std::cos(theta), std::sin(theta));
}

/// The inverse of sampleConcentricDisk: the u ∈ [0,1]² that maps to disk point d (|d| ≤ 1),
/// so the inverse of sampleCosineHemisphere too for a direction's (x, y).
inline Vec2 inverseConcentricDisk(Vec2 d) {
  const float r = std::sqrt(d.x * d.x + d.y * d.y);
  float phi = std::atan2(d.y, d.x);
  if (phi < -kPi / 4.0f) phi += 2.0f * kPi;  // phi in [−π/4, 7π/4)
  float a, b;
  if (phi < kPi / 4.0f) {  // the right wedge: r = a > 0
    a = r;
    b = phi * a / (kPi / 4.0f);
  } else if (phi < 3.0f * kPi / 4.0f) {  // top: r = b > 0
    b = r;
    a = -(phi - kPi / 2.0f) * b / (kPi / 4.0f);
  } else if (phi < 5.0f * kPi / 4.0f) {  // left: a = −r
    a = -r;
    b = (phi - kPi) * a / (kPi / 4.0f);
  } else {  // bottom: b = −r
    b = -r;
    a = -(phi - 3.0f * kPi / 2.0f) * b / (kPi / 4.0f);
  }
  return Vec2(std::clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), std::clamp(0.5f * (b + 1.0f), 0.0f, 1.0f));
}

/// Cosine-weighted hemisphere around +z; pdf = cos θ / π.
inline Vec3 sampleCosineHemisphere(Vec2 u) {
  const Vec2 d = sampleConcentricDisk(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}
inline float cosineHemispherePdf(float cosTheta) { return cosTheta > 0.0f ? cosTheta * kInvPi : 0.0f; }

/// Uniform direction on the unit sphere; pdf = 1/(4π).
inline Vec3 sampleUniformSphere(Vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = kTwoPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float kUniformSpherePdf = 1.0f / (4.0f * kPi);

/// Uniform direction on the +z hemisphere; pdf = 1/(2π).
inline Vec3 sampleUniformHemisphere(Vec2 u) {
  const float z = u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = kTwoPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float kUniformHemispherePdf = 1.0f / (2.0f * kPi);

/// Uniform point on a triangle as barycentrics (b1, b2) (Heitz 2019 low-distortion map);
/// pdf = 1/area.
inline Vec2 sampleUniformTriangle(Vec2 u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2.0f;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.0f;
    b0 = u.x - b1;
  }
  return {b0, b1};
}

/// Power heuristic (β = 2) for multiple importance sampling.
inline float powerHeuristic(float pdfA, float pdfB) {
  const float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0.0f ? a / (a + b) : 0.0f;
}

/// A piecewise-constant 1D distribution over n bins, sampled by inverting its CDF.
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::span<const float> weights) : pdf_(weights.begin(), weights.end()) {
    cdf_.resize(pdf_.size() + 1, 0.0);
    for (size_t i = 0; i < pdf_.size(); ++i) cdf_[i + 1] = cdf_[i] + std::max(0.0f, pdf_[i]);
    total_ = cdf_.back();
    for (size_t i = 0; i < pdf_.size(); ++i)
      pdf_[i] = total_ > 0.0 ? static_cast<float>(std::max(0.0f, pdf_[i]) / total_) : 0.0f;
    if (total_ > 0.0)
      for (double& c : cdf_) c /= total_;
  }
  size_t size() const { return pdf_.size(); }
  double total() const { return total_; }
  /// Probability of bin i (sums to 1 over bins).
  float probability(size_t i) const { return pdf_[i]; }
  /// The normalised cumulative sums sample() searches: size()+1 values from 0 to 1 (all 0 when
  /// the weights are), in double (the GPU renderer's copy searches the same, gpu/gpu_lights.h).
  std::span<const double> cdf() const { return cdf_; }
  /// Samples a bin; returns its index and rescales u to [0,1) within the bin in *remapped.
  size_t sample(float u, float* remapped = nullptr) const {
    const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), static_cast<double>(u));
    size_t i = static_cast<size_t>(std::max<ptrdiff_t>(0, (it - cdf_.begin()) - 1));
    i = std::min(i, pdf_.size() - 1);
    if (remapped) {
      const double width = cdf_[i + 1] - cdf_[i];
      *remapped = width > 0.0 ? static_cast<float>(std::min((u - cdf_[i]) / width, 0.99999994)) : 0.0f;
    }
    return i;
  }

 private:
  std::vector<float> pdf_;
  std::vector<double> cdf_;
  double total_ = 0.0;
};

}  // namespace pl
