// Sun masks (lightfield.h "Sun masks", issue 13 item 2): a directional light's shadow edge on a
// coarse light field is placed and sharp to a quarter of a tixel, where interpolating the
// tixels' own irradiance spreads it over a whole tixel; away from the edge the masked and the
// unmasked light fields agree (the masked light leaves the stored irradiance exactly as it is
// added back); and the rendered image is closer to the path tracer's.
//
// The scene: a Lambertian floor (y = 0, |x|, |z| ≤ 2) under a closed slab (x ≤ 0.137,
// 1 ≤ y ≤ 1.1) lit by a sun travelling along (−0.2, −1, 0), nothing else: the slab's shadow on
// the floor ends at x = 0.137 − 0.2 = −0.063, a line along z that no tixel boundary follows
// (tixels 0.25 wide, boundaries at multiples of 0.25).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "accel/accel.h"
#include "bake/bake.h"
#include "camera/camera.h"
#include "core/progress.h"
#include "lightfield/lookup.h"
#include "realtime/realtime.h"
#include "render/render.h"
#include "scene/scene.h"
#include "support/quad_mesh.h"
#include "trace/trace.h"

namespace pl {
namespace {

using test_support::addQuad;

constexpr float kEdgeX = -0.063f;  ///< where the slab's shadow ends on the floor
constexpr float kTixel = 0.25f;

class SunMaskTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { Progress::setEnabled(false); }
};

Scene makeSlabScene() {
  Scene scene;
  scene.sourcePath = "slab over a floor";
  scene.materials = {Material{.name = "floor", .bsdf = LambertBsdf{Rgb(0.6f)}},
                     Material{.name = "slab", .bsdf = LambertBsdf{Rgb(0.3f)}}};
  Mesh floor, slab;
  addQuad(floor, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
  // The slab: a closed box, faces counter-clockwise seen from outside.
  const float x0 = -3.0f, x1 = 0.137f, y0 = 1.0f, y1 = 1.1f, z0 = -3.0f, z1 = 3.0f;
  addQuad(slab, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, 1);  // top (+y)
  addQuad(slab, {x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}, 1);  // bottom (−y)
  addQuad(slab, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}, 1);  // +x
  addQuad(slab, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}, 1);  // −x
  addQuad(slab, {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}, 1);  // +z
  addQuad(slab, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}, 1);  // −z
  scene.meshes = {floor, slab};
  scene.lights.push_back(DirectionalLight{glm::normalize(Vec3(-0.2f, -1.0f, 0.0f)), Rgb(3.0f)});
  scene.finalize();
  return scene;
}

BakeSettings coarseSettings(bool sunMasks) {
  BakeSettings settings;
  settings.preset = "test";
  settings.tixelsPerUnit = 1.0f / kTixel;
  settings.gatherDirections = 64;
  settings.tolerance = 1e-4f;
  settings.sunMasks = sunMasks;
  return settings;
}

/// The light field's radiance towards +y at floor points (x, 0, 0.3) for x in `xs`.
std::vector<float> floorProfile(const LightField& lf, const std::vector<float>& xs) {
  const Accel accel(lf.scene);
  std::vector<float> profile;
  for (float x : xs) {
    RayHit hit;
    // From between the floor and the slab, straight down.
    EXPECT_TRUE(accel.intersect(Ray{Vec3(x, 0.5f, 0.3f), Vec3(0.0f, -1.0f, 0.0f), 0.0f, kInfinity}, hit));
    EXPECT_EQ(hit.mesh, 0u);
    profile.push_back(luminance(exitantRadiance(lf, hit, positionAt(lf.scene.meshes[hit.mesh], hit.triangle, hit.barycentrics),
                                                Vec3(0.0f, 1.0f, 0.0f), 0.0f)));
  }
  return profile;
}

struct Edge {
  float halfHeight;  ///< where the profile crosses halfway between its shadowed and lit levels
  float width;       ///< from 10 % to 90 % of the step
};

/// The step of a rising profile sampled at xs (shadow on the left): its levels from the ends.
Edge edgeOf(const std::vector<float>& xs, const std::vector<float>& profile) {
  const float low = profile.front(), high = profile.back();
  auto crossing = [&](float fraction) {
    const float level = low + fraction * (high - low);
    for (size_t i = 1; i < xs.size(); ++i)
      if (profile[i] >= level && profile[i - 1] < level)
        return xs[i - 1] + (xs[i] - xs[i - 1]) * (level - profile[i - 1]) / (profile[i] - profile[i - 1]);
    return kInfinity;
  };
  return {crossing(0.5f), crossing(0.9f) - crossing(0.1f)};
}

TEST_F(SunMaskTest, TheSunsShadowEdgeIsPlacedAndSharpToAQuarterTixel) {
  const Scene scene = makeSlabScene();
  const LightField masked = bake(Scene(scene), coarseSettings(true));
  const LightField plain = bake(Scene(scene), coarseSettings(false));
  ASSERT_EQ(masked.sunMaskLightCount, 1u);
  ASSERT_EQ(masked.sunMasks.size(), masked.stats.tixels);
  EXPECT_EQ(plain.sunMaskLightCount, 0u);
  EXPECT_TRUE(plain.sunMasks.empty());

  // x from 1 tixel left to 1 tixel right of the edge, in 1/40 tixel steps.
  std::vector<float> xs;
  for (int i = 0; i <= 80; ++i) xs.push_back(kEdgeX - kTixel + kTixel * float(i) / 40.0f);
  const std::vector<float> withMasks = floorProfile(masked, xs), without = floorProfile(plain, xs);
  const Edge sharp = edgeOf(xs, withMasks), blurred = edgeOf(xs, without);
  std::printf("shadow edge at x = %.4f: with masks half height at %.4f, 10-90 %% width %.3f tixel; without: %.4f, %.3f tixel\n",
              kEdgeX, sharp.halfHeight, sharp.width / kTixel, blurred.halfHeight, blurred.width / kTixel);
  // Measured: half height 0.0004 from the edge, width 0.20 tixel (the masks' quarter-tixel
  // sub-samples, bilinear); bounds at the resolution the masks promise, a quarter tixel.
  EXPECT_NEAR(sharp.halfHeight, kEdgeX, 0.25f * kTixel);
  EXPECT_LT(sharp.width, 0.4f * kTixel);
  // Without masks the step is spread over the tixel the edge falls in (measured 0.80 tixel,
  // its half height on the tixel boundary): the test can fail.
  EXPECT_GT(blurred.width, 0.6f * kTixel);

  // In the sun, a tixel and more away from the edge, both light fields hold the same light:
  // the masked light goes out of the stored irradiance and back in through the masks. They
  // differ only by the interreflected part (measured 0.13 %; bound 1 %), which moves because
  // the first shot of the tixels the edge crosses is their footprint's mean with masks, one
  // ray's 0 or 1 without. (In the shadow, where only interreflected light arrives, that is
  // ~10 %.)
  const std::vector<float> far = {0.3f, 0.6f, 1.0f, 1.5f};
  const std::vector<float> farMasked = floorProfile(masked, far), farPlain = floorProfile(plain, far);
  float largest = 0.0f;
  for (size_t i = 0; i < far.size(); ++i) largest = std::max(largest, std::abs(farMasked[i] / farPlain[i] - 1.0f));
  std::printf("in the sun, masked / unmasked differ by at most %.2g\n", largest);
  for (size_t i = 0; i < far.size(); ++i)
    EXPECT_NEAR(farMasked[i], farPlain[i], 0.01f * farPlain[i]) << "x = " << far[i];
}

// The rendered floor against the path tracer, seen from the lit side under the slab: the
// masked light field's error is well below the unmasked one's (most of it at the edge), and
// both renderers agree on the masked field.
TEST_F(SunMaskTest, MaskedLightFieldIsCloserToThePathTracerAtTheEdge) {
  const Scene scene = makeSlabScene();
  CameraDesc desc;
  desc.name = "under the slab";
  desc.eye = Vec3(1.5f, 0.8f, 0.1f);
  desc.target = Vec3(-0.3f, 0.0f, 0.0f);
  desc.fovYDegrees = 30.0f;
  const Camera camera(desc, 96, 72);
  Image reference;
  {
    const Accel accel(scene);
    const PathTracer tracer(scene, accel);
    TraceSettings trace;
    trace.spp = 256;
    trace.showProgress = false;
    reference = tracer.render(camera, trace).radiance;
  }
  auto relMse = [&](const Image& image) {
    double sum = 0.0;
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      const float a = luminance(image.pixels[i]), b = luminance(reference.pixels[i]);
      sum += double(a - b) * double(a - b) / (double(b) * double(b) + 0.01);
    }
    return sum / double(image.pixels.size());
  };
  double errors[2];
  for (const bool sunMasks : {false, true}) {
    const LightField lf = bake(Scene(scene), coarseSettings(sunMasks));
    const Accel accel(lf.scene);
    RenderSettings settings;
    settings.samplesPerPixel = 1;
    const Image image = renderLightField(lf, accel, camera, settings);
    errors[sunMasks] = relMse(image);
    if (sunMasks) {
      const Image fast = FastRenderer(lf, accel).render(camera, settings);
      for (size_t i = 0; i < image.pixels.size(); ++i)
        // Float rounding only: the hit point from the ray, not the barycentrics (realtime.h).
        ASSERT_NEAR(luminance(fast.pixels[i]), luminance(image.pixels[i]), 1e-4f * luminance(image.pixels[i]) + 1e-6f) << i;
    }
  }
  std::printf("relMSE against the path tracer: %.3g with masks, %.3g without\n", errors[1], errors[0]);
  // Measured 0.0084 against 0.0256 (the 256-spp trace's own noise is part of both).
  EXPECT_LT(errors[1], 0.5 * errors[0]) << "relMSE with masks " << errors[1] << ", without " << errors[0];
}

}  // namespace
}  // namespace pl
