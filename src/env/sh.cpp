// Spherical harmonics projection, irradiance from SH and by brute force (ibl.h).
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "env/ibl.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <mutex>

namespace pl {

namespace {

// Normalisation constants of the orthonormal real SH (ibl.h).
const double kY00 = 0.5 * std::sqrt(1.0 / kPiD);         // 0.282095
const double kY1 = std::sqrt(3.0 / (4.0 * kPiD));        // 0.488603
const double kY2 = 0.5 * std::sqrt(15.0 / kPiD);         // 1.092548
const double kY20 = 0.25 * std::sqrt(5.0 / kPiD);        // 0.315392
const double kY22 = 0.25 * std::sqrt(15.0 / kPiD);       // 0.546274

// Exact integrals of the 9 basis functions over the lat-long texel
// μ = cos θ ∈ [mu1, mu0], φ ∈ [phi0, phi1] (dω = dμ dφ), with y = μ, x = s cos φ,
// z = s sin φ, s = √(1 − μ²). Every basis function is a sum of products f(μ)·g(φ), so the
// texel integral is a sum of products of a row integral and a column integral:
//   ∫ s dμ = ½(μ s + asin μ),  ∫ μ s dμ = −⅓(1 − μ²)^{3/2},  ∫ s² dμ = μ − μ³/3,
//   ∫ cos φ = sin φ, ∫ sin φ = −cos φ, ∫ cos 2φ = ½ sin 2φ, ∫ sin 2φ = −½ cos 2φ.
struct RowIntegrals {  // over μ ∈ [mu1, mu0]
  double one, mu, muMu, s, muS, sS;
};
struct ColumnIntegrals {  // over φ ∈ [phi0, phi1]
  double one, cos, sin, cos2, sin2;
};

RowIntegrals rowIntegrals(double mu0, double mu1) {
  auto s = [](double mu) { return std::sqrt(std::max(0.0, 1.0 - mu * mu)); };
  auto fS = [&](double mu) { return 0.5 * (mu * s(mu) + std::asin(std::clamp(mu, -1.0, 1.0))); };
  auto fMuS = [](double mu) { return -std::pow(std::max(0.0, 1.0 - mu * mu), 1.5) / 3.0; };
  auto fSS = [](double mu) { return mu - mu * mu * mu / 3.0; };
  return {mu0 - mu1,
          0.5 * (mu0 * mu0 - mu1 * mu1),
          (mu0 * mu0 * mu0 - mu1 * mu1 * mu1) / 3.0,
          fS(mu0) - fS(mu1),
          fMuS(mu0) - fMuS(mu1),
          fSS(mu0) - fSS(mu1)};
}

ColumnIntegrals columnIntegrals(double phi0, double phi1) {
  return {phi1 - phi0,
          std::sin(phi1) - std::sin(phi0),
          std::cos(phi0) - std::cos(phi1),
          0.5 * (std::sin(2.0 * phi1) - std::sin(2.0 * phi0)),
          0.5 * (std::cos(2.0 * phi0) - std::cos(2.0 * phi1))};
}

std::array<double, 9> texelBasisIntegrals(const RowIntegrals& r, const ColumnIntegrals& c) {
  return {kY00 * r.one * c.one,
          kY1 * r.mu * c.one,                                     // y
          kY1 * r.s * c.sin,                                      // z = s sin φ
          kY1 * r.s * c.cos,                                      // x = s cos φ
          kY2 * r.muS * c.cos,                                    // xy
          kY2 * r.muS * c.sin,                                    // yz
          kY20 * (1.5 * r.sS * (c.one - c.cos2) - r.one * c.one), // 3z² − 1, z² = s²(1 − cos 2φ)/2
          kY2 * 0.5 * r.sS * c.sin2,                              // xz = s² sin 2φ / 2
          kY22 * (0.5 * r.sS * (c.one + c.cos2) - r.muMu * c.one)};  // x² − y², x² = s²(1 + cos 2φ)/2
}

}  // namespace

std::array<double, 9> shBasis(const DVec3& d) {
  return {kY00,
          kY1 * d.y,
          kY1 * d.z,
          kY1 * d.x,
          kY2 * d.x * d.y,
          kY2 * d.y * d.z,
          kY20 * (3.0 * d.z * d.z - 1.0),
          kY2 * d.x * d.z,
          kY22 * (d.x * d.x - d.y * d.y)};
}

Sh9 projectSh9(const EnvImage& env) {
  std::mutex mutex;
  Sh9 total;
  auto accumulate = [&](const Sh9& partial) {
    std::lock_guard lock(mutex);
    for (int k = 0; k < 9; ++k) total.coefficients[size_t(k)] += partial.coefficients[size_t(k)];
  };
  if (const auto* ll = std::get_if<LatLongMap>(&env)) {
    const int w = ll->width(), h = ll->height();
    std::vector<ColumnIntegrals> columns(static_cast<size_t>(w));
    for (int x = 0; x < w; ++x)
      columns[size_t(x)] = columnIntegrals(2.0 * kPiD * (double(x) / w - 0.5), 2.0 * kPiD * (double(x + 1) / w - 0.5));
    parallelForRange(uint64_t(h), 8, [&](uint64_t y0, uint64_t y1) {
      Sh9 part;
      for (uint64_t y = y0; y < y1; ++y) {
        const RowIntegrals row = rowIntegrals(std::cos(kPiD * double(y) / h), std::cos(kPiD * double(y + 1) / h));
        for (int x = 0; x < w; ++x) {
          const auto integral = texelBasisIntegrals(row, columns[size_t(x)]);
          const DVec3 L(ll->image.at(x, int(y)));
          for (int k = 0; k < 9; ++k) part.coefficients[size_t(k)] += integral[size_t(k)] * L;
        }
      }
      accumulate(part);
    });
    return total;
  }
  const auto& cube = std::get<CubeMap>(env);
  const int n = cube.size;
  // 2×2 Gauss–Legendre nodes at ±1/(2√3) of a texel around its centre, weights ∝ the
  // solid-angle density (1+sc²+tc²)^(−3/2), rescaled so that they sum to the exact texel
  // solid angle.
  const double offset = (1.0 / n) / std::sqrt(3.0);  // ± half-width/√3 in face coordinates (width 2/n)
  parallelForRange(uint64_t(6) * uint64_t(n), 8, [&](uint64_t r0, uint64_t r1) {
    Sh9 part;
    for (uint64_t row = r0; row < r1; ++row) {
      const int f = int(row / uint64_t(n)), y = int(row % uint64_t(n));
      for (int x = 0; x < n; ++x) {
        const double scC = 2.0 * (x + 0.5) / n - 1.0, tcC = 2.0 * (y + 0.5) / n - 1.0;
        std::array<double, 9> integral{};
        double jacobianSum = 0.0;
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) {
            const double sc = scC + (i ? offset : -offset), tc = tcC + (j ? offset : -offset);
            const double jac = std::pow(1.0 + sc * sc + tc * tc, -1.5);
            const auto b = shBasis(CubeMap::direction(f, sc, tc));
            for (int k = 0; k < 9; ++k) integral[size_t(k)] += jac * b[size_t(k)];
            jacobianSum += jac;
          }
        const double scaleToExact = CubeMap::texelSolidAngle(n, x, y) / jacobianSum;
        const DVec3 L(cube.faces[size_t(f)].at(x, y));
        for (int k = 0; k < 9; ++k) part.coefficients[size_t(k)] += integral[size_t(k)] * scaleToExact * L;
      }
    }
    accumulate(part);
  });
  return total;
}

DVec3 shRadiance(const Sh9& sh, const DVec3& dir) {
  const auto b = shBasis(dir);
  DVec3 L(0.0);
  for (int k = 0; k < 9; ++k) L += b[size_t(k)] * sh.coefficients[size_t(k)];
  return L;
}

double clampedCosineCoefficient(int l) {
  // R-H 2001 eq. 8: Â_1 = 2π/3; odd l > 1: 0; even l:
  //   Â_l = 2π (−1)^{l/2−1} / ((l+2)(l−1)) · l! / (2^l ((l/2)!)²).
  if (l == 1) return 2.0 * kPiD / 3.0;
  if (l % 2 == 1) return 0.0;
  // l!/(2^l ((l/2)!)²) = C(l, l/2)/2^l, computed as a running product to stay finite.
  double central = 1.0;
  for (int i = 1; i <= l / 2; ++i) central *= double(l / 2 + i) / double(i) / 4.0;
  const double sign = ((l / 2 - 1) % 2 == 0) ? 1.0 : -1.0;
  return 2.0 * kPiD * sign / (double(l + 2) * double(l - 1)) * central;
}

DVec3 shIrradiance(const Sh9& sh, const DVec3& n) {
  const auto b = shBasis(n);
  const double a[3] = {clampedCosineCoefficient(0), clampedCosineCoefficient(1), clampedCosineCoefficient(2)};
  DVec3 e(0.0);
  for (int k = 0; k < 9; ++k) {
    const int band = k == 0 ? 0 : (k < 4 ? 1 : 2);
    e += a[band] * b[size_t(k)] * sh.coefficients[size_t(k)];
  }
  return e;
}

double shTruncationBound(int maxBand) {
  // The clamped cosine as a kernel on the sphere is max(0, t) = Σ_l Â_l (2l+1)/(4π) P_l(t)
  // (t = n·ω). Truncating after band `maxBand` leaves the kernel K(t) = max(0,t) − K_band(t),
  // whose integral is 0. For any radiance 0 ≤ L ≤ 1 the error ∫ K L dω is therefore at most
  // ∫ K⁺ dω = ½∫|K| dω = π ∫_{−1}^{1} |K(t)| dt, attained by L = [K > 0]: a tight bound.
  // Evaluated with the midpoint rule (K is piecewise smooth, 2·10⁵ points: error < 1e-9).
  const int steps = 200000;
  double sum = 0.0;
  for (int i = 0; i < steps; ++i) {
    const double t = -1.0 + (i + 0.5) * 2.0 / steps;
    double pPrev = 1.0, p = t, truncated = clampedCosineCoefficient(0) / (4.0 * kPiD);
    for (int l = 1; l <= maxBand; ++l) {
      truncated += clampedCosineCoefficient(l) * (2.0 * l + 1.0) / (4.0 * kPiD) * p;
      const double next = ((2.0 * l + 1.0) * t * p - l * pPrev) / (l + 1.0);  // Bonnet recursion
      pPrev = p;
      p = next;
    }
    sum += std::abs(std::max(0.0, t) - truncated) * (2.0 / steps);
  }
  return kPiD * sum;
}

std::string shToJson(const Sh9& sh, const std::string& source) {
  nlohmann::ordered_json j;
  j["source"] = source;
  j["basis"] = "real orthonormal SH, bands 0-2, index l(l+1)+m, world axes +y up (see env/ibl.h)";
  j["units"] = "W m^-2 (radiance integrated against the basis over steradians)";
  auto& c = j["coefficients"] = nlohmann::json::array();
  for (const DVec3& v : sh.coefficients) c.push_back({v.x, v.y, v.z});
  return j.dump(2);
}

// ─── Irradiance maps ───────────────────────────────────────────────────────────────────────

EnvImage irradianceBruteForce(const EnvImage& source, bool cube, int size) {
  const SphereTexels src = sphereTexels(source);
  // Structure of arrays, radiance pre-multiplied by the texel solid angle.
  const size_t count = src.size();
  std::vector<double> dx(count), dy(count), dz(count), wr(count), wg(count), wb(count);
  for (size_t i = 0; i < count; ++i) {
    dx[i] = src.direction[i].x;
    dy[i] = src.direction[i].y;
    dz[i] = src.direction[i].z;
    wr[i] = double(src.radiance[i].r) * src.solidAngle[i];
    wg[i] = double(src.radiance[i].g) * src.solidAngle[i];
    wb[i] = double(src.radiance[i].b) * src.solidAngle[i];
  }
  const uint64_t targetTexels = cube ? uint64_t(6) * size * size : uint64_t(2) * size * size;
  Progress progress("irradiance (brute force)", targetTexels);
  auto irradiance = [&](const Vec3& n) {
    const double nx = n.x, ny = n.y, nz = n.z;
    double er = 0.0, eg = 0.0, eb = 0.0;
    for (size_t i = 0; i < count; ++i) {  // branch-free so that the compiler vectorises it
      const double c = std::max(0.0, nx * dx[i] + ny * dy[i] + nz * dz[i]);
      er += c * wr[i];
      eg += c * wg[i];
      eb += c * wb[i];
    }
    progress.advance();
    return Rgb(float(er), float(eg), float(eb));
  };
  EnvImage out = makeEnvImage(cube, size, irradiance);
  progress.finish();
  return out;
}

EnvImage irradianceFromSh(const Sh9& sh, bool cube, int size) {
  return makeEnvImage(cube, size, [&](const Vec3& n) { return Rgb(shIrradiance(sh, DVec3(n))); });
}

MapDifference compareMaps(const EnvImage& a, const EnvImage& reference) {
  const SphereTexels ta = sphereTexels(a), tr = sphereTexels(reference);
  if (ta.size() != tr.size() || a.index() != reference.index())
    fail("cannot compare environment maps of different layouts or sizes ({} vs {})", describe(a), describe(reference));
  MapDifference d;
  double sumSq = 0.0, omega = 0.0;
  for (size_t i = 0; i < ta.size(); ++i) {
    const double ref = luminance(tr.radiance[i]);
    if (!(ref > 0.0)) continue;
    const double rel = std::abs(double(luminance(ta.radiance[i])) - ref) / ref;
    if (rel > d.maxRelative) {
      d.maxRelative = rel;
      d.maxAt = Vec3(tr.direction[i]);
    }
    sumSq += rel * rel * tr.solidAngle[i];
    omega += tr.solidAngle[i];
  }
  d.rmsRelative = omega > 0.0 ? std::sqrt(sumSq / omega) : 0.0;
  return d;
}

}  // namespace pl
