// The light field of the repository's subsurface test scene (bench/scenes/sss-cornell.json:
// McGuire's Cornell box with a wax-like sphere and a thin slab, both subsurface) against the
// path tracer at a small size: the mean over the image and over each object's pixels.
//
// Measured (48×48, trace 512 spp, light field 4 samples per pixel, draft bake, seed 0): light
// field / path tracer 0.994 over the image but the light, 0.994 on the sphere, 1.013 on the
// slab (the same room with Lambertian stand-ins for the two objects: 1.020 over the whole
// image, light included — the draft preset's own bias here). Bounds: 2 % (the target).
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <string>
#include <variant>

#include "core/progress.h"
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

  // Regions by what the ray through each pixel's centre hits: the objects, and the whole image
  // but the light (whose 17-times-brighter pixels would weigh the mean by how its edge pixels,
  // 4 samples against 512, happen to be cut).
  const Accel accel(scene);
  const std::vector<RayHit> hits = test_support::pixelCentreHits(accel, camera);
  auto meanRatio = [&](const std::function<bool(const Material&)>& keep, int& pixels) {
    const test_support::RegionRatio region =
        test_support::regionLuminanceRatio(run.image, run.reference, hits, [&](const RayHit& hit) {
          return keep(scene.materials[scene.meshes[hit.mesh].materials[hit.triangle]]);
        });
    pixels = region.pixels;
    return region.ratio;
  };
  int pixels = 0;
  const double image = meanRatio([](const Material& m) { return !m.isEmissive(); }, pixels);
  std::printf("image but the light: %d pixels, mean luminance ratio %.4f\n", pixels, image);
  EXPECT_NEAR(image, 1.0, kImageTolerance);
  for (const std::string object : {"sphere", "slab"}) {
    const double ratio = meanRatio(
        [&](const Material& m) { return m.name == object && std::holds_alternative<SubsurfaceBsdf>(m.bsdf); }, pixels);
    std::printf("%s: %d pixels, mean luminance ratio %.4f\n", object.c_str(), pixels, ratio);
    ASSERT_GT(pixels, 20) << object;
    EXPECT_NEAR(ratio, 1.0, kObjectTolerance) << object;
  }
}

}  // namespace
}  // namespace pl
