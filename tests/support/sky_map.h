#pragma once
// Test support (header-only; include as "support/sky_map.h"): a small environment map with a
// sun, for the environment sampling tests (env/) and the environment light's (light/).
#include <utility>

#include "env/env.h"

namespace pl::test_support {

/// A 32×16 lat-long sky: a smooth gradient, a bright 2×1-texel "sun" at texels (7–8, 4), a
/// black row (13) near the bottom; scaled by 2 and rotated by `rotation` degrees about +y.
inline EnvironmentMap skyWithSun(float rotation) {
  LatLongMap m{Image(32, 16)};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) m.image.at(x, y) = Rgb(0.2f + 0.1f * float(x % 5), 0.3f, 0.5f + 0.02f * float(y));
  for (int x = 0; x < 32; ++x) m.image.at(x, 13) = Rgb(0.0f);
  m.image.at(7, 4) = m.image.at(8, 4) = Rgb(200.0f, 180.0f, 150.0f);
  return EnvironmentMap(std::move(m), 2.0f, rotation);
}

}  // namespace pl::test_support
