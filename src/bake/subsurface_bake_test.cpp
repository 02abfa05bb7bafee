// Subsurface charts in the light field (bake/subsurface.h):
//  * the operator conserves energy: no tixel sends on more than the light entering it, and the
//    interior tixels of a thick slab's face send on what a semi-infinite medium reflects
//    (van de Hulst's formula, which the path tracer's walk matches: trace/subsurface_test.cpp);
//  * a thin slab lit from above glows underneath, as bright as the path tracer shows it;
//  * relighting a subsurface scene's lights equals a fresh bake; edits of a subsurface material
//    are refused with a clear message.
// (Distributed bakes of subsurface scenes: shard_test and distributed_bake_test.)
// Deterministic (fixed seeds); tolerances from the estimates' noise, stated per test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bake/parameterisation.h"
#include "bake/relight.h"
#include "bake/subsurface.h"
#include "core/progress.h"
#include "light/lights.h"
#include "lightfield/lookup.h"
#include "scene/scene.h"
#include "support/box_mesh.h"
#include "support/expect_error.h"
#include "support/light_field_difference.h"
#include "trace/trace.h"

namespace pl {
namespace {

class SubsurfaceBakeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { Progress::setEnabled(false); }
};

/// One subsurface box [lo, hi] (wound outwards) lit by a directional light straight down.
Scene subsurfaceBox(const SubsurfaceBsdf& model, const Vec3& lo, const Vec3& hi, Rgb irradiance = Rgb(1.0f)) {
  Scene scene;
  scene.sourcePath = "subsurface box";
  Material m;
  m.name = "wax";
  m.bsdf = model;
  scene.materials.push_back(m);
  Mesh mesh;
  mesh.name = "box";
  test_support::addBox(mesh, lo, hi, 0);
  scene.meshes.push_back(std::move(mesh));
  scene.lights.push_back(DirectionalLight{Vec3(0.0f, -1.0f, 0.0f), irradiance});
  scene.finalize();
  return scene;
}

/// van de Hulst's diffuse reflectance of a semi-infinite isotropic medium of albedo α, index
/// matched (as trace/subsurface_test.cpp): R = (1 − s)(1 − 0.139 s)/(1 + 1.17 s), s = √(1 − α).
double slabReflectance(double alpha) {
  const double s = std::sqrt(1.0 - alpha);
  return (1.0 - s) * (1.0 - 0.139 * s) / (1.0 + 1.17 * s);
}

// A thick slab (4 × 4 × 2, radius 0.05: 40 radii thick) with 0.5-unit tixels: every tixel sends
// on at most what enters it (per channel, up to 4 standard errors of its 1024 walks: ≤ 1.06),
// and the mean over the top face's interior tixels (more than a tixel, 10 radii, from the
// edges) is the semi-infinite medium's reflectance within 0.01 (its noise over 16 × 1024 walks
// is ≤ 0.003; measured 0.2970, 0.5993, 0.7961 against 0.2985, 0.6046, 0.7954), so the slab's
// albedo.
TEST_F(SubsurfaceBakeTest, OperatorConservesEnergy) {
  const SubsurfaceBsdf model{Rgb(0.3f, 0.6f, 0.8f), Rgb(0.05f)};
  const Scene scene = subsurfaceBox(model, Vec3(-2.0f, -2.0f, -2.0f), Vec3(2.0f, 0.0f, 2.0f));
  const Accel accel(scene);
  BakeSettings settings = bakePreset("draft");
  settings.tixelsPerUnit = 2.0f;
  const Parameterisation param = buildParameterisation(scene, accel, settings);
  const SubsurfaceOperator op = buildSubsurfaceOperator(scene, accel, param, 1024, 5);
  ASSERT_EQ(op.rowTixel.size(), param.tixelCount);
  EXPECT_GT(op.exited, op.walks / 2);
  const std::vector<Rgb> leaving = subsurfaceLeavingFractions(op);
  DVec3 interior(0.0);
  int interiorTixels = 0;
  for (size_t r = 0; r < op.rowTixel.size(); ++r) {
    for (int ch = 0; ch < 3; ++ch) EXPECT_LE(leaving[r][ch], 1.06f) << "tixel " << op.rowTixel[r];
    const uint64_t g = op.rowTixel[r];
    const Chart& c = param.charts[param.tixelChart[g]];
    if (c.normal.y < 0.99f) continue;  // the top face
    const uint64_t local = g - c.firstTixel;
    const uint32_t i = uint32_t(local % c.resU), j = uint32_t(local / c.resU);
    if (i < 2 || j < 2 || i + 2 >= c.resU || j + 2 >= c.resV) continue;
    interior += DVec3(leaving[r]);
    ++interiorTixels;
  }
  ASSERT_EQ(interiorTixels, 16);
  interior /= double(interiorTixels);
  const SubsurfaceMedium medium = subsurfaceMedium(model);
  std::printf("interior leaving fractions (%.4f, %.4f, %.4f), semi-infinite slab (%.4f, %.4f, %.4f)\n", interior[0],
              interior[1], interior[2], slabReflectance(medium.alpha[0]), slabReflectance(medium.alpha[1]),
              slabReflectance(medium.alpha[2]));
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(interior[ch], slabReflectance(medium.alpha[ch]), 0.01) << "channel " << ch;
    // …which is the albedo itself within the mapping's accuracy (0.01 for A ≤ 0.8).
    EXPECT_NEAR(interior[ch], model.albedo[ch], 0.02) << "channel " << ch;
  }
  // The sums above hold only what the truncation kept (kSubsurfaceDroppedFraction of each entry
  // tixel's light at most is dropped): it must have dropped something here for them to show
  // that its loss stays within their tolerance.
  EXPECT_GT(op.dropped, 0u);
}

/// The path tracer's radiance leaving the slab's underside at (x, y, z), seen from below.
Rgb tracedUnderside(const Scene& scene, float x, float y, float z, uint64_t key) {
  const Accel accel(scene);
  const PathTracer tracer(scene, accel);
  TraceSettings settings;
  settings.spp = 1 << 14;
  settings.seed = 11;
  settings.sampler = SamplerKind::Independent;
  const Ray ray{Vec3(x, y - 0.5f, z), Vec3(0.0f, 1.0f, 0.0f), 0.0f, kInfinity};
  return tracer.estimateRadiance(ray, settings, key).mean;
}

// A thin slab (2 × 0.05 × 2, radius 0.1: half a radius thick) under a sun straight above: its
// underside, which no light reaches directly, glows with the light that crossed it. In the
// light field (its bottom chart's radiance at the centre and at four points around it) as in
// the path tracer within 5 %. Measured: +0.3 % at 1024 walks per tixel area; at 256 walks the
// runs tried were 2–3 % off either way (a bottom tixel sees the walks of a few top tixels only);
// the trace's 2^14 paths per point ≈ 1 %.
TEST_F(SubsurfaceBakeTest, ThinSlabGlowsOnItsFarSide) {
  const SubsurfaceBsdf model{Rgb(0.8f, 0.6f, 0.9f), Rgb(0.1f)};
  const Scene scene = subsurfaceBox(model, Vec3(-1.0f, 0.0f, -1.0f), Vec3(1.0f, 0.05f, 1.0f), Rgb(3.0f));
  BakeSettings settings = bakePreset("draft");
  settings.tixelsPerUnit = 8.0f;
  settings.gatherDirections = 64;
  settings.subsurfaceWalks = 1024;
  const LightField lf = bake(scene, settings);
  uint32_t bottom = UINT32_MAX;
  for (uint32_t ci = 0; ci < lf.charts.size(); ++ci)
    if (lf.charts[ci].normal.y < -0.99f) bottom = ci;
  ASSERT_NE(bottom, UINT32_MAX);
  const float points[][2] = {{0.0f, 0.0f}, {0.3f, 0.2f}, {-0.3f, 0.25f}, {0.25f, -0.3f}, {-0.2f, -0.2f}};
  Rgb field(0.0f), traced(0.0f);
  uint64_t key = 0;
  for (const auto& p : points) {
    field += exitantRadiance(lf, bottom, Vec3(p[0], 0.0f, p[1]), Vec3(0.0f, -1.0f, 0.0f), Vec2(0.0f));
    traced += tracedUnderside(scene, p[0], 0.0f, p[1], key++);
  }
  std::printf("underside: light field (%.4f, %.4f, %.4f), path tracer (%.4f, %.4f, %.4f)\n", field[0] / 5.0f,
              field[1] / 5.0f, field[2] / 5.0f, traced[0] / 5.0f, traced[1] / 5.0f, traced[2] / 5.0f);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_GT(traced[ch], 0.05f * 5.0f) << "channel " << ch << ": the slab should glow";
    EXPECT_NEAR(field[ch] / traced[ch], 1.0f, 0.05f) << "channel " << ch << ": light field " << field[ch] / 5.0f
                                                      << ", path tracer " << traced[ch] / 5.0f;
  }
}

using test_support::relativeDifference;

uint32_t materialIndex(const Scene& scene, const std::string& name) {
  for (uint32_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].name == name) return m;
  ADD_FAILURE() << "no material " << name;
  return 0;
}

// Relighting carries light through subsurface objects: on the repository's subsurface test
// scene (bench/scenes/sss-cornell.json, a wax sphere and a thin slab) with a point light added,
// small tixels and few walks, the ceiling light recoloured, then the point light moved and
// recoloured, each give a fresh bake of the changed scene within relight_test's bound (5× the
// bake's tolerance in relative L1: both stop when their remaining error is below it; the fresh
// bake traces the same subsurface walks, which do not depend on the lights). Edits of a
// subsurface material's albedo or radius change its walks: refused by name with the re-bake
// command, and the relighter still works after a refusal.
TEST_F(SubsurfaceBakeTest, RelightingEqualsFreshBakes) {
  Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/../../bench/scenes/sss-cornell.json");
  scene.lights.push_back(
      createLight("point", {{"position", Vec3(0.5f, 1.5f, 0.5f)}, {"intensity", Vec3(1.0f)}}, "test light"));
  scene.finalize();
  BakeSettings settings = bakePreset("draft");
  settings.tixelsAcrossScene = 8.0f;
  settings.gatherDirections = 32;
  settings.areaLightSamples = 4;
  settings.subsurfaceWalks = 16;
  settings.tolerance = 1e-4f;
  settings.maxIterations = 400;
  Parameterisation param;
  VisibilityShard visibility;
  BakeOptions options;
  options.keepParameterisation = &param;
  options.keepVisibility = &visibility;
  const LightField baked = bake(scene, settings, options);
  uint64_t subsurfaceTixels = 0;
  for (const Chart& c : baked.charts)
    if (isSubsurfaceChart(baked.scene, c)) subsurfaceTixels += c.tixelCount();
  ASSERT_GT(subsurfaceTixels, 0u);
  Relighter relighter(baked, std::move(visibility), std::move(param));
  auto expectFreshBake = [&](const char* step) {
    const LightField relit = relighter.lightField();
    const LightField fresh = bake(relighter.scene(), settings);
    const double d = relativeDifference(relit, fresh), moved = relativeDifference(baked, fresh);
    std::printf("%s: relit against fresh %.2e, baked against fresh %.3f\n", step, d, moved);
    EXPECT_LT(d, 5.0 * settings.tolerance) << step;
    EXPECT_GT(moved, 0.05) << step << ": the change should show";
  };

  // 1. The ceiling light recoloured: its first shot scaled.
  const uint32_t light = materialIndex(relighter.scene(), "light");
  relighter.setEmission(light, relighter.scene().materials[light].emission * Rgb(0.5f, 1.0f, 2.0f));
  RelightStats stats = relighter.relight();
  EXPECT_TRUE(stats.converged);
  expectFreshBake("ceiling light recoloured");

  // 2. The point light moved (beside the slab) and recoloured: its first shot traced again.
  Light moved = relighter.scene().lights[0];
  std::get<PointLight>(moved).position = Vec3(-0.4f, 0.6f, 0.6f);
  setLightEmission(moved, Rgb(0.5f, 1.5f, 1.0f));
  relighter.setLight(0, moved);
  stats = relighter.relight();
  EXPECT_EQ(stats.lightsShot, 1u);
  EXPECT_TRUE(stats.converged);
  expectFreshBake("point light moved");

  // 3. A subsurface material's albedo or radius: refused, the relighter unchanged.
  const uint32_t sphere = materialIndex(relighter.scene(), "sphere");
  test_support::expectError([&] { relighter.setAlbedo(sphere, Rgb(0.5f)); },
                            {"sss-cornell.json", "cannot relight", "'sphere'", "subsurface", "plenoptic bake"});
  Scene edited = relighter.scene();
  std::get<SubsurfaceBsdf>(edited.materials[materialIndex(edited, "slab")].bsdf).radius = Rgb(0.2f);
  test_support::expectError([&] { relighter.setScene(edited); },
                            {"sss-cornell.json", "cannot relight", "'slab'", "subsurface", "plenoptic bake"});
  EXPECT_FALSE(relighter.pending());
}

}  // namespace
}  // namespace pl
