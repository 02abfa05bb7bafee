// The environment as a light: radiance lookup and luminance importance sampling (env.h).
#include "core/error.h"
#include "env/env.h"

#include <algorithm>
#include <cmath>

namespace pl {

EnvironmentMap::EnvironmentMap(LatLongMap map, float scale, float rotationDegrees)
    : map_(std::move(map)), scale_(scale), rotationDegrees_(rotationDegrees) {
  if (map_.height() < 1 || map_.width() != 2 * map_.height())
    fail("environment map must be a 2:1 lat-long image (got {}×{})", map_.width(), map_.height());
  if (!std::isfinite(scale) || scale < 0.0f) fail("environment scale must be finite and ≥ 0 (got {})", scale);
  const double rot = double(rotationDegrees) * kPiD / 180.0;
  cosRot_ = float(std::cos(rot));
  sinRot_ = float(std::sin(rot));

  const int w = map_.width(), h = map_.height();
  // Luminance, with non-finite or negative texels refused: they would poison every estimator.
  std::vector<float> lum(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Rgb c = map_.image.at(x, y);
      if (!isFinite(c) || c.r < 0.0f || c.g < 0.0f || c.b < 0.0f)
        fail("environment map texel ({}, {}) is negative or not finite ({}, {}, {})", x, y, c.r, c.g, c.b);
      lum[size_t(y) * w + x] = luminance(c);
    }
  // Mean of the bilinear reconstruction over each texel: separable (1/8, 3/4, 1/8) filter
  // (wrapping in x, clamping in y like LatLongMap::lookup). Positive wherever the bilinear
  // radiance is positive anywhere inside the texel.
  auto at = [&](int x, int y) { return lum[size_t(std::clamp(y, 0, h - 1)) * w + size_t((x + w) % w)]; };
  std::vector<float> rowWeights(static_cast<size_t>(h));
  columns_.reserve(size_t(h));
  std::vector<float> weights(static_cast<size_t>(w));
  double total = 0.0;
  for (int y = 0; y < h; ++y) {
    const double dOmega = map_.texelSolidAngle(y);
    double rowSum = 0.0;
    for (int x = 0; x < w; ++x) {
      double m = 0.0;
      for (int j = -1; j <= 1; ++j) {
        const double wy = j == 0 ? 0.75 : 0.125;
        for (int i = -1; i <= 1; ++i) m += wy * (i == 0 ? 0.75 : 0.125) * at(x + i, y + j);
      }
      weights[size_t(x)] = float(m * dOmega);
      rowSum += m * dOmega;
      total += double(lum[size_t(y) * w + x]) * dOmega;
    }
    columns_.emplace_back(weights);
    rowWeights[size_t(y)] = float(rowSum);
  }
  rows_ = Distribution1D(rowWeights);
  integratedLuminance_ = total * scale_;
}

Vec3 EnvironmentMap::toMap(const Vec3& d) const {
  return {cosRot_ * d.x - sinRot_ * d.z, d.y, sinRot_ * d.x + cosRot_ * d.z};
}
Vec3 EnvironmentMap::toWorld(const Vec3& m) const {
  return {cosRot_ * m.x + sinRot_ * m.z, m.y, -sinRot_ * m.x + cosRot_ * m.z};
}

Rgb EnvironmentMap::radiance(const Vec3& dir) const { return scale_ * map_.lookup(toMap(dir)); }

EnvironmentSample EnvironmentMap::sample(Vec2 u) const {
  EnvironmentSample s;
  if (!(rows_.total() > 0.0)) return s;  // black map: nothing to sample
  const int w = map_.width(), h = map_.height();
  float ry = 0.0f, rx = 0.0f;
  const size_t y = rows_.sample(u.y, &ry);
  const size_t x = columns_[y].sample(u.x, &rx);
  // Density in (u, v) is constant per texel: P(row)·P(column|row)·W·H.
  // The density of this procedure at the continuous point is p(u,v)/(2π² sin θ); pdf() of
  // the returned (float) direction is evaluated instead, so that sample() and pdf() agree
  // exactly even when rounding moves a direction onto a neighbouring texel (a set of
  // measure ~1e-7 of the texel, negligible bias) — MIS weights need the two to match.
  const Vec3 mapDir = LatLongMap::direction((double(x) + rx) / w, (double(y) + ry) / h);
  s.direction = glm::normalize(toWorld(mapDir));
  s.pdf = pdf(s.direction);
  s.radiance = radiance(s.direction);
  return s;
}

float EnvironmentMap::pdf(const Vec3& dir) const {
  if (!(rows_.total() > 0.0)) return 0.0f;
  const Vec3 m = toMap(dir);
  const Vec2 st = LatLongMap::uv(m);
  const int w = map_.width(), h = map_.height();
  const int x = std::clamp(int(st.x * float(w)), 0, w - 1);
  const int y = std::clamp(int(st.y * float(h)), 0, h - 1);
  const double sinTheta = std::sqrt(std::max(0.0, 1.0 - double(m.y) * double(m.y)));
  if (!(sinTheta > 0.0)) return 0.0f;
  const double pdfUv = double(rows_.probability(size_t(y))) * double(columns_[size_t(y)].probability(size_t(x))) *
                       double(w) * h;
  return float(pdfUv / (2.0 * kPiD * kPiD * sinTheta));
}

// ─── Constant + map ────────────────────────────────────────────────────────────────────────

std::shared_ptr<const EnvironmentMap> loadEnvironmentMap(const std::string& path, float scale, float rotationDegrees) {
  EnvImage env = loadEnvironment(path);
  LatLongMap ll = std::holds_alternative<LatLongMap>(env) ? std::move(std::get<LatLongMap>(env))
                                                           : toLatLong(env, equivalentLatLongHeight(env));
  try {
    return std::make_shared<const EnvironmentMap>(std::move(ll), scale, rotationDegrees);
  } catch (const Error& e) {
    fail("{}: {}", path, e.what());
  }
}

}  // namespace pl
