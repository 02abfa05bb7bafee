// Tests of env/: layouts and their conventions, exact solid angles, SH and irradiance
// against closed forms, importance sampling (pdf normalisation, sample/pdf agreement,
// chi-square), prefiltering and the split-sum analysis, real files and bad inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>

#include <unistd.h>

#include "core/error.h"
#include "core/progress.h"
#include "core/rng.h"
#include "env/env.h"
#include "env/ibl.h"
#include "support/chi_square.h"
#include "support/sky_map.h"

namespace pl {
namespace {

namespace fs = std::filesystem;
const std::string kData = PLENOPTIC_TEST_DATA_DIR;

constexpr double kFourPi = 4.0 * kPiD;

/// Progress bars off: test logs stay readable.
class QuietEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { Progress::setEnabled(false); }
};
const auto* const kQuiet = ::testing::AddGlobalTestEnvironment(new QuietEnvironment);

/// Legendre polynomial P_l(t) by Bonnet's recursion.
double legendre(int l, double t) {
  double pPrev = 1.0, p = t;
  if (l == 0) return 1.0;
  for (int k = 1; k < l; ++k) {
    const double next = ((2.0 * k + 1.0) * t * p - k * pPrev) / (k + 1.0);
    pPrev = p;
    p = next;
  }
  return p;
}

/// A fresh, empty temporary directory for one test.
fs::path tempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pl_env_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// ─── Conventions ───────────────────────────────────────────────────────────────────────────

TEST(EnvConventions, LatLongDirections) {
  // Image centre looks along +x, u = ¾ along +z, top row up (env.h diagram).
  const Vec3 centre = LatLongMap::direction(0.5, 0.5), right = LatLongMap::direction(0.75, 0.5);
  EXPECT_NEAR(centre.x, 1.0f, 1e-6f);
  EXPECT_NEAR(right.z, 1.0f, 1e-6f);
  EXPECT_NEAR(LatLongMap::direction(0.3, 0.0).y, 1.0f, 1e-6f);
  // uv is the inverse of direction away from the poles.
  for (double u : {0.01, 0.3, 0.5, 0.77, 0.99})
    for (double v : {0.05, 0.4, 0.9}) {
      const Vec2 st = LatLongMap::uv(LatLongMap::direction(u, v));
      EXPECT_NEAR(st.x, u, 1e-5);
      EXPECT_NEAR(st.y, v, 1e-5);
    }
}

TEST(EnvConventions, CubeFacesFollowOpenGlTableWithThreeJsFlip) {
  // World direction d looks up cube direction (−d.x, d.y, d.z) in the OpenGL table, so the
  // face file nx holds world +x, px world −x, and py/ny/pz/nz their own axes.
  EXPECT_EQ(CubeMap::coords({1, 0, 0}).face, int(CubeFace::NegX));
  EXPECT_EQ(CubeMap::coords({-1, 0, 0}).face, int(CubeFace::PosX));
  EXPECT_EQ(CubeMap::coords({0, 1, 0}).face, int(CubeFace::PosY));
  EXPECT_EQ(CubeMap::coords({0, -1, 0}).face, int(CubeFace::NegY));
  EXPECT_EQ(CubeMap::coords({0, 0, 1}).face, int(CubeFace::PosZ));
  EXPECT_EQ(CubeMap::coords({0, 0, -1}).face, int(CubeFace::NegZ));
  // Side faces: the top row looks up (OpenGL: tc = −cy).
  for (int f : {0, 1, 4, 5}) EXPECT_GT(CubeMap::direction(f, 0.0, -0.9).y, 0.5);
  // Seen from inside, no face is mirrored: for a side face, moving right in the image turns
  // right, i.e. (right − centre) is along forward × up.
  for (int f : {0, 1, 4, 5}) {
    const DVec3 forward = CubeMap::direction(f, 0, 0), right = CubeMap::direction(f, 0.5, 0) - forward;
    EXPECT_GT(glm::dot(right, glm::cross(forward, DVec3(0, 1, 0))), 0.1) << "face " << f;
  }
  // +Y face: top row towards −z (OpenGL tc = +cz), as three.js shows py.
  EXPECT_LT(CubeMap::direction(int(CubeFace::PosY), 0.0, -0.9).z, -0.5);
  // coords() inverts direction() on every face.
  for (int f = 0; f < 6; ++f)
    for (double sc : {-0.9, -0.2, 0.4})
      for (double tc : {-0.7, 0.1, 0.95}) {
        const CubeCoords c = CubeMap::coords(CubeMap::direction(f, sc, tc));
        EXPECT_EQ(c.face, f);
        EXPECT_NEAR(c.s, 0.5 * (sc + 1.0), 1e-12);
        EXPECT_NEAR(c.t, 0.5 * (tc + 1.0), 1e-12);
      }
}

TEST(EnvConventions, CrossLayoutsAreContinuousAcrossEveryEdge) {
  // Fill a cube with its own texel directions, unfold it into both crosses and check that
  // texels adjacent in the cross (inside the cross shape) have nearby directions: every
  // shared edge of the unfolded cube is a real edge of the cube.
  const int n = 8;
  const EnvImage cubeImg = makeEnvImage(true, n, [](const Vec3& d) { return 0.5f * (d + Vec3(1.0f)); });
  const CubeMap& cube = std::get<CubeMap>(cubeImg);
  for (bool vertical : {false, true}) {
    const Image cross = cubeToCross(cube, vertical);
    ASSERT_EQ(cross.width, vertical ? 3 * n : 4 * n);
    // Occupied cells are those whose texels are not black (the directions never give 0,0,0
    // exactly except the single corner direction −(1,1,1), which is not a texel centre).
    auto occupied = [&](int x, int y) { return !isBlack(cross.at(x, y)); };
    int edges = 0;
    for (int y = 0; y < cross.height; ++y)
      for (int x = 0; x < cross.width; ++x) {
        if (!occupied(x, y)) continue;
        for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
          const int x2 = x + dx, y2 = y + dy;
          if (x2 >= cross.width || y2 >= cross.height || !occupied(x2, y2)) continue;
          const Vec3 a = 2.0f * cross.at(x, y) - Vec3(1.0f), b = 2.0f * cross.at(x2, y2) - Vec3(1.0f);
          // Neighbouring texel centres are at most ~1.5 texel angles apart (2/n radians at
          // worst across a face edge); unrelated texels would be ≥ 45° apart.
          EXPECT_LT(std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f)), 3.0f / n)
              << (vertical ? "vertical" : "horizontal") << " cross at " << x << "," << y;
          if ((x / n != x2 / n) || (y / n != y2 / n)) ++edges;
        }
      }
    // 5 shared face edges of N texel pairs each are visible in either cross.
    EXPECT_EQ(edges, 5 * n);
    // And reading the cross back gives the cube exactly.
    const CubeMap back = crossToCube(cross, "test");
    for (int f = 0; f < 6; ++f) EXPECT_EQ(back.faces[size_t(f)].pixels, cube.faces[size_t(f)].pixels);
  }
}

// ─── Solid angles ──────────────────────────────────────────────────────────────────────────

TEST(EnvSolidAngle, CubeTexelsSumTo4Pi) {
  for (int n : {1, 2, 3, 17, 64, 256}) {
    double sum = 0.0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) sum += CubeMap::texelSolidAngle(n, x, y);
    // Six identical faces; the closed form is exact, only rounding remains (n² terms ~1e-16).
    EXPECT_NEAR(6.0 * sum, kFourPi, 1e-11) << n;
  }
  // One face subtends 4π/6 exactly; a single texel of a 1-texel face too.
  EXPECT_NEAR(CubeMap::texelSolidAngle(1, 0, 0), kFourPi / 6.0, 1e-14);
}

TEST(EnvSolidAngle, CubeTexelIsTheSphericalQuadArea) {
  // Against direct numerical integration of (1 + x² + y²)^(−3/2) over a corner texel of a
  // 4×4 face (1000² midpoint points: error ~1e-7 relative), and not the cos³ approximation,
  // which is off by a few percent there.
  const int n = 4;
  const double exact = CubeMap::texelSolidAngle(n, 0, 0);
  double numeric = 0.0;
  const int m = 1000;
  const double h = (2.0 / n) / m;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) {
      const double x = -1.0 + (i + 0.5) * h, y = -1.0 + (j + 0.5) * h;
      numeric += std::pow(1.0 + x * x + y * y, -1.5) * h * h;
    }
  EXPECT_NEAR(exact / numeric, 1.0, 1e-6);
  const double xc = -1.0 + 1.0 / n, yc = xc;
  const double approx = (2.0 / n) * (2.0 / n) * std::pow(1.0 + xc * xc + yc * yc, -1.5);
  EXPECT_GT(std::abs(approx / exact - 1.0), 0.005);  // 0.92 % here
}

TEST(EnvSolidAngle, LatLongTexelsSumTo4Pi) {
  for (int h : {1, 2, 5, 64, 512}) {
    LatLongMap map{Image(2 * h, h)};
    double sum = 0.0;
    for (int y = 0; y < h; ++y) sum += map.texelSolidAngle(y) * map.width();
    // Exact per-row closed form: only double rounding over at most 512 rows remains.
    EXPECT_NEAR(sum, kFourPi, 1e-11) << h;
  }
  // SphereTexels carries the same numbers for both layouts.
  for (bool cube : {false, true}) {
    const SphereTexels t = sphereTexels(makeEnvImage(cube, 12, [](const Vec3&) { return Rgb(1.0f); }));
    double sum = 0.0;
    for (double w : t.solidAngle) sum += w;
    EXPECT_NEAR(sum, kFourPi, 1e-11);
  }
}

// ─── SH and irradiance ─────────────────────────────────────────────────────────────────────

TEST(EnvSh, BasisIsOrthonormal) {
  // Gram matrix by midpoint quadrature over a 400×200 lat-long grid with exact texel solid
  // angles: the error is O(h²), h = π/200 (h² ≈ 2.5e-4); the largest measured is 2.8e-5 and
  // the bound 2e-4 stays within the order of h², so a wrong basis constant (≥ 1e-3) fails.
  const int h = 200;
  LatLongMap grid{Image(2 * h, h)};
  double gram[9][9] = {};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 2 * h; ++x) {
      const auto b = shBasis(LatLongMap::directionD((x + 0.5) / (2 * h), (y + 0.5) / h));
      for (int i = 0; i < 9; ++i)
        for (int j = 0; j < 9; ++j) gram[i][j] += b[size_t(i)] * b[size_t(j)] * grid.texelSolidAngle(y);
    }
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) EXPECT_NEAR(gram[i][j], i == j ? 1.0 : 0.0, 2e-4) << i << "," << j;
}

TEST(EnvSh, ConstantEnvironmentIsExact) {
  // L = c ⇒ L_0 = c·∫Y_0 = c·2√π exactly, every other coefficient 0, and E(n) = π·c.
  const Rgb c(0.5f, 1.0f, 2.0f);
  for (bool cube : {false, true}) {
    const Sh9 sh = projectSh9(makeEnvImage(cube, cube ? 16 : 32, [&](const Vec3&) { return c; }));
    const DVec3 expected0 = DVec3(c) * 2.0 * std::sqrt(kPiD);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sh.coefficients[0][ch], expected0[ch], 1e-12 * expected0[ch]);
    // Rounding only: each coefficient sums ~10⁴ terms of size ~1e-3.
    for (int k = 1; k < 9; ++k)
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sh.coefficients[size_t(k)][ch], 0.0, 1e-12) << k;
    const DVec3 e = shIrradiance(sh, DVec3(0.3, -0.8, 0.52) / glm::length(DVec3(0.3, -0.8, 0.52)));
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(e[ch], kPiD * c[ch], 1e-11);
  }
}

TEST(EnvSh, ClampedCosineCoefficients) {
  EXPECT_NEAR(clampedCosineCoefficient(0), kPiD, 1e-15);
  EXPECT_NEAR(clampedCosineCoefficient(1), 2.0 * kPiD / 3.0, 1e-15);
  EXPECT_NEAR(clampedCosineCoefficient(2), kPiD / 4.0, 1e-15);
  EXPECT_EQ(clampedCosineCoefficient(3), 0.0);
  EXPECT_NEAR(clampedCosineCoefficient(4), -kPiD / 24.0, 1e-15);
  // The tight truncation bound for 0 ≤ L ≤ 1 (π∫|K|): 0.1927, i.e. 6.1 % of π.
  EXPECT_NEAR(shTruncationBound(), 0.19273, 1e-4);
}

TEST(EnvSh, LinearEnvironmentIrradianceIsExactInSh9) {
  // L(ω) = 1 + a·ω lies in bands 0–1, so SH9 irradiance is exact:
  //   E(n) = ∫ (1 + a·ω) max(0, n·ω) dω = π + (2π/3) a·n.
  const Vec3 a(0.2f, 0.5f, -0.6f);
  for (bool cube : {false, true}) {
    const EnvImage env = makeEnvImage(cube, 32, [&](const Vec3& d) { return Rgb(1.0f + glm::dot(a, d)); });
    const Sh9 sh = projectSh9(env);
    const EnvImage fromSh = irradianceFromSh(sh, false, 8);
    const EnvImage brute = irradianceBruteForce(env, false, 8);
    const SphereTexels ts = sphereTexels(fromSh), tb = sphereTexels(brute);
    for (size_t i = 0; i < ts.size(); ++i) {
      const double expected = kPiD + 2.0 * kPiD / 3.0 * glm::dot(DVec3(a), ts.direction[i]);
      // SH: the texel-integrated projection of a linear function is exact up to the
      // piecewise-constant texel values (midpoint samples of L): O(h²) ≈ 1e-3 at 32 texels.
      EXPECT_NEAR(ts.radiance[i].g, expected, 2e-3 * expected);
      // Brute force: midpoint rule on 32-texel maps, plus the kink of max(0, ·) at the
      // horizon cut through texels: ≈ 2e-3 relative.
      EXPECT_NEAR(tb.radiance[i].g, expected, 4e-3 * expected);
    }
  }
}

TEST(EnvSh, ClampedCosineLobeAgainstBruteForceWithinSh9Bound) {
  // L(ω) = max(0, a·ω). Its irradiance in closed form (addition theorem):
  //   E(n) = Σ_l Â_l² (2l+1)/(4π) P_l(a·n),
  // and SH9 keeps l ≤ 2, so the truncation error is Σ_{l≥4 even} Â_l²(2l+1)/(4π) P_l(a·n),
  // bounded by Σ_{l≥4} Â_l²(2l+1)/(4π) ≈ 0.0162 (vs E(a) = 2π/3).
  const DVec3 a = glm::normalize(DVec3(0.3, 0.8, -0.2));
  double truncationBound = 0.0;
  for (int l = 4; l <= 400; l += 2)
    truncationBound += std::pow(clampedCosineCoefficient(l), 2) * (2 * l + 1) / (4 * kPiD);
  EXPECT_NEAR(truncationBound, 0.0162, 5e-4);
  EXPECT_LT(truncationBound, shTruncationBound());  // the generic bound covers this case

  const EnvImage env = makeEnvImage(false, 64, [&](const Vec3& d) {
    return Rgb(float(std::max(0.0, glm::dot(a, DVec3(d)))));
  });
  const Sh9 sh = projectSh9(env);
  const SphereTexels ts = sphereTexels(irradianceFromSh(sh, true, 6));
  const SphereTexels tb = sphereTexels(irradianceBruteForce(env, true, 6));
  double worst = 0.0;
  for (size_t i = 0; i < ts.size(); ++i) {
    const double t = glm::dot(a, ts.direction[i]);
    double exact = 0.0, sh9 = 0.0;
    for (int l = 0; l <= 400; ++l) {
      const double term = std::pow(clampedCosineCoefficient(l), 2) * (2 * l + 1) / (4 * kPiD) * legendre(l, t);
      exact += term;
      if (l <= 2) sh9 += term;
    }
    // Brute force against the closed form: midpoint rule on a 128×64 map (the lobe's and the
    // kernel's kinks cut through texels): 3e-3 absolute (E is O(1)).
    EXPECT_NEAR(tb.radiance[i].r, exact, 3e-3);
    // SH9 from the map against SH9 in closed form: texel integration error only.
    EXPECT_NEAR(ts.radiance[i].r, sh9, 2e-3);
    // The measured SH-vs-brute difference stays within the truncation bound (+ the two
    // discretisation tolerances above).
    worst = std::max(worst, std::abs(double(ts.radiance[i].r) - double(tb.radiance[i].r)));
    EXPECT_LE(std::abs(double(ts.radiance[i].r) - double(tb.radiance[i].r)), truncationBound + 5e-3);
  }
  // And the truncation is visible (the test could fail if SH were accidentally exact).
  EXPECT_GT(worst, 0.005);
}

TEST(EnvSh, CubeAndLatLongAgreeOnRealMap) {
  const EnvImage venice = loadEnvironment(kData + "/envmaps/venice_sunset_1k.hdr");
  const Sh9 a = projectSh9(venice);
  const Sh9 b = projectSh9(toCube(venice, 64));
  // Resampling to a 64² cube averages over texels; the SH integrals of the two
  // discretisations of the same radiance agree to ~1 % of the dominant coefficient.
  const double scale = glm::length(a.coefficients[0]);
  for (int k = 0; k < 9; ++k) EXPECT_LT(glm::length(a.coefficients[size_t(k)] - b.coefficients[size_t(k)]), 0.01 * scale) << k;
}

// ─── Layout conversion ─────────────────────────────────────────────────────────────────────

Rgb smoothField(const Vec3& d) {
  return Rgb(1.0f + 0.5f * d.x + 0.3f * d.y * d.z, 0.7f + 0.4f * d.z * d.z, 1.2f - 0.3f * d.y);
}

TEST(EnvConvert, LatLongCubeRoundTripOfSmoothMap) {
  const EnvImage ll = makeEnvImage(false, 128, smoothField);
  const CubeMap cube = toCube(ll, 64);
  // Cube texels against the field at their centres: bilinear interpolation of a smooth field
  // sampled every 1.4° (error O(h²·f'') ≈ 1e-4) plus texel-area averaging (same order).
  const SphereTexels tc = sphereTexels(cube);
  double worst = 0.0;
  for (size_t i = 0; i < tc.size(); ++i)
    worst = std::max(worst, double(glm::length(tc.radiance[i] - smoothField(Vec3(tc.direction[i])))));
  EXPECT_LT(worst, 2e-3);
  const LatLongMap back = toLatLong(cube, 64);
  const SphereTexels tl = sphereTexels(back);
  worst = 0.0;
  for (size_t i = 0; i < tl.size(); ++i)
    worst = std::max(worst, double(glm::length(tl.radiance[i] - smoothField(Vec3(tl.direction[i])))));
  // Two resamplings in a row (lat-long → cube → lat-long), each O(h²): 5e-3.
  EXPECT_LT(worst, 5e-3);
  // Lookups between texels (seamless across cube edges, including exactly at corners).
  for (const Vec3 d : {Vec3(1, 1, 1), Vec3(-1, 0.999f, 1), Vec3(0.3f, -1, 0.999f), Vec3(0, 0, -1)}) {
    const Vec3 u = glm::normalize(d);
    EXPECT_LT(glm::length(cube.lookup(u) - smoothField(u)), 1e-2) << d.x << "," << d.y << "," << d.z;
  }
}

TEST(EnvConvert, LargeReductionsKeepTheSun) {
  // Converting the 1024×512 Venice map (a small, very bright sun) to tiny maps must keep its
  // radiant power: the source is first averaged down exactly, then supersampled. Measured
  // within 0.15 %; tolerance 2 % (bilinear supersampling of a 4× finer map). Point
  // sampling alone (8×8 points per target texel) would skip most source texels.
  const EnvImage venice = loadEnvironment(kData + "/envmaps/venice_sunset_1k.hdr");
  auto power = [](const EnvImage& env) {
    const SphereTexels t = sphereTexels(env);
    double p = 0.0;
    for (size_t i = 0; i < t.size(); ++i) p += luminance(t.radiance[i]) * t.solidAngle[i];
    return p;
  };
  const double reference = power(venice);
  for (int size : {4, 8, 16}) {
    EXPECT_NEAR(power(toLatLong(venice, size)) / reference, 1.0, 0.02) << "lat-long " << size;
    EXPECT_NEAR(power(toCube(venice, size)) / reference, 1.0, 0.02) << "cube " << size;
    EXPECT_NEAR(power(toLatLong(toCube(venice, 128), size)) / reference, 1.0, 0.02) << "cube → lat-long " << size;
  }
}

TEST(EnvConvert, DownsamplePreservesPower) {
  const EnvImage ll = makeEnvImage(false, 64, [](const Vec3& d) { return Rgb(std::exp(5.0f * d.x)); });
  const LatLongMap& src = std::get<LatLongMap>(ll);
  const LatLongMap small = downsampleLatLong(src, 4);
  auto power = [](const LatLongMap& m) {
    double p = 0.0;
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) p += double(m.image.at(x, y).r) * m.texelSolidAngle(y);
    return p;
  };
  EXPECT_NEAR(power(small) / power(src), 1.0, 1e-6);  // float texels, double sums
}

// ─── Environment light: importance sampling ────────────────────────────────────────────────

TEST(EnvLight, PdfIntegratesToOne) {
  for (float rotation : {0.0f, 37.0f}) {
    const EnvironmentMap env = test_support::skyWithSun(rotation);
    // Midpoint rule over a 20× finer lat-long grid in WORLD directions with exact solid
    // angles. The pdf is constant in (u,v) per map texel, so ∫ pdf dω = ∫ p(u,v) du dv = 1;
    // the only error is sin θ varying inside a fine texel and texels straddling map texel
    // edges after the rotation (≈ 1e-3).
    const int h = 320;
    LatLongMap grid{Image(2 * h, h)};
    double integral = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < 2 * h; ++x)
        integral += env.pdf(LatLongMap::direction((x + 0.5) / (2 * h), (y + 0.5) / h)) * grid.texelSolidAngle(y);
    EXPECT_NEAR(integral, 1.0, 3e-3) << rotation;
  }
}

TEST(EnvLight, SampleMatchesPdfAndRadiance) {
  const EnvironmentMap env = test_support::skyWithSun(37.0f);
  Pcg32 rng(7, 3);
  for (int i = 0; i < 20000; ++i) {
    const EnvironmentSample s = env.sample({rng.uniform(), rng.uniform()});
    if (std::abs(s.direction.y) < 1.0f) {
      ASSERT_GT(s.pdf, 0.0f);  // zero only exactly at a pole
    }
    EXPECT_NEAR(glm::length(s.direction), 1.0f, 1e-5f);
    // sample() reports exactly pdf() and radiance() of the direction it returns.
    EXPECT_EQ(env.pdf(s.direction), s.pdf);
    EXPECT_EQ(env.radiance(s.direction), s.radiance);
  }
}

TEST(EnvLight, ChiSquareOfSampleHistogram) {
  // Samples binned per map texel (after undoing the rotation with toMap, so rotation is
  // tested too). pdf() is constant in (u, v) inside a texel, so the expected count of a
  // texel is exactly n·p(u,v)·ΔuΔv with p(u,v) = pdf(centre)·2π² sin θ_centre — computed
  // from pdf() alone. Pearson's statistic (support/chi_square.h); rejected below p = 1e-4:
  // a correct sampler fails with probability 1e-4, a sample/pdf mismatch by orders of
  // magnitude more.
  const EnvironmentMap env = test_support::skyWithSun(37.0f);
  const int w = env.map().width(), h = env.map().height(), n = 400000;
  std::vector<double> expected(size_t(w) * h, 0.0), observed(size_t(w) * h, 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = (x + 0.5) / w, v = (y + 0.5) / h;
      const Vec3 worldCentre = env.toWorld(LatLongMap::direction(u, v));
      expected[size_t(y) * w + x] =
          n * double(env.pdf(worldCentre)) * 2.0 * kPiD * kPiD * std::sin(kPiD * v) / (double(w) * h);
    }
  Pcg32 rng(11, 5);
  int poleSamples = 0;
  for (int i = 0; i < n; ++i) {
    const EnvironmentSample s = env.sample({rng.uniform(), rng.uniform()});
    if (s.pdf == 0.0f) {
      // Only a direction that rounded onto a pole (sin θ = 0 in float) may have zero pdf.
      EXPECT_EQ(std::abs(s.direction.y), 1.0f);
      ++poleSamples;
      continue;
    }
    const Vec2 uv = LatLongMap::uv(env.toMap(s.direction));
    observed[size_t(std::min(int(uv.y * h), h - 1)) * w + size_t(std::min(int(uv.x * w), w - 1))] += 1.0;
  }
  EXPECT_LT(poleSamples, n / 10000);
  const double totalE = std::accumulate(expected.begin(), expected.end(), 0.0);
  EXPECT_NEAR(totalE, n, 1e-3 * n);  // the per-texel probabilities sum to 1 (float pdf)
  const test_support::ChiSquareOutcome r = test_support::pearsonChiSquare(observed, expected);
  EXPECT_FALSE(r.impossibleSample);
  EXPECT_GT(r.pValue, 1e-4) << "chi2 " << r.chi2 << " dof " << r.dof;
}

TEST(EnvLight, ImportanceSampledIntegralIsUnbiased) {
  // ∫ L dω by sampling (mean of L/pdf) against fine quadrature of radiance(); the estimator
  // is unbiased only if pdf > 0 wherever L > 0 (including the bilinear spill into the black
  // row). 5σ tolerance from the estimator's own variance.
  const EnvironmentMap env = test_support::skyWithSun(0.0f);
  const int h = 512;
  LatLongMap grid{Image(2 * h, h)};
  double reference = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 2 * h; ++x)
      reference += luminance(env.radiance(LatLongMap::direction((x + 0.5) / (2 * h), (y + 0.5) / h))) *
                   grid.texelSolidAngle(y);
  Pcg32 rng(3, 9);
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const EnvironmentSample s = env.sample({rng.uniform(), rng.uniform()});
    const double v = s.pdf > 0.0f ? luminance(s.radiance) / s.pdf : 0.0;  // renderers skip pdf 0
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n, sigma = std::sqrt((sum2 / n - mean * mean) / n);
  // Quadrature error of the reference (512 rows for a 16-row map): ~1e-4 relative.
  EXPECT_NEAR(mean, reference, 5.0 * sigma + 1e-3 * reference);
  // Rotation moves the radiance: the sun seen through a rotated map.
  const EnvironmentMap rotated = test_support::skyWithSun(90.0f);
  const Vec3 sunMap = LatLongMap::direction(8.0 / 32.0, 4.5 / 16.0);
  EXPECT_GT(luminance(rotated.radiance(rotated.toWorld(sunMap))), 100.0f);
  EXPECT_LT(luminance(rotated.radiance(sunMap)), 10.0f);
  // toWorld(+x) for +90° is −z (counter-clockwise seen from +y).
  EXPECT_NEAR(rotated.toWorld(Vec3(1, 0, 0)).z, -1.0f, 1e-6f);
}

TEST(EnvLight, RefusesNonFiniteTexels) {
  LatLongMap m{Image(8, 4, Rgb(1.0f))};
  m.image.at(3, 2) = Rgb(std::numeric_limits<float>::quiet_NaN());
  EXPECT_THROW(EnvironmentMap(std::move(m)), Error);
}

// ─── Prefiltering, DFG, split-sum ──────────────────────────────────────────────────────────

TEST(EnvPrefilter, ConstantEnvironmentStaysConstant) {
  const EnvImage env = makeEnvImage(false, 32, [](const Vec3&) { return Rgb(0.7f, 1.0f, 1.3f); });
  for (SpecularModel model : {SpecularModel::Ggx, SpecularModel::BlinnPhong}) {
    PrefilterOptions o;
    o.model = model;
    o.levels = 3;
    o.height = 16;
    o.samples = 64;
    const auto levels = prefilter(env, o);
    ASSERT_EQ(levels.size(), 3u);
    EXPECT_FLOAT_EQ(levels[2].roughness, 1.0f);
    // A weighted mean of a constant is that constant (float accumulation: 1e-5).
    for (const auto& level : levels)
      for (const Rgb& p : level.map.image.pixels) EXPECT_LT(glm::length(p - Rgb(0.7f, 1.0f, 1.3f)), 1e-4f);
  }
}

TEST(EnvPrefilter, RoughLevelsBlurASpot) {
  // A bright cap of ~10° around +y: the rough level spreads it (lower peak, wider support).
  const EnvImage env = makeEnvImage(false, 64, [](const Vec3& d) { return Rgb(d.y > 0.985f ? 100.0f : 0.0f); });
  PrefilterOptions o;
  o.levels = 3;
  o.height = 32;
  const auto levels = prefilter(env, o);
  const Vec3 up(0, 1, 0), side = glm::normalize(Vec3(1, 1, 0));  // 45° away
  EXPECT_GT(levels[0].map.lookup(up).r, levels[2].map.lookup(up).r);
  EXPECT_LT(levels[0].map.lookup(side).r, 1e-3f);
  EXPECT_GT(levels[2].map.lookup(side).r, 0.05f);
}

TEST(EnvPrefilter, MatchesQuadratureOfItsDefinition) {
  // P(R) = ∫ L f(R, ω) cos θ dω / ∫ f cos θ dω, evaluated by brute-force quadrature over the
  // texels of the source (64-row map, exact solid angles) against prefilter()'s default 1024
  // filtered-importance samples (Hammersley points). FIS reads pre-averaged texels and the
  // point set is finite; measured ≤ 0.62 % (Blinn-Phong at r = 1), tolerance 1.5 %.
  const EnvImage env = makeEnvImage(false, 64, [](const Vec3& d) {
    return Rgb(0.2f + 4.0f * std::pow(std::max(0.0f, glm::dot(d, glm::normalize(Vec3(1, 1, 0)))), 8.0f));
  });
  const SphereTexels texels = sphereTexels(env);
  for (SpecularModel model : {SpecularModel::Ggx, SpecularModel::BlinnPhong}) {
    PrefilterOptions o;
    o.model = model;
    o.levels = 3;  // roughness 0, 0.5, 1
    o.height = 16;
    const auto levels = prefilter(env, o);
    for (int k = 1; k < 3; ++k) {
      const Bsdf bsdf = specularBsdf(model, levels[size_t(k)].roughness, 1.0f);
      for (const Vec3 r : {Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(-1, 0.2f, 0.5f)}) {
        const Vec3 rn = glm::normalize(r);
        // Evaluate at the level's texel centre nearest to R, to avoid interpolation error.
        const LatLongMap& map = levels[size_t(k)].map;
        const Vec2 uv = LatLongMap::uv(rn);
        const int x = std::min(int(uv.x * map.width()), map.width() - 1), y = std::min(int(uv.y * map.height()), map.height() - 1);
        const Vec3 centre = LatLongMap::direction((x + 0.5) / map.width(), (y + 0.5) / map.height());
        const Frame frameC = Frame::fromNormal(centre);
        double num = 0.0, den = 0.0;
        for (size_t i = 0; i < texels.size(); ++i) {
          const Vec3 wi = frameC.toLocal(Vec3(texels.direction[i]));
          if (wi.z <= 0.0f) continue;
          const double w = eval(bsdf, Vec3(0, 0, 1), wi).g * wi.z * texels.solidAngle[i];
          num += w * texels.radiance[i].r;
          den += w;
        }
        EXPECT_NEAR(map.image.at(x, y).r / (num / den), 1.0, 0.015)
            << specularModelName(model) << " roughness " << levels[size_t(k)].roughness;
      }
    }
  }
}

TEST(EnvPrefilter, DfgTermMatchesBsdfAlbedo) {
  // A + B at f0 = 1 is the lobe's directional albedo, which bsdf.h computes independently.
  for (float roughness : {0.2f, 0.5f, 0.9f})
    for (float cosV : {1.0f, 0.5f, 0.15f}) {
      const DfgTerm t = dfgTerm(SpecularModel::Ggx, roughness, cosV, 4096);
      const Vec3 wo(std::sqrt(1.0f - cosV * cosV), 0.0f, cosV);
      const float reference = albedo(specularBsdf(SpecularModel::Ggx, roughness, 1.0f), wo).g;
      // Two numerical integrations (bsdf.h quadrature ≈ 1e-3, 4096 Hammersley points ≈ 1e-3).
      EXPECT_NEAR(t.scale + t.bias, reference, 5e-3) << roughness << " " << cosV;
      EXPECT_GT(t.bias, 0.0);  // Schlick's (1−cos)^5 part is positive
      const DfgTerm bp = dfgTerm(SpecularModel::BlinnPhong, roughness, cosV, 4096);
      EXPECT_NEAR(bp.bias, 0.0, 1e-12);  // no Fresnel in Blinn-Phong
    }
  const Image table = dfgTable(SpecularModel::Ggx, 8, 256);
  EXPECT_EQ(table.width, 8);
  for (const Rgb& p : table.pixels) {
    EXPECT_GE(p.r, 0.0f);
    EXPECT_LE(p.r + p.g, 1.001f);  // energy conservation (1e-3: quadrature)
  }
}

TEST(EnvSplitSum, ExactForConstantEnvironment) {
  // Constant L: exact = L·ρ(θv), approximation = (L·ρ(0)/ρ(0))·ρ(θv): equal up to MC noise.
  LatLongMap m{Image(32, 16, Rgb(1.0f))};
  const EnvironmentMap env(std::move(m));
  SplitSumOptions o;
  o.roughness = {0.3f, 0.8f};
  o.viewDegrees = {0.0f, 60.0f};
  o.normals = 4;
  o.samples = 2048;
  const SplitSumReport r = splitSumError(env, o);
  ASSERT_EQ(r.cells.size(), 4u);
  for (const SplitSumCell& c : r.cells) EXPECT_LT(c.maxAbsRelative, 5.0 * c.monteCarloRelative + 2e-3);
}

TEST(EnvSplitSum, ErrorGrowsWithViewAngleOnARealMap) {
  // The decomposition is exact at θv = 0 for f0 = 1 (both sides are the same integral) and
  // degrades towards grazing view: the analysis must show it.
  const auto env = loadEnvironmentMap(kData + "/envmaps/venice_sunset_1k.hdr");
  const EnvironmentMap small(downsampleLatLong(env->map(), 8));
  SplitSumOptions o;
  o.roughness = {0.5f};
  o.viewDegrees = {0.0f, 80.0f};
  o.normals = 8;
  o.samples = 1024;
  const SplitSumReport r = splitSumError(small, o);
  EXPECT_LT(r.cells[0].meanAbsRelative, 5.0 * r.cells[0].monteCarloRelative + 1e-3);
  EXPECT_GT(r.cells[1].meanAbsRelative, r.cells[0].meanAbsRelative);
}

// ─── Files ─────────────────────────────────────────────────────────────────────────────────

TEST(EnvFiles, LoadsPisaCubeAndVeniceLatLong) {
  const EnvImage pisa = loadEnvironment(kData + "/envmaps/pisa-cube");
  ASSERT_TRUE(std::holds_alternative<CubeMap>(pisa));
  // 64²: the three.js 256² faces box-filtered 4×4 in their own pixel grids
  // (tests/data/THIRD_PARTY.md), so orientation and seams are the distributed ones.
  EXPECT_EQ(std::get<CubeMap>(pisa).size, 64);
  const EnvImage pattern = loadEnvironment(kData + "/envmaps/pisa-cube/{face}.hdr");
  EXPECT_EQ(std::get<CubeMap>(pattern).faces[3].pixels, std::get<CubeMap>(pisa).faces[3].pixels);
  // The sky is up: the +Y face (py) is brighter on average than the ground face (ny).
  auto mean = [](const Image& im) {
    double s = 0.0;
    for (const Rgb& p : im.pixels) s += luminance(p);
    return s / double(im.pixels.size());
  };
  EXPECT_GT(mean(std::get<CubeMap>(pisa).faces[2]), mean(std::get<CubeMap>(pisa).faces[3]));
  // Seamless: the two sides of every cube edge match in the real data (three.js faces,
  // loaded with our orientation table): the mean relative jump across face edges is small,
  // while a wrong orientation would compare unrelated pixels.
  const CubeMap& cube = std::get<CubeMap>(pisa);
  double jump = 0.0, level = 0.0;
  int count = 0;
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < cube.size; ++i) {
      const std::array<std::pair<int, int>, 4> inside = {{{i, 0}, {i, cube.size - 1}, {0, i}, {cube.size - 1, i}}};
      const std::array<std::pair<int, int>, 4> outside = {{{i, -1}, {i, cube.size}, {-1, i}, {cube.size, i}}};
      for (int e = 0; e < 4; ++e) {
        const float a = luminance(cube.fetch(f, inside[size_t(e)].first, inside[size_t(e)].second));
        const float b = luminance(cube.fetch(f, outside[size_t(e)].first, outside[size_t(e)].second));
        jump += std::abs(a - b);
        level += 0.5 * (a + b);
        ++count;
      }
    }
  // Measured ≈ 0.06 on these 64² faces (≈ 0.03 on the 256² originals, where mismatched edges
  // gave ≈ 0.5).
  EXPECT_LT(jump / level, 0.1);

  const EnvImage venice = loadEnvironment(kData + "/envmaps/venice_sunset_1k.hdr");
  ASSERT_TRUE(std::holds_alternative<LatLongMap>(venice));
  EXPECT_EQ(std::get<LatLongMap>(venice).width(), 1024);
}

TEST(EnvFiles, SaveAndReloadEveryLayout) {
  const fs::path dir = tempDir("layouts");
  const EnvImage env = makeEnvImage(true, 8, smoothField);
  for (const char* layout : {"cube", "cross", "vcross"}) {
    const std::string out = (dir / (std::string(layout) + (std::string(layout) == "cube" ? "" : ".exr"))).string();
    saveEnvironment(out, env, parseEnvLayout(layout));
    const EnvImage back = loadEnvironment(out);
    ASSERT_TRUE(std::holds_alternative<CubeMap>(back)) << layout;
    for (int f = 0; f < 6; ++f)
      for (size_t i = 0; i < std::get<CubeMap>(back).faces[size_t(f)].pixels.size(); ++i)
        // .hdr (cube) stores RGBE: 8-bit mantissa per channel, relative error ≤ 2^-8.
        EXPECT_LT(glm::length(std::get<CubeMap>(back).faces[size_t(f)].pixels[i] -
                              std::get<CubeMap>(env).faces[size_t(f)].pixels[i]),
                  1e-2f)
            << layout;
  }
  saveEnvironment((dir / "pattern_{face}.pfm").string(), env, EnvLayout::Cube);
  EXPECT_TRUE(fs::exists(dir / "pattern_nz.pfm"));
  saveEnvironment((dir / "ll.exr").string(), env, EnvLayout::LatLong);
  EXPECT_TRUE(std::holds_alternative<LatLongMap>(loadEnvironment((dir / "ll.exr").string())));
  fs::remove_all(dir);
}

TEST(EnvFiles, BadInputsNameTheFile) {
  const fs::path dir = tempDir("bad");
  const Image face(4, 4, Rgb(1.0f));
  for (int f = 0; f < 5; ++f) writeHdrImage((dir / (std::string(kCubeFaceNames[size_t(f)]) + ".hdr")).string(), face);
  std::string msg = errorOf([&] { loadEnvironment(dir.string()); });
  EXPECT_NE(msg.find("nz"), std::string::npos) << msg;
  EXPECT_NE(msg.find("missing"), std::string::npos) << msg;
  EXPECT_NE(msg.find(dir.string()), std::string::npos) << msg;

  writeHdrImage((dir / "nz.hdr").string(), Image(8, 8, Rgb(1.0f)));
  msg = errorOf([&] { loadEnvironment(dir.string()); });
  EXPECT_NE(msg.find("nz.hdr"), std::string::npos) << msg;
  EXPECT_NE(msg.find("same size"), std::string::npos) << msg;

  writeHdrImage((dir / "nz.hdr").string(), Image(4, 5, Rgb(1.0f)));
  msg = errorOf([&] { loadEnvironment(dir.string()); });
  EXPECT_NE(msg.find("nz.hdr"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not square"), std::string::npos) << msg;

  const std::string odd = (dir / "odd.hdr").string();
  writeHdrImage(odd, Image(50, 30, Rgb(1.0f)));
  msg = errorOf([&] { loadEnvironment(odd); });
  EXPECT_NE(msg.find(odd), std::string::npos) << msg;
  EXPECT_NE(msg.find("cross"), std::string::npos) << msg;
  msg = errorOf([&] { crossToCube(Image(50, 30), "odd-cross.exr"); });
  EXPECT_NE(msg.find("odd-cross.exr"), std::string::npos) << msg;

  msg = errorOf([&] { loadEnvironment((dir / "nothing.hdr").string()); });
  EXPECT_NE(msg.find("nothing.hdr"), std::string::npos) << msg;
  msg = errorOf([&] { loadEnvironment((dir / "x_{face}.hdr").string()); });
  EXPECT_NE(msg.find("px"), std::string::npos) << msg;
  EXPECT_THROW(parseEnvLayout("sphere"), Error);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pl
