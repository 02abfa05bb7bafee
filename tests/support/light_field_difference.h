#pragma once
// The relative L1 difference of two light fields' values, Σ|Y(a − b)| / Σ Y(b) (Y the
// luminance), with which relighting tests compare a relit field to a fresh bake.
#include <gtest/gtest.h>

#include <cmath>

#include "lightfield/lightfield.h"

namespace pl::test_support {

inline double relativeDifference(const LightField& a, const LightField& b) {
  EXPECT_EQ(a.values.size(), b.values.size());
  double diff = 0.0, total = 0.0;
  for (size_t v = 0; v < a.values.size() && v < b.values.size(); ++v) {
    diff += std::abs(double(luminance(a.values[v] - b.values[v])));
    total += std::abs(double(luminance(b.values[v])));
  }
  return total > 0.0 ? diff / total : diff;
}

}  // namespace pl::test_support
