// The light field of the repository's subsurface test scene (bench/scenes/sss-cornell.json:
// McGuire's Cornell box with a wax-like sphere and a thin slab, both subsurface) against the
// path tracer at a small size: the mean over the image and over each object's pixels.
//
// Measured (48×48, trace 512 spp, light field 4 samples per pixel, draft bake): see the
// tolerances below and docs/benchmarks.md, "Subsurface scattering in the light field".
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <variant>

#include "core/progress.h"
#include "image/compare.h"
#include "support/light_field_vs_trace.h"

namespace pl {
namespace {

constexpr int kSize = 48;
constexpr int kTraceSpp = 512;
constexpr int kLightFieldSamples = 4;
constexpr double kImageTolerance = 0.02;
constexpr double kObjectTolerance = 0.02;

TEST(SubsurfaceVsPathTracer, CornellBoxWithSphereAndSlabAgreesInMean) {
  Progress::setEnabled(false);
  const Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/../../bench/scenes/sss-cornell.json");
  ASSERT_FALSE(scene.cameras.empty());
  const Camera camera(scene.cameras.front(), kSize, kSize);
  const test_support::LightFieldAndReference run =
      test_support::lightFieldAndReference(scene, camera, kTraceSpp, bakePreset("draft"), kLightFieldSamples);

  const ImageComparison all = compareImages(run.image, run.reference);
  std::printf("image: mean luminance ratio %.4f\n", all.meanLuminanceRatio);
  EXPECT_NEAR(all.meanLuminanceRatio, 1.0, kImageTolerance);

  const Accel accel(scene);
  const std::vector<RayHit> hits = test_support::pixelCentreHits(accel, camera);
  for (const char* object : {"sphere", "slab"}) {
    double field = 0.0, traced = 0.0;
    int pixels = 0;
    for (size_t p = 0; p < hits.size(); ++p) {
      if (!hits[p].hit()) continue;
      const Material& m = scene.materials[scene.meshes[hits[p].mesh].materials[hits[p].triangle]];
      if (m.name != object || !std::holds_alternative<SubsurfaceBsdf>(m.bsdf)) continue;
      field += luminance(run.image.pixels[p]);
      traced += luminance(run.reference.pixels[p]);
      ++pixels;
    }
    std::printf("%s: %d pixels, mean luminance ratio %.4f\n", object, pixels, field / traced);
    ASSERT_GT(pixels, 20) << object;
    EXPECT_NEAR(field / traced, 1.0, kObjectTolerance) << object;
  }
}

}  // namespace
}  // namespace pl
