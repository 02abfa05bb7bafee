#include <gtest/gtest.h>

#include "core/math.h"
#include "core/rng.h"
#include "core/sampling.h"

namespace pl {
namespace {

TEST(Frame, IsOrthonormalAndRoundTrips) {
  Pcg32 rng(1, 2);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 n = sampleUniformSphere({rng.uniform(), rng.uniform()});
    const Frame f = Frame::fromNormal(n);
    EXPECT_NEAR(glm::dot(f.s, f.t), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(f.s, f.n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.s), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.t), 1.0f, 1e-5f);
    const Vec3 v = sampleUniformSphere({rng.uniform(), rng.uniform()});
    const Vec3 back = f.toWorld(f.toLocal(v));
    EXPECT_NEAR(glm::length(back - v), 0.0f, 1e-5f);
    EXPECT_GT(glm::dot(glm::cross(f.s, f.t), f.n), 0.99f);  // right-handed
  }
}

TEST(Pcg32, SameKeySameStreamDifferentKeysDiffer) {
  Pcg32 a = Pcg32::forKey(5, 7, 1), b = Pcg32::forKey(5, 7, 1), c = Pcg32::forKey(5, 8, 1);
  int same = 0;
  for (int i = 0; i < 100; ++i) {
    const uint32_t x = a.next();
    EXPECT_EQ(x, b.next());
    same += x == c.next();
  }
  EXPECT_LT(same, 3);
}

TEST(Pcg32, UniformMeanAndRange) {
  Pcg32 rng(42, 54);
  double sum = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const float u = rng.uniform();
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    sum += u;
  }
  // Standard error of the mean of U(0,1) is sqrt(1/12/n) ≈ 6.5e-4; allow 5 sigma.
  EXPECT_NEAR(sum / n, 0.5, 5 * std::sqrt(1.0 / 12.0 / n));
}

TEST(Sampling, CosineHemisphereIntegratesCosineToPi) {
  // E[cos θ / pdf] = ∫ cos θ dω = π for the cosine-weighted sampler (exact per sample).
  Pcg32 rng(3, 4);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 w = sampleCosineHemisphere({rng.uniform(), rng.uniform()});
    EXPECT_NEAR(glm::length(w), 1.0f, 1e-5f);
    EXPECT_GE(w.z, 0.0f);
    if (w.z > 1e-3f) {
      EXPECT_NEAR(w.z / cosineHemispherePdf(w.z), kPi, 1e-4f);
    }
  }
}

TEST(Distribution1D, SamplesProportionallyToWeights) {
  const std::vector<float> w = {1.0f, 0.0f, 3.0f};
  Distribution1D d(w);
  EXPECT_FLOAT_EQ(d.probability(0), 0.25f);
  EXPECT_FLOAT_EQ(d.probability(1), 0.0f);
  EXPECT_FLOAT_EQ(d.probability(2), 0.75f);
  EXPECT_EQ(d.sample(0.1f), 0u);
  EXPECT_EQ(d.sample(0.3f), 2u);
  float remapped = -1;
  d.sample(0.625f, &remapped);
  EXPECT_NEAR(remapped, 0.5f, 1e-6f);
}

}  // namespace
}  // namespace pl
