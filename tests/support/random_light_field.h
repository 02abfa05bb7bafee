#pragma once
// Test support (header-only; include as "support/random_light_field.h"): light fields with
// random values, for comparing renderers without a bake.
#include <utility>

#include "bake/parameterisation.h"
#include "core/rng.h"
#include "lightfield/lightfield.h"
#include "scene/scene.h"

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

/// The built-in Cornell box with every non-emissive material a GGX metal too sharp for a
/// glossy map (α 2e-3): its charts are mirror-like specular records (bake/parameterisation.h
/// isMirrorLike), which the renderers follow by sampling the lobe.
inline Scene mirrorLikeCornellBox() {
  Scene scene = makeCornellBox();
  for (Material& m : scene.materials)
    if (!m.isEmissive()) m.bsdf = GgxBsdf{Rgb(0.0f), Rgb(0.9f), 2e-3f};
  return scene;
}

}  // namespace pl::test_support
