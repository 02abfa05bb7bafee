// Next-event estimation at mirror-like lobes (lightfield/lookup.h MirrorLikeLights): the
// built-in Cornell box under its own area light with the white walls, floor, ceiling and blocks
// a GGX metal of roughness 0.2 — mirror-like at draft, so every view ray that meets them
// follows a chain of sampled lobes — against the path tracer, and the fast renderer against the
// reference one.
#include <gtest/gtest.h>

#include <cstdio>

#include "accel/accel.h"
#include "bake/bake.h"
#include "camera/camera.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "image/compare.h"
#include "realtime/realtime.h"
#include "render/render.h"
#include "scene/scene.h"
#include "support/fast_vs_reference.h"
#include "support/light_field_vs_trace.h"

namespace pl {
namespace {

class MirrorLikeLightsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { Progress::setEnabled(false); }
  ThreadPool pool_{2};
};

/// The built-in box with its "white" material (walls, floor, ceiling, blocks) made GGX metal of
/// roughness 0.2 over its colour (glTF metallic-roughness, metallic 1).
Scene metalBox() {
  Scene scene = makeCornellBox();
  for (Material& m : scene.materials)
    if (const auto* lambert = std::get_if<LambertBsdf>(&m.bsdf); lambert && m.name == "white")
      m.bsdf = gltfMetallicRoughnessModel(lambert->albedo, 1.0f, 0.2f);
  scene.finalize();
  return scene;
}

// Measured (48 × 48, draft, 16 samples per pixel vs 256 spp): LF/PT 0.9777, relMSE 0.0201;
// without the split at the first hit (lookup.h firstHitLobeSamples: one lobe sample there)
// 0.9843, 0.0409, which the bound fails. With the lobe's own samples alone (as before
// MirrorLikeLights) the lamp's reflections are fireflies: the conformance case of the same
// box, tests/conformance ggx-m-0.2, had relMSE 0.257 then. Bounds: the ratio within 0.03,
// relMSE 1.5 × the measured.
TEST_F(MirrorLikeLightsTest, LampReflectionsInMirrorLikeMetalMatchThePathTracer) {
  const Scene scene = metalBox();
  const Camera camera(scene.cameras.front(), 48, 48);
  const BakeSettings settings = bakePreset("draft");
  const auto [reference, lf, image] = test_support::lightFieldAndReference(scene, camera, 256, settings, 16);
  uint32_t mirrorLike = 0;
  for (const Chart& c : lf.charts) mirrorLike += c.kind == ChartKind::Specular;
  ASSERT_GT(mirrorLike, 0u);
  const Accel accel(lf.scene);
  ASSERT_TRUE(MirrorLikeLights(lf, accel).active());
  const ImageComparison with = compareImages(image, reference);
  std::printf("area light in mirror-like GGX metal r 0.2: LF/PT %.4f relMSE %.5f\n", with.meanLuminanceRatio,
              with.relMseAverage);
  EXPECT_NEAR(with.meanLuminanceRatio, 1.0, 0.03);
  EXPECT_LT(with.relMseAverage, 0.030);

  // The fast renderer samples the same lights and splits the same first hits with the same
  // numbers (one and four samples per pixel): only the hit points' rounding and the order of
  // sums differ, a missing or doubled term would be above 1e-2.
  for (int spp : {1, 4}) {
    const ImageComparison same = test_support::fastAgainstReferenceRenderer(lf, accel, camera, spp);
    std::printf("fast vs reference renderer, %d spp: relMSE %.3g, mean ratio %.7f\n", spp, same.relMseAverage,
                same.meanLuminanceRatio);
    EXPECT_LT(same.relMseAverage, 1e-6) << spp;
    EXPECT_NEAR(same.meanLuminanceRatio, 1.0, 1e-4) << spp;
  }
}

}  // namespace
}  // namespace pl
