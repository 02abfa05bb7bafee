// Tests of core/sampler.h: stratification of the Owen-scrambled ZSobol points, their
// convergence rate against independent sampling, and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "core/sampler.h"

namespace pl {
namespace {

/// The n = 2^k points of dimension `dimension` of pixel (x, y) in an image of the given size.
std::vector<Vec2> pixelPoints2D(int width, int height, int x, int y, int k, uint32_t dimension, uint64_t seed) {
  const int spp = 1 << k;
  const ZSobolLayout layout(width, height, spp, seed);
  std::vector<Vec2> points;
  for (int i = 0; i < spp; ++i) {
    Sampler s = Sampler::sobol(layout, x, y, uint64_t(i));
    s.setDimension(dimension);
    points.push_back(s.get2D());
  }
  return points;
}

/// True when every elementary interval [a/2^i, (a+1)/2^i) × [b/2^j, (b+1)/2^j) with
/// i + j = k holds exactly one of the 2^k points (a (0, k, 2)-net in base 2).
bool isZeroKTwoNet(const std::vector<Vec2>& points, int k) {
  for (int i = 0; i <= k; ++i) {
    const int j = k - i;
    std::set<std::pair<int, int>> cells;
    for (const Vec2& p : points) {
      EXPECT_GE(p.x, 0.0f);
      EXPECT_LT(p.x, 1.0f);
      EXPECT_GE(p.y, 0.0f);
      EXPECT_LT(p.y, 1.0f);
      cells.insert({int(std::ldexp(p.x, i)), int(std::ldexp(p.y, j))});
    }
    if (cells.size() != points.size()) return false;
  }
  return true;
}

TEST(ZSobol, EveryPixelsSamplesAreAZeroKTwoNetInEveryDimension) {
  // Odd and even log2(spp) (the last index digit is base 2 or base 4), odd image sizes, padded
  // dimensions far from the first.
  for (int k = 0; k <= 9; ++k)
    for (auto [x, y] : {std::pair{0, 0}, std::pair{5, 2}, std::pair{12, 9}})
      for (uint32_t dimension : {0u, 1u, 2u, 7u, 100u})
        EXPECT_TRUE(isZeroKTwoNet(pixelPoints2D(13, 10, x, y, k, dimension, 3), k))
            << "k " << k << " pixel " << x << "," << y << " dimension " << dimension;
}

TEST(ZSobol, OneDimensionalSamplesAreStratified) {
  for (int k = 0; k <= 9; ++k) {
    const ZSobolLayout layout(64, 48, 1 << k, 11);
    for (uint32_t dimension : {0u, 3u, 41u}) {
      std::set<int> strata;
      for (int i = 0; i < (1 << k); ++i) {
        Sampler s = Sampler::sobol(layout, 17, 40, uint64_t(i));
        s.setDimension(dimension);
        strata.insert(int(std::ldexp(s.get1D(), k)));
      }
      EXPECT_EQ(strata.size(), size_t(1) << k) << "k " << k << " dimension " << dimension;
    }
  }
}

TEST(ZSobol, DependsOnlyOnPixelSampleDimensionAndSeed) {
  const ZSobolLayout layout(32, 32, 16, 5);
  Sampler a = Sampler::sobol(layout, 3, 4, 7), b = Sampler::sobol(layout, 3, 4, 7);
  // Dimensions are explicit: drawing other dimensions first changes nothing.
  b.setDimension(9);
  (void)b.get2D();
  a.setDimension(4);
  b.setDimension(4);
  EXPECT_EQ(a.get2D(), b.get2D());
  EXPECT_EQ(a.get1D(), b.get1D());  // both now at dimension 5
  // Another pixel, another seed, another dimension: other numbers.
  auto point = [](const ZSobolLayout& l, int x, uint32_t dimension) {
    Sampler s = Sampler::sobol(l, x, 4, 7);
    s.setDimension(dimension);
    return s.get2D();
  };
  const Vec2 v = point(layout, 3, 4);
  EXPECT_NE(point(layout, 4, 4), v);
  EXPECT_NE(point(ZSobolLayout(32, 32, 16, 6), 3, 4), v);
  EXPECT_NE(point(layout, 3, 5), v);
}

TEST(ZSobol, NeighbouringPixelsGetDifferentPoints) {
  // At 1 spp the 4 pixels of an aligned 2×2 block differ only in the lowest base-4 digit of
  // the global index, and the shuffle permutes that digit: they are 4 consecutive points of
  // an aligned block of the scrambled sequence, so in every dimension they fall into the 4
  // different quarters of [0, 1).
  const ZSobolLayout layout(16, 16, 1, 2);
  for (uint32_t dimension : {0u, 6u}) {
    std::set<int> quarters;
    for (auto [x, y] : {std::pair{6, 2}, std::pair{7, 2}, std::pair{6, 3}, std::pair{7, 3}}) {
      Sampler s = Sampler::sobol(layout, x, y, 0);
      s.setDimension(dimension);
      quarters.insert(int(s.get1D() * 4.0f));
    }
    EXPECT_EQ(quarters.size(), 4u) << "dimension " << dimension;
  }
}

/// Root-mean-square error, over `trials` seeds, of the n-point estimate of the integral of the
/// smooth f(x, y) = e^x · cos y over [0, 1)² (exactly (e − 1)·sin 1).
double rmsError(SamplerKind kind, int n, int trials, uint32_t dimension) {
  const double exact = (std::exp(1.0) - 1.0) * std::sin(1.0);
  double sumSquares = 0.0;
  for (int t = 0; t < trials; ++t) {
    const ZSobolLayout layout = ZSobolLayout::forKey(uint64_t(t), n, 1234);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      Sampler s = Sampler::make(kind, layout, uint64_t(t), 0, 0, uint64_t(i), 1234);
      s.setDimension(dimension);
      const Vec2 u = s.get2D();
      sum += std::exp(double(u.x)) * std::cos(double(u.y));
    }
    const double error = sum / n - exact;
    sumSquares += error * error;
  }
  return std::sqrt(sumSquares / trials);
}

// Owen-scrambled (0,2)-sequences integrate smooth functions with an RMS error O(n^−3/2)
// (Owen 1997), independent samples O(n^−1/2): 16× the samples divide the error by 64 and by 4
// respectively. Asserting a reduction of more than 16× (and an error at 4096 points far below
// the independent one) leaves a wide margin over the 4× of independent sampling, whatever the
// 64 seeds draw.
TEST(ZSobol, ConvergesFasterThanIndependentSamplingOnASmoothIntegrand) {
  constexpr int kTrials = 64;
  for (uint32_t dimension : {0u, 9u}) {
    const double sobol256 = rmsError(SamplerKind::Sobol, 256, kTrials, dimension);
    const double sobol4096 = rmsError(SamplerKind::Sobol, 4096, kTrials, dimension);
    const double independent256 = rmsError(SamplerKind::Independent, 256, kTrials, dimension);
    const double independent4096 = rmsError(SamplerKind::Independent, 4096, kTrials, dimension);
    EXPECT_GT(sobol256 / sobol4096, 16.0) << sobol256 << " " << sobol4096;
    EXPECT_LT(independent256 / independent4096, 8.0) << independent256 << " " << independent4096;
    EXPECT_LT(sobol4096, independent4096 / 20.0) << sobol4096 << " " << independent4096;
  }
}

TEST(ZSobol, RejectsImagesItCannotIndex) {
  EXPECT_THROW(ZSobolLayout(70000, 10, 4, 0), Error);
  EXPECT_THROW(ZSobolLayout(10, 10, 0, 0), Error);
  EXPECT_EQ(parseSampler("sobol"), SamplerKind::Sobol);
  EXPECT_EQ(parseSampler("independent"), SamplerKind::Independent);
  EXPECT_THROW(parseSampler("halton"), Error);
}

TEST(IndependentSampler, IsThePcg32StreamInCallOrder) {
  Sampler s = Sampler::independent(4, 5, 6);
  Pcg32 rng = Pcg32::forKey(4, 5, 6);
  s.setDimension(30);  // ignored
  EXPECT_EQ(s.get1D(), rng.uniform());
  const Vec2 u = s.get2D();
  EXPECT_EQ(u.x, rng.uniform());
  EXPECT_EQ(u.y, rng.uniform());
}

}  // namespace
}  // namespace pl
