// Lat-long and cube layouts: directions, exact texel solid angles, bilinear lookup and
// resampling between layouts. Conventions and diagrams: env.h.
#include "core/error.h"
#include "core/parallel.h"
#include "env/env.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace pl {

// ─── Lat-long ──────────────────────────────────────────────────────────────────────────────

DVec3 LatLongMap::directionD(double u, double v) {
  const double theta = kPiD * v;
  const double phi = 2.0 * kPiD * (u - 0.5);
  const double sinTheta = std::sin(theta);
  return {sinTheta * std::cos(phi), std::cos(theta), sinTheta * std::sin(phi)};
}

Vec3 LatLongMap::direction(double u, double v) { return Vec3(directionD(u, v)); }

Vec2 LatLongMap::uv(const Vec3& dir) {
  // In double: acos loses precision near the poles in float.
  const double phi = std::atan2(double(dir.z), double(dir.x));  // (−π, π]
  double u = phi / (2.0 * kPiD) + 0.5;
  if (u >= 1.0) u -= 1.0;
  if (u < 0.0) u += 1.0;
  const double len = std::sqrt(double(dir.x) * dir.x + double(dir.y) * dir.y + double(dir.z) * dir.z);
  const double v = std::acos(std::clamp(double(dir.y) / len, -1.0, 1.0)) / kPiD;
  return {std::min(float(u), 0x1.fffffep-1f), float(v)};
}

double LatLongMap::texelSolidAngle(int y) const {
  const double h = height(), w = width();
  const double theta0 = kPiD * y / h, theta1 = kPiD * (y + 1) / h;
  return (2.0 * kPiD / w) * (std::cos(theta0) - std::cos(theta1));
}

Rgb LatLongMap::lookup(const Vec3& dir) const {
  const Vec2 st = uv(dir);
  const int w = width(), h = height();
  // Texel centres sit at (x + ½, y + ½): shift by ½ to get the lower-left bilinear corner.
  const float fx = st.x * float(w) - 0.5f, fy = st.y * float(h) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  int x0 = int(x0f) % w;
  if (x0 < 0) x0 += w;
  const int x1 = (x0 + 1) % w;
  const int y0 = std::clamp(int(y0f), 0, h - 1), y1 = std::clamp(int(y0f) + 1, 0, h - 1);
  const Rgb top = (1.0f - ax) * image.at(x0, y0) + ax * image.at(x1, y0);
  const Rgb bottom = (1.0f - ax) * image.at(x0, y1) + ax * image.at(x1, y1);
  return (1.0f - ay) * top + ay * bottom;
}

// ─── Cube ──────────────────────────────────────────────────────────────────────────────────

CubeMap::CubeMap(int n) : size(n) {
  for (Image& f : faces) f = Image(n, n);
}

namespace {

// OpenGL table 8.19 inverted: the cube-space direction through (sc, tc) of a face.
DVec3 cubeSpaceDirection(int face, double sc, double tc) {
  switch (face) {
    case 0: return {1.0, -tc, -sc};
    case 1: return {-1.0, -tc, sc};
    case 2: return {sc, 1.0, tc};
    case 3: return {sc, -1.0, -tc};
    case 4: return {sc, -tc, 1.0};
    default: return {-sc, -tc, -1.0};
  }
}

// The world ↔ cube-space handedness flip (env.h): c = (−d.x, d.y, d.z); its own inverse.
DVec3 flipX(const DVec3& d) { return {-d.x, d.y, d.z}; }

// Integral of (1 + x² + y²)^(−3/2) over [0,x]×[0,y]: the solid angle subtended by that
// rectangle of the plane z = 1 (sign follows x·y).
double areaElement(double x, double y) { return std::atan2(x * y, std::sqrt(x * x + y * y + 1.0)); }

}  // namespace

DVec3 CubeMap::direction(int face, double sc, double tc) {
  return glm::normalize(flipX(cubeSpaceDirection(face, sc, tc)));
}

CubeCoords CubeMap::coords(const DVec3& worldDir) {
  const DVec3 c = flipX(worldDir);
  const double ax = std::abs(c.x), ay = std::abs(c.y), az = std::abs(c.z);
  CubeCoords r;
  double sc, tc, ma;
  if (ax >= ay && ax >= az) {
    ma = ax;
    if (c.x > 0) { r.face = 0; sc = -c.z; tc = -c.y; }
    else { r.face = 1; sc = c.z; tc = -c.y; }
  } else if (ay >= az) {
    ma = ay;
    if (c.y > 0) { r.face = 2; sc = c.x; tc = c.z; }
    else { r.face = 3; sc = c.x; tc = -c.z; }
  } else {
    ma = az;
    if (c.z > 0) { r.face = 4; sc = c.x; tc = -c.y; }
    else { r.face = 5; sc = -c.x; tc = -c.y; }
  }
  if (!(ma > 0.0)) return r;  // zero or NaN direction: face centre of +X, never a crash
  r.s = std::clamp(0.5 * (sc / ma + 1.0), 0.0, 1.0);
  r.t = std::clamp(0.5 * (tc / ma + 1.0), 0.0, 1.0);
  return r;
}

double CubeMap::texelSolidAngle(int n, int x, int y) {
  const double x0 = 2.0 * x / n - 1.0, x1 = 2.0 * (x + 1) / n - 1.0;
  const double y0 = 2.0 * y / n - 1.0, y1 = 2.0 * (y + 1) / n - 1.0;
  return areaElement(x1, y1) - areaElement(x0, y1) - areaElement(x1, y0) + areaElement(x0, y0);
}

Rgb CubeMap::fetch(int face, int x, int y) const {
  if (x >= 0 && x < size && y >= 0 && y < size) return faces[size_t(face)].at(x, y);
  // Off the face: extend the face plane to the texel centre, and take the texel of the cube
  // that direction falls in (the adjacent face, or for a corner one of the two neighbours).
  const double sc = 2.0 * (x + 0.5) / size - 1.0, tc = 2.0 * (y + 0.5) / size - 1.0;
  const CubeCoords cc = coords(direction(face, sc, tc));
  const int nx = std::clamp(int(cc.s * size), 0, size - 1);
  const int ny = std::clamp(int(cc.t * size), 0, size - 1);
  return faces[size_t(cc.face)].at(nx, ny);
}

Rgb CubeMap::lookup(const Vec3& dir) const {
  const CubeCoords cc = coords(DVec3(dir));
  const double fx = cc.s * size - 0.5, fy = cc.t * size - 0.5;
  const double x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = float(fx - x0f), ay = float(fy - y0f);
  const int x0 = int(x0f), y0 = int(y0f);
  const Rgb top = (1.0f - ax) * fetch(cc.face, x0, y0) + ax * fetch(cc.face, x0 + 1, y0);
  const Rgb bottom = (1.0f - ax) * fetch(cc.face, x0, y0 + 1) + ax * fetch(cc.face, x0 + 1, y0 + 1);
  return (1.0f - ay) * top + ay * bottom;
}

// ─── Either layout ─────────────────────────────────────────────────────────────────────────

Rgb lookup(const EnvImage& env, const Vec3& dir) {
  return std::visit([&](const auto& m) { return m.lookup(dir); }, env);
}

std::string describe(const EnvImage& env) {
  if (const auto* ll = std::get_if<LatLongMap>(&env)) return fmt::format("lat-long {}×{}", ll->width(), ll->height());
  const auto& cube = std::get<CubeMap>(env);
  return fmt::format("cube 6×{}²", cube.size);
}

SphereTexels sphereTexels(const EnvImage& env) {
  SphereTexels t;
  if (const auto* ll = std::get_if<LatLongMap>(&env)) {
    const int w = ll->width(), h = ll->height();
    t.direction.reserve(size_t(w) * h);
    t.radiance.reserve(size_t(w) * h);
    t.solidAngle.reserve(size_t(w) * h);
    for (int y = 0; y < h; ++y) {
      const double dOmega = ll->texelSolidAngle(y);
      for (int x = 0; x < w; ++x) {
        t.direction.push_back(LatLongMap::directionD((x + 0.5) / w, (y + 0.5) / h));
        t.radiance.push_back(ll->image.at(x, y));
        t.solidAngle.push_back(dOmega);
      }
    }
    return t;
  }
  const auto& cube = std::get<CubeMap>(env);
  const int n = cube.size;
  std::vector<double> faceSolidAngle(size_t(n) * n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) faceSolidAngle[size_t(y) * n + x] = CubeMap::texelSolidAngle(n, x, y);
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        t.direction.push_back(CubeMap::direction(f, 2.0 * (x + 0.5) / n - 1.0, 2.0 * (y + 0.5) / n - 1.0));
        t.radiance.push_back(cube.faces[size_t(f)].at(x, y));
        t.solidAngle.push_back(faceSolidAngle[size_t(y) * n + x]);
      }
  return t;
}

// ─── Filling and resampling ────────────────────────────────────────────────────────────────

EnvImage makeEnvImage(bool cube, int size, const std::function<Rgb(const Vec3&)>& fn) {
  if (size < 1) fail("environment map size must be at least 1 (got {})", size);
  if (cube) {
    CubeMap map(size);
    const int n = size;
    parallelFor(uint64_t(6) * uint64_t(n), [&](uint64_t row) {
      const int f = int(row / uint64_t(n)), y = int(row % uint64_t(n));
      for (int x = 0; x < n; ++x)
        map.faces[size_t(f)].at(x, y) = fn(Vec3(CubeMap::direction(f, 2.0 * (x + 0.5) / n - 1.0, 2.0 * (y + 0.5) / n - 1.0)));
    });
    return map;
  }
  LatLongMap map{Image(2 * size, size)};
  const int w = map.width(), h = map.height();
  parallelFor(uint64_t(h), [&](uint64_t y) {
    for (int x = 0; x < w; ++x)
      map.image.at(x, int(y)) = fn(LatLongMap::direction((x + 0.5) / w, (double(y) + 0.5) / h));
  });
  return map;
}

int equivalentLatLongHeight(const EnvImage& env) {
  if (const auto* ll = std::get_if<LatLongMap>(&env)) return ll->height();
  return 2 * std::get<CubeMap>(env).size;
}
int equivalentFaceSize(const EnvImage& env) {
  if (const auto* ll = std::get_if<LatLongMap>(&env)) return std::max(1, ll->height() / 2);
  return std::get<CubeMap>(env).size;
}

namespace {

// Supersampling factor per axis: how many source texels (at the source's finest angular
// resolution) fit across one target texel, rounded up, at most 8.
int supersampling(const EnvImage& src, int targetLatLongHeight) {
  const double ratio = double(equivalentLatLongHeight(src)) / double(targetLatLongHeight);
  return std::clamp(int(std::ceil(ratio - 1e-9)), 1, 8);
}

// Box-downsamples a cube by an integer factor with exact texel solid-angle weights.
CubeMap downsampleCube(const CubeMap& cube, int factor) {
  const int n = cube.size / factor;
  CubeMap out(n);
  parallelFor(uint64_t(6) * uint64_t(n), [&](uint64_t row) {
    const int f = int(row / uint64_t(n)), y = int(row % uint64_t(n));
    for (int x = 0; x < n; ++x) {
      DVec3 sum(0.0);
      double omega = 0.0;
      for (int j = 0; j < factor; ++j)
        for (int i = 0; i < factor; ++i) {
          const double dOmega = CubeMap::texelSolidAngle(cube.size, x * factor + i, y * factor + j);
          sum += dOmega * DVec3(cube.faces[size_t(f)].at(x * factor + i, y * factor + j));
          omega += dOmega;
        }
      out.faces[size_t(f)].at(x, y) = Rgb(sum / omega);
    }
  });
  return out;
}

// Supersampling takes at most 8×8 points per target texel. When the source is much finer
// than that, first average it down (exactly, by an integer factor that divides its size)
// to at most 4× the target's angular resolution, so that no source texel is skipped.
std::optional<EnvImage> reduceForTarget(const EnvImage& env, int targetLatLongHeight) {
  const int sourceHeight = equivalentLatLongHeight(env);
  int factor = 1;
  while (sourceHeight / (2 * factor) >= 4 * targetLatLongHeight) factor *= 2;
  if (const auto* ll = std::get_if<LatLongMap>(&env)) {
    while (factor > 1 && ll->height() % factor != 0) factor /= 2;
    if (factor > 1) return downsampleLatLong(*ll, factor);
  } else {
    const auto& cube = std::get<CubeMap>(env);
    while (factor > 1 && cube.size % factor != 0) factor /= 2;
    if (factor > 1) return downsampleCube(cube, factor);
  }
  return std::nullopt;  // use the source as it is
}

}  // namespace

LatLongMap toLatLong(const EnvImage& original, int height) {
  if (height < 1) fail("lat-long height must be at least 1 (got {})", height);
  const std::optional<EnvImage> reduced = reduceForTarget(original, height);
  const EnvImage& env = reduced ? *reduced : original;
  const int w = 2 * height, h = height;
  const int k = supersampling(env, height);
  LatLongMap out{Image(w, h)};
  parallelFor(uint64_t(h), [&](uint64_t yy) {
    const int y = int(yy);
    for (int x = 0; x < w; ++x) {
      // k×k stratified points, each weighted by its solid-angle density sin θ.
      DVec3 sum(0.0);
      double weight = 0.0;
      for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
          const double u = (x + (i + 0.5) / k) / w, v = (y + (j + 0.5) / k) / h;
          const double wgt = std::sin(kPiD * v);
          sum += wgt * DVec3(lookup(env, LatLongMap::direction(u, v)));
          weight += wgt;
        }
      out.image.at(x, y) = Rgb(sum / weight);
    }
  });
  return out;
}

CubeMap toCube(const EnvImage& original, int faceSize) {
  if (faceSize < 1) fail("cube face size must be at least 1 (got {})", faceSize);
  const std::optional<EnvImage> reduced = reduceForTarget(original, 2 * faceSize);
  const EnvImage& env = reduced ? *reduced : original;
  const int n = faceSize;
  const int k = supersampling(env, 2 * n);
  CubeMap out(n);
  parallelFor(uint64_t(6) * uint64_t(n), [&](uint64_t row) {
    const int f = int(row / uint64_t(n)), y = int(row % uint64_t(n));
    for (int x = 0; x < n; ++x) {
      // k×k stratified points, each weighted by its solid-angle density (1+sc²+tc²)^(−3/2).
      DVec3 sum(0.0);
      double weight = 0.0;
      for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
          const double sc = 2.0 * (x + (i + 0.5) / k) / n - 1.0, tc = 2.0 * (y + (j + 0.5) / k) / n - 1.0;
          const double wgt = std::pow(1.0 + sc * sc + tc * tc, -1.5);
          sum += wgt * DVec3(lookup(env, Vec3(CubeMap::direction(f, sc, tc))));
          weight += wgt;
        }
      out.faces[size_t(f)].at(x, y) = Rgb(sum / weight);
    }
  });
  return out;
}

LatLongMap downsampleLatLong(const LatLongMap& map, int factor) {
  if (factor < 1 || map.height() % factor != 0)
    fail("cannot downsample a lat-long map of height {} by {}", map.height(), factor);
  if (factor == 1) return map;
  const int w = map.width() / factor, h = map.height() / factor;
  LatLongMap out{Image(w, h)};
  parallelFor(uint64_t(h), [&](uint64_t yy) {
    const int y = int(yy);
    for (int x = 0; x < w; ++x) {
      DVec3 sum(0.0);
      double omega = 0.0;
      for (int j = 0; j < factor; ++j) {
        const double dOmega = map.texelSolidAngle(y * factor + j);
        for (int i = 0; i < factor; ++i) sum += dOmega * DVec3(map.image.at(x * factor + i, y * factor + j));
        omega += factor * dOmega;
      }
      out.image.at(x, y) = Rgb(sum / omega);
    }
  });
  return out;
}

}  // namespace pl
