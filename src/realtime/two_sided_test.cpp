// Two-sided surfaces (issue 13 item 3), end to end: a thin sheet lit from one side looks the
// same in the path tracer and in the light field (bake + both renderers) from both sides, and
// the sidedness rule itself (lightfield.h "Sides", scene.h emittedRadiance) on small cases.
//
// The scene: a Lambertian floor (y = 0, |x|, |z| ≤ 2) and a vertical sheet above it (x = 0,
// 0.5 ≤ y ≤ 1.5, |z| ≤ 1), both single open quads, under a point light at (1.5, 3, 0). The
// sheet's front (+x, facing the light) is lit directly; its back (−x) only by the floor behind
// it, which the light reaches under the sheet (x ∈ [−0.3, 0]) and over it (x < −1.5): a back
// side whose radiance is all interreflection, a few per cent of the front's. (The sheet does
// not stand on the floor: where it would, bilinear interpolation of the floor's irradiance
// across the sheet's foot leaks lit floor behind it — the seam problem of issue 13 item 2,
// not the sidedness this test is about.) Before two-sided charts the light field
// gave the back the front's irradiance (≈ 40× too bright) and the bake gave it nothing to pass on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "camera/camera.h"
#include "core/progress.h"
#include "bake/bake.h"
#include "lightfield/lookup.h"
#include "bake/parameterisation.h"
#include "realtime/realtime.h"
#include "render/render.h"
#include "scene/scene.h"
#include "trace/trace.h"
#include "support/light_field_vs_trace.h"
#include "support/quad_mesh.h"
#include "support/sphere_mesh.h"

namespace pl {
namespace {

class TwoSidedTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { Progress::setEnabled(false); }
};

using test_support::addQuad;

Scene makeSheetScene() {
  Scene scene;
  scene.sourcePath = "sheet on a floor";
  Material floor, sheet;
  floor.name = "floor";
  floor.bsdf = LambertBsdf{Rgb(0.8f)};
  sheet.name = "sheet";
  sheet.bsdf = LambertBsdf{Rgb(0.7f, 0.6f, 0.5f)};
  scene.materials = {floor, sheet};
  Mesh floorMesh, sheetMesh;
  // Floor facing +y, sheet facing +x (counter-clockwise seen from the front).
  addQuad(floorMesh, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
  addQuad(sheetMesh, {0, 0.5f, -1}, {0, 1.5f, -1}, {0, 1.5f, 1}, {0, 0.5f, 1}, 1);
  scene.meshes = {floorMesh, sheetMesh};
  scene.lights.push_back(PointLight{Vec3(1.5f, 3.0f, 0.0f), Rgb(8.0f)});
  scene.finalize();
  return scene;
}

CameraDesc sheetCamera(float side) {
  CameraDesc c;
  c.name = "sheet";
  c.eye = Vec3(side * 2.2f, 1.0f, 0.3f);
  c.target = Vec3(0.0f, 1.0f, 0.0f);
  c.fovYDegrees = 30.0f;  // the sheet fills the view: ±0.59 at distance 2.2
  return c;
}

/// Mean radiance over the pixels whose centre ray hits the sheet (mesh 1).
Rgb meanOverSheet(const Image& image, const Camera& camera, const Accel& accel, int* count) {
  Rgb sum(0.0f);
  *count = 0;
  const std::vector<RayHit> hits = test_support::pixelCentreHits(accel, camera);
  for (size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].hit() || hits[i].mesh != 1) continue;
    sum += image.pixels[i];
    ++*count;
  }
  return *count > 0 ? sum / float(*count) : sum;
}

TEST_F(TwoSidedTest, OpenSurfacesGetABackRecordClosedOnesDoNot) {
  const Scene scene = makeSheetScene();
  BakeSettings settings = bakePreset("draft");
  const Parameterisation p = buildParameterisation(scene, settings);
  // Two open quads. The floor's back faces nothing (the scene lies above it, the light too,
  // the sky is black): one-sided. The sheet: a front record followed by its back.
  ASSERT_EQ(p.charts.size(), 3u);
  EXPECT_EQ(p.charts[0].sides, 1);
  {
    const uint32_t ci = 1;
    const Chart& front = p.charts[ci];
    const Chart& back = p.charts[ci + 1];
    EXPECT_EQ(front.sides, 2);
    EXPECT_FALSE(front.isBack);
    EXPECT_EQ(back.sides, 2);
    EXPECT_TRUE(back.isBack);
    EXPECT_EQ(back.material, front.material);
    EXPECT_EQ(back.resU, front.resU);
    EXPECT_EQ(back.resV, front.resV);
    EXPECT_EQ(back.origin, front.origin);
    EXPECT_EQ(back.normal, -front.normal);
    // Same tixel grid, so the same gather points.
    for (uint64_t t = 0; t < front.tixelCount(); ++t)
      EXPECT_EQ(p.gatherPoint[back.firstTixel + t], p.gatherPoint[front.firstTixel + t]);
  }
  for (const auto& mesh : p.triangleChart)
    for (uint32_t chart : mesh) EXPECT_FALSE(p.charts[chart].isBack) << "triangles map to front records";

  // The rule that picks a side: the back record only for a viewer behind a two-sided chart.
  const uint32_t sheet = p.triangleChart[1][0];
  EXPECT_EQ(facingChart(p.charts.data(), sheet, Vec3(1, 0, 0), p.charts[sheet].normal), sheet);
  EXPECT_EQ(facingChart(p.charts.data(), sheet, Vec3(-1, 0, 0), p.charts[sheet].normal), sheet + 1);
  EXPECT_EQ(facingChart(p.charts.data(), sheet + 1, Vec3(1, 0, 0), p.charts[sheet + 1].normal), sheet + 1) << "a back record is never turned again";
}

// A closed, consistently wound cube stays one-sided; flipping one face's winding, or removing
// a face (an open box), makes the whole connected surface open, and every face whose back sees
// something two-sided.
TEST_F(TwoSidedTest, ClosednessDecidesTheSides) {
  for (int variant = 0; variant < 3; ++variant) {
    Scene scene;
    scene.sourcePath = "cube";
    scene.materials.push_back(Material{});
    Mesh mesh;
    const Vec3 p000(0, 0, 0), p100(1, 0, 0), p010(0, 1, 0), p110(1, 1, 0), p001(0, 0, 1), p101(1, 0, 1), p011(0, 1, 1),
        p111(1, 1, 1);
    // Counter-clockwise seen from outside.
    const Vec3 faces[6][4] = {{p000, p010, p110, p100}, {p001, p101, p111, p011}, {p000, p001, p011, p010},
                              {p100, p110, p111, p101}, {p000, p100, p101, p001}, {p010, p011, p111, p110}};
    for (int f = 0; f < 6; ++f) {
      if (variant == 2 && f == 5) continue;  // open box
      if (variant == 1 && f == 0) addQuad(mesh, faces[f][3], faces[f][2], faces[f][1], faces[f][0], 0);  // flipped
      else addQuad(mesh, faces[f][0], faces[f][1], faces[f][2], faces[f][3], 0);
    }
    scene.meshes.push_back(mesh);
    scene.finalize();
    const Parameterisation p = buildParameterisation(scene, bakePreset("draft"));
    const size_t faceCount = variant == 2 ? 5 : 6;
    size_t twoSided = 0;
    for (const Chart& c : p.charts) twoSided += c.sides == 2 ? 1 : 0;
    // The flipped face's back is the cube's outside, where nothing is (black sky, no lights):
    // it stays one-sided; the other faces' backs are the (open) cube's inside.
    const size_t faceless = variant == 1 ? 1 : 0;
    if (variant == 0) {
      EXPECT_EQ(p.charts.size(), faceCount);
      EXPECT_EQ(twoSided, 0u);
      // Outward normals: the front of a closed mesh is its outside.
      for (const Chart& c : p.charts) EXPECT_GT(glm::dot(c.normal, c.origin + 0.5f * (c.axisU + c.axisV) - Vec3(0.5f)), -1e-3f);
    } else {
      EXPECT_EQ(p.charts.size(), 2 * faceCount - faceless) << "variant " << variant;
      EXPECT_EQ(twoSided, 2 * (faceCount - faceless)) << "variant " << variant;
    }
  }
}

// Emission sidedness on both records: a one-sided emitter's back record emits nothing, a
// two-sided one's emits like its front.
TEST_F(TwoSidedTest, EmissionRuleOnBackRecords) {
  Material m;
  m.emission = Rgb(2.0f);
  Chart front, back;
  front.sides = back.sides = 2;
  back.isBack = true;
  EXPECT_EQ(chartEmittedRadiance(m, front, 1.0f), Rgb(2.0f));
  EXPECT_EQ(chartEmittedRadiance(m, front, -1.0f), Rgb(0.0f));
  EXPECT_EQ(chartEmittedRadiance(m, back, 1.0f), Rgb(0.0f));
  EXPECT_EQ(chartEmittedRadiance(m, back, -1.0f), Rgb(2.0f));
  m.twoSidedEmission = true;
  EXPECT_EQ(chartEmittedRadiance(m, back, 1.0f), Rgb(2.0f));
  EXPECT_EQ(emittedRadiance(m, -0.5f), Rgb(2.0f));
}

// The sheet from both sides: light field (bake, reference renderer, fast renderer) vs the
// path tracer, mean radiance over the sheet's pixels.
//
// Tolerances. Path tracer: 64 × 48 pixels × 256 independent samples; the mean over ~1500
// sheet pixels has a standard error below 0.3 % (checked: the test requires it below a fifth
// of the tolerance). Light field: tixels a small fraction of the sheet (default preset) on a
// sheet lit by a point light 1.5 away, bilinear between tixel centres, and 256 gather rays per
// tixel for the interreflected light; the mean over the sheet is within 2 % on the front and 6 %
// on the back (all of whose light is interreflection, the bake's noisiest part), measured
// 0.02 % and 2.0 % with the extent-based density, 0.13 % and 2.2 % with the room-scale one.
// The one-sided light field failed the back by a factor ≈ 40.
TEST_F(TwoSidedTest, ThinSheetMatchesThePathTracerFromBothSides) {
  const Scene traced = makeSheetScene();
  const Accel traceAccel(traced);
  const PathTracer tracer(traced, traceAccel);
  BakeSettings settings = bakePreset("draft");
  settings.tixelsAcrossScene = 24;
  settings.gatherDirections = 256;
  const LightField lf = bake(makeSheetScene(), settings);
  const Accel accel(lf.scene);
  const FastRenderer fast(lf, accel);
  Rgb sides[2];
  for (int s = 0; s < 2; ++s) {
    const float side = s == 0 ? 1.0f : -1.0f;
    const std::string label = s == 0 ? "front (lit) side" : "back side";
    const Camera camera(sheetCamera(side), 64, 48);
    TraceSettings ts;
    ts.spp = 256;
    ts.sampler = SamplerKind::Independent;
    ts.showProgress = false;
    const TraceResult r = tracer.render(camera, ts);
    int count = 0;
    const Rgb pt = meanOverSheet(r.radiance, camera, accel, &count);
    ASSERT_GT(count, 1000) << label;
    const Rgb ptVar = meanOverSheet(r.variance, camera, accel, &count) / float(count);
    RenderSettings rs;
    rs.samplesPerPixel = 1;
    const Rgb lfRef = meanOverSheet(renderLightField(lf, accel, camera, rs), camera, accel, &count);
    const Rgb lfFast = meanOverSheet(fast.render(camera, rs), camera, accel, &count);
    const float tolerance = s == 0 ? 0.02f : 0.06f;
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(std::sqrt(ptVar[c]), 0.2f * tolerance * pt[c]) << label << ": the path trace is too noisy to judge";
      EXPECT_NEAR(lfRef[c], pt[c], tolerance * pt[c]) << label << " channel " << c;
      EXPECT_NEAR(lfFast[c], lfRef[c], 1e-5f * lfRef[c]) << label << ": fast and reference renderer differ";
    }
    std::printf("%s: path tracer %.5f, light field %.5f (ratio %.4f)\n", label.c_str(), luminance(pt), luminance(lfRef),
                luminance(lfRef) / luminance(pt));
    sides[s] = pt;
  }
  // The scene does what the comment says: the back is lit, but far less than the front.
  EXPECT_GT(luminance(sides[1]), 0.005f * luminance(sides[0]));
  EXPECT_LT(luminance(sides[1]), 0.2f * luminance(sides[0]));
}

// The one-sided rule on curved charts: a closed smooth sphere (flat-shaded faces within 30°,
// so curved charts; closed, so one-sided) lit from outside. From inside it the path tracer
// sees black (no light gets in), and so must both light-field renderers: the lookup's cos θ
// on a curved record is taken as 1, so before viewedChart they reflected the outside's
// irradiance there. From outside the same sphere is lit in all three.
TEST_F(TwoSidedTest, InsideAClosedSmoothMeshIsBlackInEveryRenderer) {
  Scene scene = makeSheetScene();
  Material ball;
  ball.name = "ball";
  ball.bsdf = LambertBsdf{Rgb(0.7f)};
  scene.materials.push_back(ball);
  Mesh sphere;
  test_support::addSphere(sphere, Vec3(0.0f, 1.0f, 1.5f), 0.4f, 16, 32, uint32_t(scene.materials.size() - 1));
  scene.meshes.push_back(sphere);
  scene.finalize();
  const Accel traceAccel(scene);
  const PathTracer tracer(scene, traceAccel);
  BakeSettings settings = bakePreset("draft");
  settings.gatherDirections = 64;
  const LightField lf = bake(Scene(scene), settings);
  uint32_t curvedOneSided = 0;
  for (const Chart& c : lf.charts) curvedOneSided += c.material == scene.materials.size() - 1 && c.curved && c.sides == 1;
  ASSERT_GT(curvedOneSided, 0u);
  const Accel accel(lf.scene);
  const FastRenderer fast(lf, accel);
  RenderSettings rs;
  rs.samplesPerPixel = 1;
  TraceSettings ts;
  ts.spp = 16;
  ts.showProgress = false;
  auto luminanceSum = [](const Image& image) {
    double sum = 0.0;
    for (const Rgb& p : image.pixels) sum += luminance(p);
    return sum;
  };
  CameraDesc inside;
  inside.eye = {0.0f, 1.0f, 1.5f};
  inside.target = {1.0f, 1.2f, 1.5f};
  inside.fovYDegrees = 60.0f;
  const Camera in(inside, 32, 24);
  EXPECT_EQ(luminanceSum(tracer.render(in, ts).radiance), 0.0);
  EXPECT_EQ(luminanceSum(renderLightField(lf, accel, in, rs)), 0.0);
  EXPECT_EQ(luminanceSum(fast.render(in, rs)), 0.0);
  CameraDesc outside = inside;
  outside.eye = {2.5f, 1.6f, 1.5f};
  outside.target = {0.0f, 1.0f, 1.5f};
  const Camera out(outside, 32, 24);
  const double pt = luminanceSum(tracer.render(out, ts).radiance);
  EXPECT_GT(pt, 0.0);
  // Measured: the light field's sum 0.34 % above the path tracer's (16 spp), the fast
  // renderer's within 1e-6 of the reference's. Bounds: 3 % (the draft bake's bias on the box
  // scenes is 1–2 %), and the 1e-5 float rounding the two renderers are allowed elsewhere.
  const double reference = luminanceSum(renderLightField(lf, accel, out, rs));
  EXPECT_NEAR(reference, pt, 0.03 * pt);
  EXPECT_NEAR(luminanceSum(fast.render(out, rs)), reference, 1e-5 * reference);
}

}  // namespace
}  // namespace pl
