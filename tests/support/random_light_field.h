#pragma once
// Test support (header-only; include as "support/random_light_field.h"): light fields with
// random values, for comparing renderers without a bake.
#include <utility>

#include "bake/parameterisation.h"
#include "core/rng.h"
#include "lightfield/lightfield.h"

namespace pl::test_support {

/// A light field over `scene` with the charts of `settings` (the default preset's unless given)
/// and *random* values in [0, 4): a harsher test of the 16-neighbour lookup than a smooth bake
/// (every tixel and direction texel differs from its neighbours), and fast (no propagation).
inline LightField randomLightField(Scene scene, uint64_t seed, const BakeSettings& settings = BakeSettings{}) {
  LightField lf;
  lf.settings = settings;
  Parameterisation param = buildParameterisation(scene, lf.settings);
  lf.charts = std::move(param.charts);
  lf.triangleChart = std::move(param.triangleChart);
  lf.values.resize(param.valueCount);
  Pcg32 rng(seed, 7);
  for (Rgb& v : lf.values) v = Rgb(4.0f * rng.uniform(), 4.0f * rng.uniform(), 4.0f * rng.uniform());
  lf.scene = std::move(scene);
  lf.scene.finalize();  // the move keeps the Embree padding, but be explicit
  return lf;
}

}  // namespace pl::test_support
