// Textured glossy materials in the light field against the path tracer: the built-in Cornell
// box with its white material made glossy (GGX, and normalised Blinn-Phong) over a checkerboard
// albedo texture. The diffuse part of a glossy chart is kept as one irradiance value per tixel
// and modulated by the texture where it is seen (lightfield.h, "What is stored per chart
// kind"); before that, glossy maps held the untextured material's whole exitant radiance, and
// the light field was 1.6× too bright with no checkerboard on the walls.
#include <gtest/gtest.h>

#include <cstdio>

#include "bake/bake.h"
#include "camera/camera.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "image/compare.h"
#include "scene/scene.h"
#include "support/light_field_vs_trace.h"

namespace pl {
namespace {

class TexturedGlossyTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { Progress::setEnabled(false); }
  ThreadPool pool_{2};
};

/// The built-in box with `white` replaced by `bsdf` over an 8 × 8 checkerboard of albedo
/// 0.15 and 0.95 (the box has no uvs: each triangle maps the texture by its barycentrics).
Scene texturedCornellBox(const Bsdf& bsdf) {
  Scene scene = makeCornellBox();
  Texture checker;
  checker.path = "checker";
  checker.image = Image(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) checker.image.at(x, y) = Rgb(((x + y) % 2) != 0 ? 0.95f : 0.15f);
  scene.textures.push_back(checker);
  for (Material& m : scene.materials)
    if (m.name == "white") {
      m.bsdf = bsdf;
      m.albedoTexture = int(scene.textures.size()) - 1;
    }
  scene.finalize();
  return scene;
}

Camera smallCornellCamera(const Scene& scene) { return Camera(scene.cameras.front(), 48, 48); }

struct Figures {
  double ratio, relMse, untexturedRatio;
};

/// Light field (draft, 4 samples per pixel) against a 256-spp path trace, and the same
/// path trace of the untextured material (what the light field showed before).
Figures compare(const Bsdf& bsdf) {
  const Scene scene = texturedCornellBox(bsdf);
  const Camera camera = smallCornellCamera(scene);
  const auto [reference, lf, image] = test_support::lightFieldAndReference(scene, camera, 256, bakePreset("draft"), 4);
  uint64_t withDiffuseValue = 0;
  for (const Chart& c : lf.charts) withDiffuseValue += c.diffuseValue;
  EXPECT_GT(withDiffuseValue, 0u);
  const ImageComparison cmp = compareImages(image, reference);
  Scene plain = scene;
  for (Material& m : plain.materials) m.albedoTexture = -1;
  const auto untextured = test_support::lightFieldAndReference(plain, camera, 64, bakePreset("draft"), 1);
  return {cmp.meanLuminanceRatio, cmp.relMseAverage, compareImages(untextured.reference, reference).meanLuminanceRatio};
}

// Measured (48 × 48, draft, 4 samples per pixel vs 256 spp; relMSE compare.h's):
//                     LF/PT    relMSE    before (maps held the untextured Lo)
//   textured GGX      0.984    0.0061    1.333, 0.214
//   textured Blinn    0.980    0.0065    1.375, 0.261
//   textured Lambert  0.982    0.0061    (diffuse charts: the same figures, so the 2 % is this
//                                         small box's, not the glossy charts')
// (with the renderers' former independent film points). With their stratified ones
// (render_settings.h pixelSample): GGX 1.0095, relMSE 0.0232; Blinn-Phong 1.0039, 0.0235 — 80 %
// of it two of the lamp's edge pixels where one of the 4 samples landed on the lamp (3.6 against
// the trace's 0.6: a chance of the fixed seed; 0.0032 at 16 samples per pixel).
// Bounds: the ratio within 0.03 and relMSE below 0.035, which the untextured light field
// misses by 6× and more.
TEST_F(TexturedGlossyTest, TexturedGgxWallsMatchThePathTracer) {
  const Figures f = compare(gltfMetallicRoughnessModel(Rgb(0.8f), 0.0f, 0.6f));
  std::printf("textured GGX: LF/PT %.4f relMSE %.5f (untextured/textured path trace %.3f)\n", f.ratio, f.relMse,
              f.untexturedRatio);
  EXPECT_GT(f.untexturedRatio, 1.3);  // the texture matters: without it the box is much brighter
  EXPECT_NEAR(f.ratio, 1.0, 0.03);
  EXPECT_LT(f.relMse, 0.035);
}

TEST_F(TexturedGlossyTest, TexturedBlinnPhongWallsMatchThePathTracer) {
  const Figures f = compare(BlinnPhongBsdf{Rgb(0.8f), Rgb(0.15f), 30.0f});
  std::printf("textured Blinn-Phong: LF/PT %.4f relMSE %.5f (untextured/textured path trace %.3f)\n", f.ratio, f.relMse,
              f.untexturedRatio);
  EXPECT_GT(f.untexturedRatio, 1.3);
  EXPECT_NEAR(f.ratio, 1.0, 0.03);
  EXPECT_LT(f.relMse, 0.035);
}

}  // namespace
}  // namespace pl
