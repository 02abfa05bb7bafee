// Tests of the straightforward light-field renderer on hand-made light fields whose
// rendered radiance has a closed form.
#include "render/render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "accel/accel.h"
#include "camera/camera.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "bake/bake.h"
#include "lightfield/lookup.h"
#include "plf/plf_file.h"
#include "scene/scene.h"
#include "support/sphere_mesh.h"

namespace pl {
namespace {

/// A quad mesh (two triangles) with corners c0, c1, c2, c3 counter-clockwise seen from the
/// front, one material.
Mesh makeQuad(const std::string& name, Vec3 c0, Vec3 c1, Vec3 c2, Vec3 c3, uint32_t material) {
  Mesh m;
  m.name = name;
  m.positions = {c0, c1, c2, c3};
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.materials = {material, material};
  return m;
}

/// A diffuse chart over the square [lo, hi] of the plane through `origin` spanned by
/// axisU, axisV, with res × res tixels whose stored irradiance is E0 + gradient·centre
/// (a linear field: bilinear interpolation reproduces it exactly between tixel centres).
Chart linearIrradianceChart(LightField& lf, uint32_t material, Vec3 origin, Vec3 axisU, Vec3 axisV, float side,
                            uint32_t res, float e0, Vec3 gradient) {
  Chart c;
  c.material = material;
  c.kind = ChartKind::Diffuse;
  c.origin = origin;
  c.axisU = axisU;
  c.axisV = axisV;
  c.normal = glm::cross(axisU, axisV);
  c.tixelSize = side / float(res);
  c.resU = c.resV = res;
  c.dirRes = 1;
  c.firstTixel = lf.stats.tixels;
  c.firstValue = lf.values.size();
  for (uint32_t j = 0; j < res; ++j)
    for (uint32_t i = 0; i < res; ++i) {
      const Vec3 centre = origin + (float(i) + 0.5f) * c.tixelSize * axisU + (float(j) + 0.5f) * c.tixelSize * axisV;
      lf.values.push_back(Rgb(e0 + glm::dot(gradient, centre)));
    }
  lf.stats.tixels += c.tixelCount();
  return c;
}

/// The irradiance the chart's clamp-to-edge bilinear interpolation gives at world point p:
/// for a linear field, the field at p with each grid coordinate clamped to the tixel centres.
float expectedIrradiance(const Chart& c, Vec3 p, float e0, Vec3 gradient) {
  const float half = 0.5f * c.tixelSize, side = c.tixelSize * float(c.resU);
  const float u = std::clamp(glm::dot(p - c.origin, c.axisU), half, side - half);
  const float v = std::clamp(glm::dot(p - c.origin, c.axisV), half, side - half);
  return e0 + glm::dot(gradient, c.origin + u * c.axisU + v * c.axisV);
}

class RenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { Progress::setEnabled(false); }
  ThreadPool pool_{2};
};

TEST_F(RenderTest, DiffuseChartWithLinearIrradianceMatchesClosedForm) {
  // A unit quad in z = 0 (front +z), albedo a, irradiance E(x, y) = 2 + 3x + 1.5y stored
  // on 4×4 tixels, seen from above; everything else is the constant environment.
  // Expected pixel value: a·E(hit)/π on the quad (Lambertian exitant radiance), the
  // environment elsewhere.
  LightField lf;
  const Rgb albedo(0.5f, 0.25f, 0.75f);
  lf.scene.sourcePath = "handmade";
  lf.scene.materials = {Material{"wall", LambertBsdf{albedo}, -1, Rgb(0.0f), false}};
  lf.scene.meshes = {makeQuad("quad", {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, 0)};
  lf.scene.environment.constant = Rgb(0.1f, 0.2f, 0.3f);
  lf.scene.finalize();
  const float e0 = 2.0f;
  const Vec3 gradient(3.0f, 1.5f, 0.0f);
  lf.charts = {linearIrradianceChart(lf, 0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1.0f, 4, e0, gradient)};
  lf.triangleChart = {{0, 0}};
  const Accel accel(lf.scene);

  CameraDesc desc;
  desc.eye = {0.5f, 0.5f, 2.0f};
  desc.target = {0.5f, 0.5f, 0.0f};
  desc.up = {0, 1, 0};
  desc.fovYDegrees = 40.0f;  // the quad fills the middle of the image, the environment the rest
  const Camera camera(desc, 40, 30);
  const Image image = renderLightField(lf, accel, camera, RenderSettings{});
  ASSERT_EQ(image.width, 40);
  ASSERT_EQ(image.height, 30);

  int onQuad = 0, onEnvironment = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Ray ray = camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f), Vec2(0.5f)).ray;
      const float t = -ray.origin.z / ray.direction.z;
      const Vec3 p = ray.origin + t * ray.direction;
      // Pixels whose ray passes within 1e-4 of the quad's border could go either way in
      // float arithmetic; they say nothing about the lookup.
      const float border = std::min({p.x, 1.0f - p.x, p.y, 1.0f - p.y});
      if (std::abs(border) < 1e-4f) continue;
      Rgb expected = lf.scene.environment.constant;
      if (border > 0.0f) {
        expected = albedo * expectedIrradiance(lf.charts[0], p, e0, gradient) * kInvPi;
        ++onQuad;
      } else {
        ++onEnvironment;
      }
      // Relative 1e-5: float rounding of the hit point and of the bilinear weights (the
      // values are O(1), errors of a few ulps), far below any interpolation mistake (which
      // would be ≥ 1 % here: the field changes by 0.75 per tixel).
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(image.at(x, y)[ch], expected[ch], 1e-5f * expected[ch]) << "pixel " << x << "," << y;
    }
  EXPECT_GT(onQuad, 200);
  EXPECT_GT(onEnvironment, 100);
}

TEST_F(RenderTest, MirrorReflectsTheDiffuseChartTimesReflectance) {
  // A mirror quad [−1,1]² in z = 0 facing up, under a diffuse ceiling at z = 3 facing down
  // whose irradiance grows linearly along x. The camera looks down at the mirror, so every
  // pixel sees the ceiling by one reflection: expected = reflectance · a·E(q)/π where q is
  // where the mirrored ray meets the ceiling.
  LightField lf;
  const Rgb reflectance(0.8f, 0.6f, 0.4f);
  const Rgb albedo(0.5f);
  lf.scene.sourcePath = "handmade-mirror";
  lf.scene.materials = {Material{"mirror", MirrorBsdf{reflectance, false}, -1, Rgb(0.0f), false},
                        Material{"ceiling", LambertBsdf{albedo}, -1, Rgb(0.0f), false}};
  lf.scene.meshes = {makeQuad("mirror", {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0),
                     makeQuad("ceiling", {-10, 10, 3}, {10, 10, 3}, {10, -10, 3}, {-10, -10, 3}, 1)};
  lf.scene.environment.constant = Rgb(0.0f);
  lf.scene.finalize();
  Chart mirror;
  mirror.material = 0;
  mirror.kind = ChartKind::Specular;
  mirror.dirRes = 0;
  mirror.origin = {-1, -1, 0};
  mirror.tixelSize = 2.0f;
  const float e0 = 4.0f;
  const Vec3 gradient(0.25f, 0.0f, 0.0f);
  // Ceiling frame: normal −z, axisU = +x, axisV = normal × axisU = −y, origin at (−10, 10, 3).
  const Chart ceiling = linearIrradianceChart(lf, 1, {-10, 10, 3}, {1, 0, 0}, {0, -1, 0}, 20.0f, 8, e0, gradient);
  ASSERT_NEAR(ceiling.normal.z, -1.0f, 1e-6f);
  lf.charts = {mirror, ceiling};
  lf.triangleChart = {{0, 0}, {1, 1}};
  lf.settings.mirrorDepth = 4;
  const Accel accel(lf.scene);

  CameraDesc desc;
  desc.eye = {0.3f, -1.0f, 2.0f};
  desc.target = {0.0f, 0.0f, 0.0f};
  desc.fovYDegrees = 25.0f;
  const Camera camera(desc, 24, 24);
  const Image image = renderLightField(lf, accel, camera, RenderSettings{});
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Ray ray = camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f), Vec2(0.5f)).ray;
      const Vec3 p = ray.origin + (-ray.origin.z / ray.direction.z) * ray.direction;
      ASSERT_LT(std::max(std::abs(p.x), std::abs(p.y)), 1.0f) << "camera must see only the mirror";
      const Vec3 reflected(ray.direction.x, ray.direction.y, -ray.direction.z);
      const Vec3 q = p + ((3.0f - p.z) / reflected.z) * reflected;
      const Rgb expected = reflectance * albedo * expectedIrradiance(ceiling, q, e0, gradient) * kInvPi;
      // Relative 1e-4: the reflected ray starts from an offset origin (2e-5 relative, see
      // offsetRayOrigin) and travels ~3 units, moving q by ~1e-4 along a field of slope
      // 0.25/4 per unit: a relative change of < 1e-5; float rounding adds a few ulps.
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(image.at(x, y)[ch], expected[ch], 1e-4f * expected[ch]) << "pixel " << x << "," << y;
    }

  // With no reflections allowed the mirror (which does not emit) is black, as a chain longer
  // than the bake's mirror depth contributes nothing.
  RenderSettings noMirrors;
  noMirrors.mirrorDepth = 0;
  const Image black = renderLightField(lf, accel, camera, noMirrors);
  for (const Rgb& pixel : black.pixels) EXPECT_EQ(pixel, Rgb(0.0f));
}

TEST_F(RenderTest, SeveralSamplesAverageTheLookupAndAreReproducible) {
  // A chart of constant irradiance seen through a thin lens: every aperture and film sample
  // sees the same radiance, so the image is uniform a·E/π; the random streams depend on
  // (pixel, sample, seed) only, so two renders are identical.
  LightField lf;
  const Rgb albedo(0.6f);
  lf.scene.materials = {Material{"wall", LambertBsdf{albedo}, -1, Rgb(0.0f), false}};
  lf.scene.meshes = {makeQuad("quad", {-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}, 0)};
  lf.scene.finalize();
  lf.charts = {linearIrradianceChart(lf, 0, {-50, -50, 0}, {1, 0, 0}, {0, 1, 0}, 100.0f, 2, 5.0f, Vec3(0.0f))};
  lf.triangleChart = {{0, 0}};
  const Accel accel(lf.scene);
  CameraDesc desc;
  desc.eye = {0, 0, 5};
  desc.target = {0, 0, 0};
  desc.fNumber = 2.0f;
  desc.focusDistance = 3.0f;  // out of focus: the lens samples spread over the quad
  desc.focalLengthMm = 50.0f;
  const Camera camera(desc, 16, 12);
  ASSERT_TRUE(camera.isThinLens());
  const Image a = renderLightField(lf, accel, camera, RenderSettings{});
  const Image b = renderLightField(lf, accel, camera, RenderSettings{});
  EXPECT_EQ(a.pixels, b.pixels);
  const float expected = 0.6f * 5.0f * kInvPi;
  // Relative 1e-5: a mean of 16 equal float values.
  for (const Rgb& pixel : a.pixels) EXPECT_NEAR(pixel.g, expected, 1e-5f * expected);
}

// The ray-cone level of detail (lookup.h albedoTextureLod with the camera's textureConeSpread)
// in its closed form: on a plane facing the camera at distance d the level is log2 of the
// texels one pixel spans — measured here independently, from the uvs where the rays of two
// neighbouring pixel centres land. Four times the distance is two levels more; a plane turned
// by 60° about the horizontal (cos θ = ½) half a level more than facing: its footprint is
// twice as long along the view and as wide across it, twice the area (lookup.h: the level
// follows the footprint's area).
TEST_F(RenderTest, TextureLodOfAPlaneFacingTheCameraIsLog2OfTexelsPerPixel) {
  Scene scene;
  scene.materials = {Material{"plane", LambertBsdf{Rgb(1.0f)}, 0, Rgb(0.0f), false}};
  Texture texture;
  texture.path = "1024";
  texture.image = Image(1024, 1024);  // only its size matters here
  scene.textures = {texture};
  CameraDesc desc;
  desc.eye = {0, 0, 0};
  desc.target = {0, 0, -1};
  desc.fovYDegrees = 40.0f;
  const Camera camera(desc, 64, 48);
  const float spread = textureConeSpread(RenderSettings{}, camera.pixelSpread(), 1);
  auto levelAndTexelsPerPixel = [&](float distance, float tilt) {
    // A 2 × 2 quad (uv 0…1: 512 texels per unit) through (0, 0, −d), turned by `tilt` about x.
    const Vec3 centre(0.0f, 0.0f, -distance), u(1.0f, 0.0f, 0.0f), v(0.0f, std::cos(tilt), -std::sin(tilt));
    scene.meshes = {makeQuad("plane", centre - u - v, centre + u - v, centre + u + v, centre - u + v, 0)};
    scene.finalize();
    const Accel accel(scene);
    Vec2 uv[2];
    float level = 0.0f;
    for (int k = 0; k < 2; ++k) {
      const Ray ray = camera.generateRay(Vec2(32.0f + float(k), 24.0f), Vec2(0.5f)).ray;  // centre pixel and its right neighbour
      RayHit hit;
      EXPECT_TRUE(accel.intersect(ray, hit));
      uv[k] = uvAt(scene.meshes[0], hit.triangle, hit.barycentrics);
      if (k == 0) level = albedoLodAt(scene, 0, hit.mesh, hit.triangle, ray.direction, spread * hit.t);
    }
    return std::pair(level, glm::length(uv[1] - uv[0]) * 1024.0f);
  };
  const auto [near, nearTexels] = levelAndTexelsPerPixel(2.5f, 0.0f);
  const auto [far, farTexels] = levelAndTexelsPerPixel(10.0f, 0.0f);
  const auto [tilted, tiltedTexels] = levelAndTexelsPerPixel(10.0f, kPi / 3.0f);
  // 0.01 levels: approximateLog2 is within 0.0078; the neighbouring pixel's ray is 1/48 of
  // the fov off the axis, so its footprint differs from the centre pixel's by cos² of ~0.8°
  // (4e-4 of a level).
  EXPECT_NEAR(near, std::log2(nearTexels), 0.01f);
  EXPECT_NEAR(far, std::log2(farTexels), 0.01f);
  EXPECT_NEAR(far - near, 2.0f, 1e-4f);
  EXPECT_NEAR(tilted - far, 0.5f, 1e-3f);
  EXPECT_GT(far, 5.0f);  // 512 texels per unit, 0.15 units per pixel at d = 10: ≈ 78 texels
  // Off: no cone, full resolution.
  RenderSettings off;
  off.textureLod = false;
  EXPECT_EQ(textureConeSpread(off, camera.pixelSpread(), 1), 0.0f);
}

// What texture LOD is for: a checkerboard floor seen at a glancing angle, minified up to many
// texels per pixel. One sample per pixel at full resolution picks one texel per pixel (the
// pattern aliases into noise and moiré); with LOD each pixel reads the texture's average over
// its footprint. Both are compared with the same floor at 256 jittered samples per pixel and
// full resolution (the pixel's true box average), as an RMS difference over the image.
TEST_F(RenderTest, TextureLodBringsOneSampleOfAMinifiedCheckerboardCloseToTheSupersampledImage) {
  LightField lf;
  lf.scene.sourcePath = "checkerboard";
  Texture checker;
  checker.path = "checker";
  checker.image = Image(64, 64);  // squares of 2 × 2 texels, 0.1 and 0.9
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) checker.image.at(x, y) = Rgb(((x / 2 + y / 2) % 2) != 0 ? 0.9f : 0.1f);
  lf.scene.textures = {checker};
  lf.scene.materials = {Material{"floor", LambertBsdf{Rgb(1.0f)}, 0, Rgb(0.0f), false}};
  Mesh floor = makeQuad("floor", {-20, 0, 0}, {20, 0, 0}, {20, 0, -40}, {-20, 0, -40}, 0);
  for (Vec2& uv : floor.uvs) uv *= 40.0f;  // the texture repeated once per scene unit: 64 texels per unit
  lf.scene.meshes = {floor};
  lf.scene.finalize();
  // Irradiance π everywhere: the radiance is the albedo texel itself.
  lf.charts = {linearIrradianceChart(lf, 0, {-20, 0, 0}, {1, 0, 0}, {0, 0, -1}, 40.0f, 4, kPi, Vec3(0.0f))};
  lf.triangleChart = {{0, 0}};
  const Accel accel(lf.scene);
  CameraDesc desc;
  desc.eye = {0.0f, 1.5f, 0.5f};
  desc.target = {0.0f, 0.0f, -6.0f};
  desc.fovYDegrees = 40.0f;
  const Camera camera(desc, 64, 48);
  RenderSettings truth, withLod, withoutLod;
  truth.samplesPerPixel = 256;
  truth.textureLod = false;
  withoutLod.textureLod = false;
  const Image reference = renderLightField(lf, accel, camera, truth);
  auto rmsDifference = [&](const RenderSettings& settings) {
    const Image image = renderLightField(lf, accel, camera, settings);
    double sum = 0.0;
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      const Rgb d = image.pixels[i] - reference.pixels[i];
      sum += double(glm::dot(d, d)) / 3.0;
    }
    return std::sqrt(sum / double(image.pixels.size()));
  };
  const double lod = rmsDifference(withLod), fullResolution = rmsDifference(withoutLod);
  ::testing::Test::RecordProperty("rms_with_lod", std::to_string(lod));
  ::testing::Test::RecordProperty("rms_full_resolution", std::to_string(fullResolution));
  std::printf("checkerboard, 1 spp vs 256 spp: RMS difference %.4f with LOD, %.4f at full resolution\n", lod,
              fullResolution);
  // Measured: 0.030 with LOD, 0.205 at full resolution. The margin: LOD must remove at least
  // two thirds of the aliasing error (the rest is the isotropic cone's overblur at grazing
  // angles and the 256-sample reference's own noise).
  EXPECT_LT(lod, fullResolution / 3.0);
  EXPECT_GT(fullResolution, 0.1);  // the scene does alias at full resolution (0.8 contrast)
}

TEST_F(RenderTest, GlossyChartIsLookedUpInTheDirectionTowardsTheViewer) {
  // A glossy chart (8×8 paraboloid map per tixel) whose stored radiance is linear in the
  // direction texel coordinates, L(a, b) = 1 + 0.5a + 0.25b, the same at every tixel. The
  // direction bilinear interpolation reproduces it exactly, so the pixel must equal
  // 1 + 0.5·ca + 0.25·cb at the continuous texel coordinates of the direction *towards the
  // camera* in the chart frame: (s, t) = (x, y)/(1 + z) (lightfield.h), texel centres at
  // s = −1 + (2a + 1)/R. Looking the map up with the ray direction instead (pointing into
  // the surface) or with swapped axes gives other values.
  LightField lf;
  lf.scene.materials = {Material{"glossy", GgxBsdf{}, -1, Rgb(0.0f), false}};
  lf.scene.meshes = {makeQuad("quad", {-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}, 0)};
  lf.scene.finalize();
  Chart c;
  c.material = 0;
  c.kind = ChartKind::Glossy;
  c.origin = {-3, -3, 0};
  c.tixelSize = 3.0f;
  c.resU = c.resV = 2;
  const uint32_t R = 8;
  c.dirRes = R;
  for (uint32_t tixel = 0; tixel < 4; ++tixel)
    for (uint32_t b = 0; b < R; ++b)
      for (uint32_t a = 0; a < R; ++a) lf.values.push_back(Rgb(1.0f + 0.5f * float(a) + 0.25f * float(b)));
  lf.charts = {c};
  lf.triangleChart = {{0, 0}};
  const Accel accel(lf.scene);
  CameraDesc desc;
  desc.eye = {-1.5f, -0.7f, 1.2f};  // oblique: s and t both vary across the image
  desc.target = {0.0f, 0.0f, 0.0f};
  desc.fovYDegrees = 30.0f;
  const Camera camera(desc, 20, 16);
  const Image image = renderLightField(lf, accel, camera, RenderSettings{});
  float lo = kInfinity, hi = 0.0f;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Ray ray = camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f), Vec2(0.5f)).ray;
      const Vec3 p = ray.origin + (-ray.origin.z / ray.direction.z) * ray.direction;
      ASSERT_LT(std::max(std::abs(p.x), std::abs(p.y)), 3.0f) << "camera must see only the chart";
      const Vec3 towardsViewer = -ray.direction;  // chart frame = world frame here
      const Vec2 st = Vec2(towardsViewer.x, towardsViewer.y) / (1.0f + towardsViewer.z);
      auto texel = [&](float v) { return std::clamp((v + 1.0f) * 0.5f * float(R) - 0.5f, 0.0f, float(R - 1)); };
      const float expected = 1.0f + 0.5f * texel(st.x) + 0.25f * texel(st.y);
      // Relative 1e-5: float rounding of (s, t) and of the bilinear weights.
      EXPECT_NEAR(image.at(x, y).g, expected, 1e-5f * expected) << "pixel " << x << "," << y;
      lo = std::min(lo, expected);
      hi = std::max(hi, expected);
    }
  EXPECT_GT(hi - lo, 0.5f) << "the view must sweep several direction texels";
}

TEST_F(RenderTest, MissesSeeTheEnvironmentMapAlongTheRay) {
  // Rays that leave the scene see Le(direction) = constant + map radiance along the ray's own
  // direction (towards the sky). The map varies with direction, so a sign error or a frame
  // mix-up shows. The only geometry is a small quad behind the camera.
  LightField lf;
  lf.scene.materials = {Material{"wall", LambertBsdf{Rgb(0.5f)}, -1, Rgb(0.0f), false}};
  lf.scene.meshes = {makeQuad("behind", {-1, -1, 10}, {1, -1, 10}, {1, 1, 10}, {-1, 1, 10}, 0)};
  lf.scene.environment.constant = Rgb(0.05f);
  LatLongMap sky;
  sky.image = Image(16, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) sky.image.at(x, y) = Rgb(float(x), float(y), 1.0f);
  lf.scene.environment.map = std::make_shared<const EnvironmentMap>(sky, 0.5f, 20.0f);
  lf.scene.finalize();
  lf.charts = {linearIrradianceChart(lf, 0, {-1, -1, 10}, {1, 0, 0}, {0, 1, 0}, 2.0f, 1, 1.0f, Vec3(0.0f))};
  lf.triangleChart = {{0, 0}};
  const Accel accel(lf.scene);
  CameraDesc desc;
  desc.eye = {0, 0, 0};
  desc.target = {0.3f, 0.4f, -1.0f};
  desc.fovYDegrees = 90.0f;
  const Camera camera(desc, 24, 18);
  const Image image = renderLightField(lf, accel, camera, RenderSettings{});
  float lo = kInfinity, hi = 0.0f;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Ray ray = camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f), Vec2(0.5f)).ray;
      const Rgb expected = lf.scene.environment.radiance(ray.direction);
      // The same function evaluated on the same ray: equal up to float rounding.
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(image.at(x, y)[ch], expected[ch], 1e-6f * expected[ch]) << "pixel " << x << "," << y;
      lo = std::min(lo, expected.r);
      hi = std::max(hi, expected.r);
    }
  EXPECT_GT(hi - lo, 1.0f) << "the view must sweep a varying part of the map";
}

/// A closed cube [−1, 1]³ whose six faces point inwards, all Lambertian with albedo a and
/// emitting Le: the white furnace. Radiance everywhere inside is L = Le/(1 − a) (the Neumann
/// series Le·(1 + a + a² + …)).
Scene makeFurnace(float albedo, float emission) {
  Scene scene;
  scene.sourcePath = "furnace";
  scene.materials = {Material{"furnace", LambertBsdf{Rgb(albedo)}, -1, Rgb(emission), false}};
  const Vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const Vec3& n : normals) {
    // Inward normal n: the face lies at −n; t1 × t2 = n makes the winding face inwards.
    const Vec3 t1 = std::abs(n.x) > 0.5f ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    const Vec3 t2 = glm::cross(n, t1);
    scene.meshes.push_back(makeQuad("face", -n - t1 - t2, -n + t1 - t2, -n + t1 + t2, -n - t1 + t2, 0));
  }
  scene.finalize();
  return scene;
}

TEST_F(RenderTest, BakedWhiteFurnaceRendersLeOverOneMinusAlbedo) {
  const float albedo = 0.5f, emission = 1.0f;
  BakeSettings settings = bakePreset("draft");
  const LightField baked = bake(makeFurnace(albedo, emission), settings);
  // Through the file, as `plenoptic render` sees it.
  const std::string path = ::testing::TempDir() + "furnace_render_test.plf";
  writeLightField(path, baked);
  const LightField lf = readLightField(path);
  std::remove(path.c_str());
  const Accel accel(lf.scene);
  CameraDesc desc;
  desc.eye = {0.1f, 0.2f, 0.3f};
  desc.target = {1.0f, 0.5f, -1.0f};
  desc.fovYDegrees = 100.0f;  // wide: edges and corners of several faces in view
  const Image image = renderLightField(lf, accel, Camera(desc, 32, 24), RenderSettings{});
  const float expected = emission / (1.0f - albedo);
  // 1 %: the furnace criterion. The converged bake is exact for a uniform field up to
  // its stopping tolerance (draft: 5e-3 relative change, leaving ≈ 5e-3·a/(1−a) = 0.5 %),
  // and the lookup interpolates a uniform field exactly.
  for (const Rgb& pixel : image.pixels)
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(pixel[ch], expected, 0.01f * expected);
}

TEST_F(RenderTest, TexturedBakeRoundTripsThroughThePlfWithTheImageFileNotItsPixels) {
  // The OBJ's albedo texture is a PNG: the .plf stores that file's bytes and decodes them on
  // load, which must give the very pixels the scene loader had, hence the same render.
  const std::string png = std::string(PLENOPTIC_TEST_DATA_DIR) + "/scene/textured/mat/checker.png";
  Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/scene/textured/quad.obj");
  scene.environment.constant = Rgb(1.0f, 0.8f, 0.6f);  // something to light the quad with
  BakeSettings settings = bakePreset("draft");
  const LightField baked = bake(std::move(scene), settings);
  ASSERT_EQ(baked.scene.textures.size(), 1u);
  ASSERT_TRUE(baked.scene.textures[0].encoded);
  const std::string path = ::testing::TempDir() + "textured_render_test.plf";
  writeLightField(path, baked);
  const LightField lf = readLightField(path);
  const PlfInfo info = readLightFieldInfo(path);
  std::remove(path.c_str());

  ASSERT_EQ(lf.scene.textures.size(), 1u);
  const Texture& before = baked.scene.textures[0];
  const Texture& after = lf.scene.textures[0];
  EXPECT_EQ(after.path, before.path);
  ASSERT_TRUE(after.encoded);
  EXPECT_EQ(*after.encoded, *before.encoded);
  EXPECT_EQ(after.encoded->size(), std::filesystem::file_size(png));  // the file as it was
  ASSERT_EQ(after.image.width, before.image.width);
  ASSERT_EQ(after.image.height, before.image.height);
  for (size_t i = 0; i < before.image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(after.image.pixels[i][c], before.image.pixels[i][c]) << i;
  for (int c = 0; c < 3; ++c) EXPECT_EQ(after.average[c], before.average[c]);
  EXPECT_EQ(info.textures, 1u);

  CameraDesc desc;
  desc.eye = {0.5f, 0.5f, 1.5f};
  desc.target = {0.5f, 0.5f, 0.0f};
  desc.fovYDegrees = 50.0f;
  const Camera camera(desc, 24, 24);
  const Accel accelBefore(baked.scene), accelAfter(lf.scene);
  const Image imageBefore = renderLightField(baked, accelBefore, camera, RenderSettings{});
  const Image imageAfter = renderLightField(lf, accelAfter, camera, RenderSettings{});
  ASSERT_EQ(imageAfter.pixels.size(), imageBefore.pixels.size());
  float brightest = 0.0f;
  for (size_t i = 0; i < imageBefore.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(imageAfter.pixels[i][c], imageBefore.pixels[i][c]) << "pixel " << i;
      brightest = std::max(brightest, imageBefore.pixels[i][c]);
    }
  EXPECT_GT(brightest, 0.0f);  // the comparison is of a lit, textured quad
}

/// The white furnace (L = Le/(1 − a) = 2 everywhere, a = ½, Le = 1) with a clear glass sphere
/// in it, baked (draft preset, converged) and rendered at 16 samples per pixel: the mean of
/// the green channel and its brightest pixel over a 32 × 24 view of the sphere and the walls
/// around it, each divided by the expected 2. causticPhotons: BakeSettings::causticPhotons
/// (the walls' light seen through the glass gathered, or shot as photons: caustics.h).
void glassFurnace(const DielectricBsdf& glass, double& meanOverExpected, double& brightestOverExpected,
                  uint64_t causticPhotons = 0) {
  const float albedo = 0.5f, emission = 1.0f;
  Scene scene = makeFurnace(albedo, emission);
  scene.materials.push_back(Material{"glass", glass, -1, Rgb(0.0f), false});
  Mesh sphere;
  sphere.name = "sphere";
  test_support::addSphere(sphere, Vec3(0.1f, -0.2f, 0.0f), 0.5f, 24, 48, 1);
  scene.meshes.push_back(std::move(sphere));
  scene.finalize();
  BakeSettings settings = bakePreset("draft");
  settings.tolerance = 1e-5f;  // converged: the furnace error left is the glass's
  settings.maxIterations = 400;
  settings.causticPhotons = causticPhotons;
  const LightField lf = bake(std::move(scene), settings);
  const Accel accel(lf.scene);
  CameraDesc desc;
  desc.eye = {0.0f, 0.3f, 0.9f};
  desc.target = {0.1f, -0.2f, 0.0f};
  desc.fovYDegrees = 70.0f;  // the sphere and the walls around it
  RenderSettings render;
  render.samplesPerPixel = 16;
  const Image image = renderLightField(lf, accel, Camera(desc, 32, 24), render);
  const double expected = emission / (1.0f - albedo);
  double sum = 0.0, brightest = 0.0;
  for (const Rgb& pixel : image.pixels) {
    sum += pixel.g;
    brightest = std::max(brightest, double(pixel.g));
  }
  meanOverExpected = sum / double(image.pixels.size()) / expected;
  brightestOverExpected = brightest / expected;
}

TEST_F(RenderTest, GlassSphereInTheFurnaceIsInvisible) {
  // The walls gather through the smooth glass (bake) and the camera looks through it (render).
  // Each glass chain ends on a wall of radiance L with weight 1 (reflection) or 1/η²·η² (in and
  // out), so the sphere is invisible, except that chains longer than the depth limit end
  // with nothing: near the silhouette a ray refracted in at grazing incidence meets the
  // inside at the critical angle, where F ≈ 1, and circles inside for many steps. A hard cut
  // at 8 lost 1.5 % of this image; with roulette from step 8 the limit still matters (these
  // chains reflect with weight 1): −0.37 % at 64, −0.19 % at 128, −0.03 % at 256, the
  // default (measured with the gather directions' earlier jitter; −0.06 % at 256 with the
  // multi-jittered ones). The default settings are checked here, with the light seen through
  // the glass gathered (exact per tixel: no pixel brighter than 2) and shot as caustic photons
  // (the draft preset's 2²⁰: the mean as exact — the photons' flux crosses the glass with
  // weight t, not the radiance's t/η'² — and each pixel within the photons' noise, measured
  // +1.2 % at the brightest).
  for (const uint64_t photons : {uint64_t(0), bakePreset("draft").causticPhotons}) {
    double mean = 0.0, brightest = 0.0;
    glassFurnace(DielectricBsdf{1.5f}, mean, brightest, photons);
    EXPECT_LE(brightest, photons == 0 ? 1.005 : 1.03);  // never brighter: glass creates no energy
    // 0.5 %: the light-field glass furnace criterion (measured error printed).
    std::printf("glass furnace in the light field, %llu caustic photons: mean error %+.2e\n",
                static_cast<unsigned long long>(photons), mean - 1.0);
    EXPECT_NEAR(mean, 1.0, 0.005);
  }
}

TEST_F(RenderTest, RoughGlassSphereInTheFurnaceIsNearlyInvisible) {
  // The same with rough glass (α = 0.25), stored on both sides of every chart like a glossy
  // surface: outside, Lo = R·L + T·(η²L) = L when the BSDF conserves energy (T carries the
  // 1/η² of radiance leaving the dense side, the inside holds η²L). What is left is the
  // discretisation: the operators' quadrature of the lobe over gather cells and output texels,
  // the bilinear lookups, and the rough BSDF's own energy balance (the path tracer's rough
  // glass furnace: within 0.3 %). Measured: mean −0.17 %, brightest pixel +0.15 %; checked
  // at the 0.5 % furnace criterion.
  DielectricBsdf glass;
  glass.ior = 1.5f;
  glass.alpha = 0.25f;
  double mean = 0.0, brightest = 0.0;
  glassFurnace(glass, mean, brightest);
  std::printf("rough glass furnace in the light field: mean error %+.2e, brightest pixel %+.2e\n", mean - 1.0,
              brightest - 1.0);
  EXPECT_NEAR(mean, 1.0, 0.005);
  EXPECT_LE(brightest, 1.005);
}

}  // namespace
}  // namespace pl
