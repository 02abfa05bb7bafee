// Tests of the paraboloid hemisphere map and its texel grid.
#include "lightfield/paraboloid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "core/rng.h"
#include "core/sampling.h"

namespace pl {
namespace {

TEST(Paraboloid, RoundTripDirectionToMapAndBack) {
  Pcg32 rng(7, 1);
  for (int i = 0; i < 100000; ++i) {
    const Vec3 d = sampleUniformHemisphere(Vec2(rng.uniform(), rng.uniform()));
    const Vec2 st = directionToParaboloid(d);
    const Vec3 back = paraboloidToDirection(st);
    // float round-off of a handful of operations on unit-size numbers: a few ulps of 1.
    EXPECT_NEAR(back.x, d.x, 2e-6f);
    EXPECT_NEAR(back.y, d.y, 2e-6f);
    EXPECT_NEAR(back.z, d.z, 2e-6f);
  }
}

TEST(Paraboloid, RoundTripMapToDirectionAndBack) {
  Pcg32 rng(8, 1);
  for (int i = 0; i < 100000; ++i) {
    const Vec2 st = sampleConcentricDisk(Vec2(rng.uniform(), rng.uniform()));
    const Vec3 d = paraboloidToDirection(st);
    EXPECT_NEAR(glm::length(d), 1.0f, 2e-6f);
    EXPECT_GE(d.z, 0.0f);
    const Vec2 back = directionToParaboloid(d);
    EXPECT_NEAR(back.x, st.x, 2e-6f);
    EXPECT_NEAR(back.y, st.y, 2e-6f);
  }
}

TEST(Paraboloid, KnownDirections) {
  EXPECT_EQ(directionToParaboloid(Vec3(0, 0, 1)), Vec2(0, 0));
  // Horizon directions land on the unit circle, 45° elevation at radius tan(22.5°).
  EXPECT_NEAR(directionToParaboloid(Vec3(1, 0, 0)).x, 1.0f, 1e-7f);
  EXPECT_NEAR(directionToParaboloid(Vec3(0, -1, 0)).y, -1.0f, 1e-7f);
  const float h = std::sqrt(0.5f);
  EXPECT_NEAR(directionToParaboloid(Vec3(h, 0, h)).x, std::tan(kPi / 8.0f), 1e-6f);
  // Below the horizon: projected onto the horizon.
  const Vec2 below = directionToParaboloid(glm::normalize(Vec3(3, 4, -1)));
  EXPECT_NEAR(below.x, 0.6f, 1e-6f);
  EXPECT_NEAR(below.y, 0.8f, 1e-6f);
}

TEST(Paraboloid, HemisphereFullyCoveredByTexelsWithSolidAngle) {
  // Every direction of the hemisphere maps into [−1, 1]², into a texel whose solid angle is
  // positive: no direction falls into a gap or a texel the map thinks is empty.
  for (uint32_t res : {1u, 2u, 5u, 8u, 16u}) {
    const std::vector<float>& omega = paraboloidTexelSolidAngles(res);
    Pcg32 rng(res, 3);
    for (int i = 0; i < 20000; ++i) {
      Vec3 d = sampleUniformHemisphere(Vec2(rng.uniform(), rng.uniform()));
      if (i < 64) d = glm::normalize(Vec3(std::cos(i * 0.1f), std::sin(i * 0.1f), 0.0f));  // the horizon itself
      const Vec2 st = directionToParaboloid(d);
      ASSERT_LE(st.x * st.x + st.y * st.y, 1.0f + 1e-6f);
      const uint32_t a = std::min(res - 1, uint32_t((st.x + 1.0f) * 0.5f * res));
      const uint32_t b = std::min(res - 1, uint32_t((st.y + 1.0f) * 0.5f * res));
      EXPECT_GT(omega[a + b * res], 0.0f) << "res " << res << " texel " << a << "," << b;
    }
    // And every texel's representative direction lies in the upper hemisphere.
    for (uint32_t b = 0; b < res; ++b)
      for (uint32_t a = 0; a < res; ++a) {
        const Vec3 d = paraboloidTexelDirection(a, b, res);
        EXPECT_GT(d.z, 0.0f);
        EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
      }
  }
}

TEST(Paraboloid, TexelSolidAnglesSumToTwoPi) {
  for (uint32_t res : {1u, 2u, 3u, 4u, 7u, 8u, 16u, 31u, 64u}) {
    double sum = 0.0;
    for (uint32_t b = 0; b < res; ++b)
      for (uint32_t a = 0; a < res; ++a) sum += paraboloidTexelSolidAngle(a, b, res);
    // The quadrature is smooth piece by piece (breaks at the kinks), so it is accurate to
    // well below 1e-9; 1e-9 relative leaves room for summation round-off only.
    EXPECT_NEAR(sum, 2.0 * kPiD, 2.0 * kPiD * 1e-9) << "res " << res;
  }
}

TEST(Paraboloid, TexelSolidAngleMatchesBruteForceIntegration) {
  // Independent check: midpoint rule of the Jacobian 4/(1+s²+t²)² over the texel's points
  // inside the disk, on a 1500² grid. The midpoint rule's error comes from the disk boundary
  // cutting cells (area error ~ perimeter·h/2 relative ~ 1e-3 of a boundary texel), hence 2e-3.
  const uint32_t res = 6;
  for (uint32_t b = 0; b < res; ++b)
    for (uint32_t a = 0; a < res; ++a) {
      const double exact = paraboloidTexelSolidAngle(a, b, res);
      const int n = 1500;
      const double size = 2.0 / res, h = size / n;
      double brute = 0.0;
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const double s = -1.0 + a * size + (x + 0.5) * h, t = -1.0 + b * size + (y + 0.5) * h;
          const double r2 = s * s + t * t;
          if (r2 <= 1.0) brute += 4.0 / ((1.0 + r2) * (1.0 + r2)) * h * h;
        }
      EXPECT_NEAR(exact, brute, 2e-3 * std::max(brute, 1e-3)) << a << "," << b;
    }
}

TEST(Paraboloid, SolidAngleMatchesFractionOfUniformDirections) {
  // A statistical check tied to directions, not to the Jacobian formula: the fraction of
  // uniformly distributed hemisphere directions landing in a texel, times 2π.
  const uint32_t res = 4;
  const int n = 400000;
  std::vector<int> counts(res * res, 0);
  Pcg32 rng(99, 5);
  for (int i = 0; i < n; ++i) {
    const Vec2 st = directionToParaboloid(sampleUniformHemisphere(Vec2(rng.uniform(), rng.uniform())));
    const uint32_t a = std::min(res - 1, uint32_t((st.x + 1.0f) * 0.5f * res));
    const uint32_t b = std::min(res - 1, uint32_t((st.y + 1.0f) * 0.5f * res));
    ++counts[a + b * res];
  }
  for (uint32_t k = 0; k < res * res; ++k) {
    const double p = paraboloidTexelSolidAngle(k % res, k / res, res) / (2.0 * kPiD);
    const double sigma = std::sqrt(n * p * (1.0 - p));
    // 5σ of a binomial count: fails by chance with probability < 1e-6 per texel.
    EXPECT_NEAR(counts[k], n * p, 5.0 * sigma + 1.0) << "texel " << k;
  }
}

}  // namespace
}  // namespace pl
