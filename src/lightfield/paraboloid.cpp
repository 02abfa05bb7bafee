// Paraboloid map of the hemisphere, its texel grid and exact texel solid angles.
#include "lightfield/paraboloid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>

namespace pl {

Vec2 directionToParaboloid(const Vec3& localDirection) {
  // Directions below the horizon (z < 0) have no place in the hemisphere's map: they are
  // projected onto the horizon, i.e. the unit circle, so a lookup just below a surface reads
  // the values of its horizon texels instead of diverging at z = −1.
  if (localDirection.z >= 0.0f) {
    const float inv = 1.0f / (1.0f + localDirection.z);
    return {localDirection.x * inv, localDirection.y * inv};
  }
  const float r = std::sqrt(localDirection.x * localDirection.x + localDirection.y * localDirection.y);
  if (r == 0.0f) return {0.0f, 0.0f};  // straight down: no meaningful horizon point
  return {localDirection.x / r, localDirection.y / r};
}

Vec3 paraboloidToDirection(Vec2 st) {
  const float r2 = st.x * st.x + st.y * st.y;
  const float inv = 1.0f / (1.0f + r2);
  return {2.0f * st.x * inv, 2.0f * st.y * inv, (1.0f - r2) * inv};
}

Vec2 paraboloidTexelCentre(uint32_t a, uint32_t b, uint32_t resolution) {
  const float size = 2.0f / float(resolution);
  return {-1.0f + (float(a) + 0.5f) * size, -1.0f + (float(b) + 0.5f) * size};
}

Vec3 paraboloidTexelDirection(uint32_t a, uint32_t b, uint32_t resolution) {
  Vec2 st = paraboloidTexelCentre(a, b, resolution);
  const float r = std::sqrt(st.x * st.x + st.y * st.y);
  if (r > kHorizonRadius) st *= kHorizonRadius / r;
  return paraboloidToDirection(st);
}

namespace {

// ∫ 4 / (a + t²)² dt = 4·[ t / (2a(a + t²)) + atan(t/√a) / (2a^{3/2}) ]  (a = 1 + s² > 0).
double jacobianAntiderivativeT(double a, double t) {
  const double sa = std::sqrt(a);
  return 4.0 * (t / (2.0 * a * (a + t * t)) + std::atan(t / sa) / (2.0 * a * sa));
}

// 8-point Gauss–Legendre nodes and weights on [−1, 1].
constexpr std::array<double, 8> kGlNodes = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                            -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                            0.7966664774136267,  0.9602898564975363};
constexpr std::array<double, 8> kGlWeights = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                              0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                              0.2223810344533745, 0.1012285362903763};

}  // namespace

double paraboloidTexelSolidAngle(uint32_t a, uint32_t b, uint32_t resolution) {
  const double size = 2.0 / double(resolution);
  const double s0 = -1.0 + a * size, s1 = s0 + size;
  const double t0 = -1.0 + b * size, t1 = t0 + size;
  // Outer variable s = sin φ, so that the disk's half-height √(1 − s²) = cos φ is smooth in φ;
  // the integrand of φ, ∫_{max(t0,−cos φ)}^{min(t1,cos φ)} J dt · cos φ, is then smooth except
  // where cos φ crosses |t0| or |t1|; we split the φ range there.
  const double phi0 = std::asin(std::clamp(s0, -1.0, 1.0));
  const double phi1 = std::asin(std::clamp(s1, -1.0, 1.0));
  std::vector<double> breaks = {phi0, phi1};
  for (double t : {t0, t1}) {
    const double c = std::acos(std::min(1.0, std::abs(t)));
    for (double p : {c, -c})
      if (p > phi0 && p < phi1) breaks.push_back(p);
  }
  std::sort(breaks.begin(), breaks.end());
  double total = 0.0;
  constexpr int kSubintervals = 4;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double lo = breaks[k], hi = breaks[k + 1];
    const double h = (hi - lo) / kSubintervals;
    for (int m = 0; m < kSubintervals; ++m) {
      const double mid = lo + (m + 0.5) * h;
      for (size_t q = 0; q < kGlNodes.size(); ++q) {
        const double phi = mid + 0.5 * h * kGlNodes[q];
        const double s = std::sin(phi), c = std::cos(phi);
        const double lower = std::max(t0, -c), upper = std::min(t1, c);
        if (upper <= lower) continue;
        const double aa = 1.0 + s * s;
        const double inner = jacobianAntiderivativeT(aa, upper) - jacobianAntiderivativeT(aa, lower);
        total += 0.5 * h * kGlWeights[q] * inner * c;
      }
    }
  }
  return total;
}

const std::vector<float>& paraboloidTexelSolidAngles(uint32_t resolution) {
  static std::mutex mutex;
  static std::map<uint32_t, std::vector<float>> cache;  // node-based: references stay valid
  std::lock_guard<std::mutex> lock(mutex);
  auto [it, inserted] = cache.try_emplace(resolution);
  if (inserted) {
    it->second.resize(size_t(resolution) * resolution);
    for (uint32_t b = 0; b < resolution; ++b)
      for (uint32_t a = 0; a < resolution; ++a)
        it->second[a + size_t(b) * resolution] = float(paraboloidTexelSolidAngle(a, b, resolution));
  }
  return it->second;
}

}  // namespace pl
