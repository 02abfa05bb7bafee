#pragma once
// Test support (header-only; include as "support/chi_square.h"): Pearson's chi-square
// goodness-of-fit statistic and its p-value, the one implementation the sampler tests share
// (the BSDF samplers against their pdfs, the environment light's sampler against its pdf).
//
// The caller bins samples into cells and supplies, per cell, the observed count and the
// expected count N·P(cell) computed from the pdf alone. Cells expecting fewer than
// kChiSquareMinExpected samples are pooled, smallest first, into one cell (the χ²
// approximation of Pearson's statistic needs ≳ 5 per cell). The p-value is Q(dof/2, χ²/2), the
// regularised upper incomplete gamma function (Numerical Recipes §6.2), dof = cells − 1.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace pl::test_support {

inline constexpr double kChiSquareMinExpected = 5.0;

/// Regularised upper incomplete gamma Q(a, x) = 1 − P(a, x) (series for x < a + 1, else the
/// Lentz continued fraction; Numerical Recipes §6.2). Q(k/2, χ²/2) is the χ² survival function.
inline double regularizedGammaQ(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double logPrefactor = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(logPrefactor);
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(logPrefactor) * h;
}

struct ChiSquareOutcome {
  double pValue = 0.0;
  double chi2 = 0.0;
  int dof = 0;
  bool impossibleSample = false;  ///< a sample landed in a cell whose expected count is 0
};

/// Pearson's statistic of `observed` against `expected` (same length) with small cells pooled
/// (see the top of this file). `exemptCell` (or −1) is a cell whose expectation is a
/// difference (e.g. N minus the integrated cells) and so is not checked for impossible samples.
inline ChiSquareOutcome pearsonChiSquare(const std::vector<double>& observed, const std::vector<double>& expected,
                                         int exemptCell = -1) {
  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  ChiSquareOutcome out;
  double pooledObserved = 0.0, pooledExpected = 0.0;
  int cells = 0;
  for (const size_t i : order) {
    if (int(i) != exemptCell && expected[i] == 0.0 && observed[i] > 0.0) out.impossibleSample = true;
    if (expected[i] < kChiSquareMinExpected) {
      pooledObserved += observed[i];
      pooledExpected += expected[i];
      continue;
    }
    const double diff = observed[i] - expected[i];
    out.chi2 += diff * diff / expected[i];
    ++cells;
  }
  if (pooledExpected >= kChiSquareMinExpected) {
    const double diff = pooledObserved - pooledExpected;
    out.chi2 += diff * diff / pooledExpected;
    ++cells;
  } else if (pooledObserved > 0.0 && cells > 0) {
    // Too little expected mass left to form a cell of its own: its discrepancy still counts
    // (with expected ≥ 1, so a few stray samples cannot blow up), but adds no degree of
    // freedom, which can only make the test stricter.
    const double diff = pooledObserved - pooledExpected;
    out.chi2 += diff * diff / std::max(pooledExpected, 1.0);
  }
  out.dof = cells - 1;
  out.pValue = out.dof > 0 ? regularizedGammaQ(0.5 * out.dof, 0.5 * out.chi2) : 1.0;
  return out;
}

}  // namespace pl::test_support
