#pragma once
// EXPECT_VEC3_NEAR(a, b, tol): GoogleTest's EXPECT_NEAR on each component of two Vec3 (or Rgb),
// for tests that compare points, normals or colours.
#include <gtest/gtest.h>

#include "core/math.h"

#define EXPECT_VEC3_NEAR(a, b, tol)                                                                    \
  do {                                                                                                 \
    const Vec3 va_ = (a), vb_ = (b);                                                                   \
    EXPECT_NEAR(va_.x, vb_.x, tol);                                                                    \
    EXPECT_NEAR(va_.y, vb_.y, tol);                                                                    \
    EXPECT_NEAR(va_.z, vb_.z, tol);                                                                    \
  } while (0)
