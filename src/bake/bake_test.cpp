// End-to-end tests of the bake: white furnace, mirror furnace, visibility reuse and its hash.
#include "bake/bake.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "accel/accel.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "lightfield/lookup.h"
#include "lightfield/paraboloid.h"
#include "bake/parameterisation.h"
#include "plf/plf_file.h"
#include "bake/propagation.h"
#include "bake/visibility.h"
#include "support/expect_error.h"
#include "support/quad_mesh.h"
#include "support/mask_texture.h"

namespace pl {
namespace {

using test_support::expectError;

// A closed axis-aligned box [0, size]³ of 6 quads wound to face inwards; quad `special` (or
// none when −1) gets material 1, all others material 0.
Scene makeClosedBox(float size, const Material& walls, const Material& special = {}, int specialFace = -1) {
  Scene scene;
  scene.sourcePath = "furnace box";
  scene.materials.push_back(walls);
  scene.materials.push_back(special);
  Mesh mesh;
  const Vec3 centre(0.5f * size);
  auto quad = [&](Vec3 a, Vec3 b, Vec3 c, Vec3 d, uint32_t material) {
    if (glm::dot(glm::cross(b - a, c - a), centre - a) < 0.0f) std::swap(b, d);
    test_support::addQuad(mesh, a, b, c, d, material);
  };
  const float s = size;
  const Vec3 p000(0, 0, 0), p100(s, 0, 0), p010(0, s, 0), p110(s, s, 0), p001(0, 0, s), p101(s, 0, s), p011(0, s, s),
      p111(s, s, s);
  const Vec3 faces[6][4] = {{p000, p100, p110, p010}, {p001, p101, p111, p011}, {p000, p001, p011, p010},
                            {p100, p101, p111, p110}, {p000, p100, p101, p001}, {p010, p110, p111, p011}};
  for (int f = 0; f < 6; ++f) quad(faces[f][0], faces[f][1], faces[f][2], faces[f][3], f == specialFace ? 1u : 0u);
  scene.meshes.push_back(std::move(mesh));
  scene.finalize();
  return scene;
}

BakeSettings smallSettings() {
  BakeSettings s = bakePreset("draft");
  s.tixelsAcrossScene = 8;
  s.gatherDirections = 64;
  s.tolerance = 1e-6f;
  s.maxIterations = 400;
  return s;
}

class BakeTest : public ::testing::Test {
 protected:
  void SetUp() override { Progress::setEnabled(false); }
};

// White furnace: a closed enclosure whose walls all have albedo a and emit Le has radiance
// Le/(1−a) everywhere (L = Le + a·L). Checked on every tixel (stored irradiance E satisfies
// Le + a·E/π = Le/(1−a)) and through the renderer's lookup at random points.
void checkFurnace(float a, uint32_t areaLightSamples, float perTixelTolerance) {
  Material wall;
  wall.bsdf = LambertBsdf{Rgb(a)};
  wall.emission = Rgb(1.0f, 2.0f, 0.5f);
  BakeSettings settings = smallSettings();
  settings.areaLightSamples = areaLightSamples;
  const LightField lf = bake(makeClosedBox(3.0f, wall), settings);
  const Rgb expected = wall.emission / (1.0f - a);
  // Iteration stops when the relative power change is below 1e-6: the remaining series error
  // is ~1e-6·a/(1−a) ≤ 1e-5, far below the tolerances checked.
  EXPECT_LT(lf.stats.residual, 1e-6);
  double sumRel = 0.0, maxRel = 0.0;
  for (const Chart& c : lf.charts) {
    ASSERT_EQ(c.kind, ChartKind::Diffuse);
    for (uint64_t t = 0; t < c.tixelCount(); ++t) {
      const Rgb L = wall.emission + a * lf.values[c.firstValue + t] * kInvPi;
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(L[ch], expected[ch], perTixelTolerance * expected[ch]) << "chart tixel " << t;
        sumRel += L[ch] / expected[ch];
        maxRel = std::max(maxRel, double(std::abs(L[ch] / expected[ch] - 1.0f)));
      }
    }
  }
  // The mean over tixels is within 1 % (the furnace criterion) in every mode.
  const double meanRel = sumRel / (3.0 * lf.stats.tixels);
  EXPECT_NEAR(meanRel, 1.0, 0.01);
  std::printf("furnace a=%.1f light samples %u: mean error %+.2e, max tixel error %.2e, %u iterations\n", a,
              areaLightSamples, meanRel - 1.0, maxRel, lf.stats.iterations);
  Pcg32 rng(3, 4);
  for (int i = 0; i < 200; ++i) {
    const uint32_t ci = uint32_t(rng.next() % lf.charts.size());
    const Chart& c = lf.charts[ci];
    // A random point inside the face (the grid covers the 3 × 3 face exactly).
    const Vec3 p = c.origin + rng.uniform() * c.tixelSize * c.resU * c.axisU + rng.uniform() * c.tixelSize * c.resV * c.axisV;
    const Vec3 w = glm::normalize(c.normal + 0.5f * c.axisU);
    const Rgb L = exitantRadiance(lf, ci, p, w, Vec2(0.0f));
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(L[ch], expected[ch], perTixelTolerance * expected[ch]);
  }
}

TEST_F(BakeTest, WhiteFurnaceGatherOnlyIsExactPerTixel) {
  // Without area-light sampling every gather ray sees Le + a·E/π of a uniform field, so each
  // tixel converges to the closed form up to the iteration tolerance and float round-off;
  // 1e-3 is generous.
  checkFurnace(0.5f, 0, 1e-3f);
  checkFurnace(0.9f, 0, 1e-3f);
}

TEST_F(BakeTest, WhiteFurnaceWithAreaLightSampling) {
  // With MIS area-light sampling the direct part is a Monte Carlo estimate per tixel (16
  // shadow rays + 64 gather rays): unbiased, so the mean is within 1 %, but individual tixels
  // scatter (worst of 384 tixels measured: 1.3 % at a = 0.5, 0.5 % at a = 0.9, where the
  // direct part is a smaller fraction of the total); 5 % leaves room for other seeds.
  checkFurnace(0.5f, 16, 0.05f);
  checkFurnace(0.9f, 16, 0.05f);
}

TEST_F(BakeTest, MirrorFurnace) {
  // One wall is an ideal mirror of reflectance 1: it shows the uniform furnace field, so the
  // diffuse walls still converge to Le/(1−a). Exercises the mirror chains of the visibility
  // field (every gather ray towards the mirror continues to a diffuse wall). Without caustic
  // photons the emission seen in the mirror is gathered, exact per tixel as in the gather-only
  // furnace; with them (caustics.h) it is a photon estimate: right on average, each tixel
  // within its photon noise (measured: mean −0.06 %, worst tixel 1.6 %).
  const float a = 0.5f;
  Material wall;
  wall.bsdf = LambertBsdf{Rgb(a)};
  wall.emission = Rgb(1.0f);
  Material mirror;
  mirror.bsdf = MirrorBsdf{Rgb(1.0f), false};
  for (const uint64_t photons : {uint64_t(0), uint64_t(1) << 20}) {
    BakeSettings settings = smallSettings();
    settings.areaLightSamples = 0;
    settings.causticPhotons = photons;
    const LightField lf = bake(makeClosedBox(3.0f, wall, mirror, 2), settings);
    int specular = 0;
    double sum = 0.0, count = 0.0, worst = 0.0;
    for (const Chart& c : lf.charts) {
      if (c.kind == ChartKind::Specular) {
        ++specular;
        EXPECT_EQ(c.dirRes, 0u);
        continue;
      }
      for (uint64_t t = 0; t < c.tixelCount(); ++t) {
        const Rgb L = wall.emission + a * lf.values[c.firstValue + t] * kInvPi;
        // Le/(1−a) = 2; tolerance as in the gather-only furnace, or the photons' noise.
        EXPECT_NEAR(L.g, 2.0f, photons == 0 ? 2e-3f : 0.06f) << "photons " << photons;
        sum += L.g;
        count += 1.0;
        worst = std::max(worst, std::abs(double(L.g) / 2.0 - 1.0));
      }
    }
    std::printf("mirror furnace, %llu caustic photons: mean error %+.2e, worst tixel %.2e\n",
                static_cast<unsigned long long>(photons), sum / count / 2.0 - 1.0, worst);
    EXPECT_NEAR(sum / count, 2.0, 2e-3) << "photons " << photons;
    EXPECT_EQ(specular, 1);
    EXPECT_EQ(lf.stats.causticPhotons, photons);
  }
}

// A single upward-facing quad under a constant environment Le: every gather ray escapes, so the
// outgoing radiance is Le times the directional albedo — ρ·Le for a Lambertian quad, and
// Le·albedo(ωo) for a glossy one (through the precomputed glossy operator and the paraboloid
// map). Tolerance 2 %: the glossy values are texel averages, bilinearly interpolated, of an
// albedo that varies by a few percent across the lobe's texels. (Exactly at the normal the
// albedo of a normalised Blinn-Phong lobe has a cusp — it falls 2 % within 7° — which a 16²
// map smooths by about that much, so the directions checked stay 10° or more away from it.)
TEST_F(BakeTest, QuadUnderUniformSkyReflectsLeTimesAlbedo) {
  const Rgb sky(0.5f, 1.0f, 2.0f);
  for (int glossyCase = 0; glossyCase < 2; ++glossyCase) {
    Scene scene;
    scene.sourcePath = "quad under sky";
    const BlinnPhongBsdf bp{Rgb(0.2f), Rgb(0.6f), 20.0f};
    const LambertBsdf lambert{Rgb(0.7f, 0.5f, 0.3f)};
    Material m;
    m.name = "patch";
    if (glossyCase) m.bsdf = bp;
    else m.bsdf = lambert;
    scene.materials.push_back(m);
    Mesh quad;
    quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}};
    quad.materials = {0, 0};
    scene.meshes.push_back(quad);
    scene.environment.constant = sky;
    scene.finalize();
    BakeSettings settings = smallSettings();
    settings.tixelsAcrossScene = 2;
    settings.gatherDirections = 256;
    settings.glossyDirRes = 16;
    const LightField lf = bake(scene, settings);
    // An open quad under a sky: two-sided, and its back sees the same sky as its front.
    ASSERT_EQ(lf.charts.size(), 2u);
    ASSERT_TRUE(lf.charts[1].isBack);
    for (uint32_t record = 0; record < 2; ++record) {
      const Chart& c = lf.charts[record];
      EXPECT_EQ(c.kind, glossyCase ? ChartKind::Glossy : ChartKind::Diffuse);
      for (float thetaDeg : {10.0f, 25.0f, 40.0f}) {
        const float th = thetaDeg * kPi / 180.0f;
        const Vec3 local(std::sin(th) * 0.6f, std::sin(th) * 0.8f, std::cos(th));
        const Vec3 w = chartWorldDirection(c, local);
        const Rgb got = exitantRadiance(lf, 0, Vec3(0.5f, 0.5f, 0.0f), w, Vec2(0.5f));  // facingChart picks the side
        const Rgb expected = glossyCase ? sky * albedo(bp, local) : sky * lambert.albedo;
        for (int ch = 0; ch < 3; ++ch)
          EXPECT_NEAR(got[ch], expected[ch], (glossyCase ? 0.02f : 1e-4f) * expected[ch])
              << (glossyCase ? "glossy" : "lambert") << " side " << record << " θ=" << thetaDeg << " channel " << ch;
      }
    }
  }
}

// A Lambertian floor under the sun (straight down, irradiance E) and a black blocker at
// height 1 whose alpha mask cuts away its half z < 0 (mask along v = z + 0.5). The bake's
// first-shot shadow rays and its visibility field go through the same ray casting as the path
// tracer, so the floor is lit (L = ρE/π: nothing else reflects light) below the cut-out half and
// dark below the opaque half; without the mask both halves are dark.
TEST_F(BakeTest, AlphaMaskedBlockerCastsTheMaskedShadowInTheLightField) {
  for (const bool masked : {true, false}) {
    Scene scene;
    scene.sourcePath = "masked blocker";
    const float rho = 0.6f, e = 2.0f;
    scene.materials.push_back({.name = "floor", .bsdf = LambertBsdf{Rgb(rho)}});
    scene.materials.push_back({.name = "blocker", .bsdf = LambertBsdf{Rgb(0.0f)}});
    Mesh mesh;
    mesh.positions = {{-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-0.5f, 1, -0.5f}, {-0.5f, 1, 0.5f},
                      {0.5f, 1, 0.5f}, {0.5f, 1, -0.5f}};
    for (const Vec3& p : mesh.positions) mesh.uvs.push_back(Vec2(p.x + 0.5f, p.z + 0.5f));
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};  // both facing +y
    mesh.materials = {0, 0, 1, 1};
    scene.meshes.push_back(mesh);
    if (masked) {
      scene.textures.push_back(test_support::halfMaskTexture());  // top half opaque
      scene.materials[1].alphaTexture = 0;
    }
    scene.lights.push_back(DirectionalLight{Vec3(0.0f, -1.0f, 0.0f), Rgb(e)});
    scene.finalize();
    BakeSettings settings = smallSettings();
    settings.tixelsAcrossScene = 32;  // 1/8 unit: the probes below are 2 tixels from any edge
    const LightField lf = bake(scene, settings);
    const uint32_t floorChart = lf.triangleChart[0][0];
    ASSERT_EQ(lf.charts[floorChart].kind, ChartKind::Diffuse);
    const Vec3 up(0.0f, 1.0f, 0.0f);
    const float lit = rho * e / kPi;
    const Rgb underHole = exitantRadiance(lf, floorChart, Vec3(0.0f, 0.0f, -0.25f), up, Vec2(0.0f));
    const Rgb underOpaque = exitantRadiance(lf, floorChart, Vec3(0.0f, 0.0f, 0.25f), up, Vec2(0.0f));
    const Rgb outside = exitantRadiance(lf, floorChart, Vec3(1.25f, 0.0f, 0.25f), up, Vec2(0.0f));
    EXPECT_NEAR(outside.g, lit, 1e-3f * lit);
    EXPECT_NEAR(underOpaque.g, 0.0f, 1e-3f * lit);
    if (masked) EXPECT_NEAR(underHole.g, lit, 1e-3f * lit);
    else EXPECT_NEAR(underHole.g, 0.0f, 1e-3f * lit);
  }
}

// An environment *map* bright (radiance c) above the horizon (world y > 0) and black below:
// a Lambertian quad facing up sees only the bright half, E = π·c, L = ρ·c; one facing down
// sees only the black half. Checks that escaping gather rays look the map up in their world
// direction. Tolerance 2 % of ρ·c: bilinear filtering blurs the map's horizon over one texel
// row (5.6°), where cos θ, and so the weight, is small.
TEST_F(BakeTest, EnvironmentMapIsLookedUpInTheLeavingDirection) {
  const float c = 2.0f;
  LatLongMap map;
  map.image = Image(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      if (LatLongMap::direction((x + 0.5) / 64.0, (y + 0.5) / 32.0).y > 0.0f) map.image.at(x, y) = Rgb(c);
  for (const float facing : {1.0f, -1.0f}) {
    Scene scene;
    scene.sourcePath = "quad under half sky";
    Material m;
    m.name = "patch";
    m.bsdf = LambertBsdf{Rgb(0.5f)};
    scene.materials.push_back(m);
    Mesh quad;
    quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};  // in y = 0
    quad.triangles = {facing > 0.0f ? UVec3(0, 2, 1) : UVec3(0, 1, 2), facing > 0.0f ? UVec3(0, 3, 2) : UVec3(0, 2, 3)};
    quad.materials = {0, 0};
    scene.meshes.push_back(quad);
    scene.environment.map = std::make_shared<const EnvironmentMap>(map);
    scene.finalize();
    BakeSettings settings = smallSettings();
    settings.tixelsAcrossScene = 2;
    settings.gatherDirections = 256;
    const LightField lf = bake(scene, settings);
    ASSERT_EQ(lf.charts.size(), 2u);  // open: its back sees the other half of the sky
    ASSERT_NEAR(lf.charts[0].normal.y, facing, 1e-6f);
    const Rgb L = exitantRadiance(lf, 0, Vec3(0.5f, 0.0f, 0.5f), lf.charts[0].normal, Vec2(0.5f));
    EXPECT_NEAR(L.g, facing > 0.0f ? 0.5f * c : 0.0f, 0.02f * 0.5f * c) << "facing " << facing;
    const Rgb back = exitantRadiance(lf, 0, Vec3(0.5f, 0.0f, 0.5f), -lf.charts[0].normal, Vec2(0.5f));
    EXPECT_NEAR(back.g, facing > 0.0f ? 0.0f : 0.5f * c, 0.02f * 0.5f * c) << "back of facing " << facing;
  }
}

TEST_F(BakeTest, GlossyOperatorRowsIntegrateTheBsdf) {
  // Σ_k W[c][k] = mean over texel c of ∫ f cos θi dωi = the directional albedo. For Lambert it
  // is exactly ρ; for Blinn-Phong the albedo at the texel's direction, compared with the BSDF
  // module's own numerical albedo (the texel average and the 16 sub-samples per cell differ
  // from it by < 2 % for a lobe this wide near normal incidence).
  const uint32_t res = 6, m = 12;
  const std::vector<Rgb> lambert = glossyOperator(LambertBsdf{Rgb(0.7f)}, res, m);
  for (uint32_t c = 0; c < res * res; ++c) {
    Rgb sum(0.0f);
    for (uint32_t k = 0; k < m * m; ++k) sum += lambert[c * m * m + k];
    EXPECT_NEAR(sum.r, 0.7f, 1e-4f);
  }
  // A finer map, so that the four texels around the normal span only θ < 19°, where the
  // albedo varies by < 0.5 %: the texel average then matches the albedo at the texel centre.
  const uint32_t fine = 12;
  const BlinnPhongBsdf bp{Rgb(0.2f), Rgb(0.6f), 20.0f};
  const std::vector<Rgb> op = glossyOperator(bp, fine, m);
  for (uint32_t c : {65u, 66u, 77u, 78u}) {  // texels (5|6, 5|6) around the normal
    Rgb sum(0.0f);
    for (uint32_t k = 0; k < m * m; ++k) sum += op[c * m * m + k];
    const Rgb expected = albedo(bp, paraboloidTexelDirection(c % fine, c / fine, fine));
    EXPECT_NEAR(sum.g, expected.g, 0.02f * expected.g);
  }
}

TEST_F(BakeTest, NarrowLobeOperatorRowsIntegrateTheBsdf) {
  // A lobe narrower than the cell sub-samples (GGX α = 0.0025, FWHM 0.4°; the sub-samples of a
  // 16² grid lie ≈ 1.8° apart): the operator samples the lobe, so each row still sums to the
  // directional albedo (16 sub-samples per cell would mostly miss the lobe), every row's
  // weight lies in the cells around the mirror direction, and the cell-constant BSDF (×N/π)
  // integrates to the same albedo.
  const uint32_t res = 12, m = 16;
  for (const Bsdf& bsdf : {Bsdf(GgxBsdf{Rgb(0.0f), Rgb(0.9f), 0.0025f}), Bsdf(BlinnPhongBsdf{Rgb(0.0f), Rgb(0.5f), 1e6f})}) {
    ASSERT_TRUE(isNarrowLobe(bsdf, m));
    const std::vector<Rgb> op = glossyOperator(bsdf, res, m);
    for (uint32_t c : {65u, 66u, 77u, 78u, 40u, 100u}) {
      Rgb sum(0.0f);
      for (uint32_t k = 0; k < m * m; ++k) sum += op[c * m * m + k];
      const Vec3 wo = paraboloidTexelDirection(c % res, c / res, res);
      const Rgb expected = albedo(bsdf, wo);
      EXPECT_NEAR(sum.g, expected.g, 0.02f * expected.g) << modelName(bsdf) << " texel " << c;
      // The mirror direction's cell holds the largest weight.
      const uint32_t mirrorCell = gatherCellOf(Vec3(-wo.x, -wo.y, wo.z), m);
      uint32_t largest = 0;
      for (uint32_t k = 1; k < m * m; ++k)
        if (op[c * m * m + k].g > op[c * m * m + largest].g) largest = k;
      const int da = int(largest % m) - int(mirrorCell % m), db = int(largest / m) - int(mirrorCell / m);
      EXPECT_LE(std::abs(da) + std::abs(db), 2) << modelName(bsdf) << " texel " << c;
    }
  }
  EXPECT_FALSE(isNarrowLobe(GgxBsdf{Rgb(0.0f), Rgb(0.9f), 0.09f}, m));  // roughness 0.3: sub-sampled
}

TEST_F(BakeTest, RoughGlassOperatorsIntegrateTheBsdfOnBothSides) {
  // Rough glass (propagation.h): on side s the output is R_s·(own gather) + T_s·(the twin's).
  // Row sums, for the texels around the normal (as above): R_s + T_s = the BSDF's directional
  // albedo ∫ f |cos θi| dωi over both hemispheres at the texel's direction in the BSDF frame
  // (z negated on the back). And the furnace balance: outside radiance L, inside η²L (radiance
  // grows by η² entering the dense side) must give back L outside and η²L inside:
  //   R_front + η² T_front = 1,   R_back + T_back/η² = 1,
  // up to the BSDF's own energy balance (multiple-scattering compensation) and the quadrature.
  // Measured at α = 0.25: front R 0.0381 T 0.4282 (albedo 0.4641) balance 1.0015, back
  // R 0.1387 T 1.9399 (albedo 2.0965) balance 1.0009.
  const uint32_t fine = 12, m = 12;
  DielectricBsdf glass;
  glass.ior = 1.5f;
  glass.alpha = 0.25f;
  const float eta2 = glass.ior * glass.ior;
  for (const bool back : {false, true}) {
    const std::vector<Rgb> reflection = glossyOperator(glass, fine, m, back, back);
    const std::vector<Rgb> transmission = glossyOperator(glass, fine, m, back, !back);
    for (uint32_t c : {65u, 66u, 77u, 78u}) {
      float r = 0.0f, t = 0.0f;
      for (uint32_t k = 0; k < m * m; ++k) {
        r += reflection[c * m * m + k].g;
        t += transmission[c * m * m + k].g;
      }
      const Vec3 wo = glassBsdfDirection(back, paraboloidTexelDirection(c % fine, c / fine, fine));
      const float expected = albedo(glass, wo).g;
      EXPECT_NEAR(r + t, expected, 0.02f * expected) << "back " << back << " texel " << c;
      const float balance = back ? r + t / eta2 : r + eta2 * t;
      std::printf("rough glass operator, %s texel %u: R %.4f T %.4f albedo %.4f balance %.4f\n", back ? "back" : "front", c,
                  r, t, expected, balance);
      EXPECT_NEAR(balance, 1.0f, 0.005f) << "back " << back << " texel " << c;
    }
  }
}

TEST_F(BakeTest, ReusedVisibilityAndChangedLightEqualsFullBake) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "plenoptic_bake_test_reuse";
  std::filesystem::create_directories(dir);
  const std::string plv = (dir / "cornell.plv").string();
  std::filesystem::remove(plv);
  BakeSettings settings = smallSettings();
  settings.tixelsAcrossScene = 12;
  settings.tolerance = 1e-4f;

  BakeOptions save;
  save.visibilityPath = plv;
  const LightField first = bake(makeCornellBox(), settings, save);
  EXPECT_FALSE(first.stats.reusedVisibility);
  ASSERT_TRUE(std::filesystem::exists(plv));

  Scene changed = makeCornellBox();
  for (Material& m : changed.materials)
    if (m.isEmissive()) m.emission *= Rgb(0.5f, 1.0f, 2.0f);
  for (Material& m : changed.materials)
    if (m.name == "red") m.bsdf = LambertBsdf{Rgb(0.3f, 0.6f, 0.1f)};  // albedo change: same field
  BakeOptions reuse;
  reuse.visibilityPath = plv;
  reuse.reuseVisibility = true;
  std::string note;
  reuse.log = [&](const std::string& line) { note += line + "\n"; };
  const LightField reused = bake(changed, settings, reuse);
  EXPECT_TRUE(reused.stats.reusedVisibility) << note;
  EXPECT_EQ(reused.stats.visibilityRays, 0u);

  const LightField full = bake(changed, settings, BakeOptions{});
  ASSERT_EQ(reused.values.size(), full.values.size());
  double maxRel = 0.0, changedFromFirst = 0.0;
  for (size_t i = 0; i < full.values.size(); ++i)
    for (int ch = 0; ch < 3; ++ch) {
      const double ref = std::max(1e-6f, std::abs(full.values[i][ch]));
      maxRel = std::max(maxRel, std::abs(double(reused.values[i][ch]) - full.values[i][ch]) / ref);
      changedFromFirst = std::max(changedFromFirst, std::abs(double(first.values[i][ch]) - full.values[i][ch]) / ref);
    }
  // Same deterministic visibility field, the tixel setup taken from the .plt with the red
  // wall's tixels filled again, same propagation: identical, bit for bit.
  EXPECT_EQ(maxRel, 0.0);
  EXPECT_NE(note.find("tixel setup: reused"), std::string::npos) << note;
  EXPECT_EQ(note.find("(0 charts of changed materials"), std::string::npos) << note;
  EXPECT_GT(changedFromFirst, 0.1);  // and the change did change the light field
  std::filesystem::remove_all(dir);
}

// With --reuse-visibility the saved field is read while the first shot runs, and a stale field
// is only discovered after it: the field is then traced inside propagation. The result must
// be the full bake's, bit for bit (same field, same arithmetic), the new field saved, and its
// tracing reported as visibility time, not as propagation time.
TEST_F(BakeTest, StaleVisibilityFieldIsRetracedAndEqualsFullBake) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "plenoptic_bake_test_stale";
  std::filesystem::create_directories(dir);
  const std::string plv = (dir / "cornell.plv").string();
  BakeSettings settings = smallSettings();
  settings.tixelsAcrossScene = 12;
  BakeSettings other = settings;
  other.tixelsAcrossScene = 10;  // a different parameterisation: a stale field for `settings`
  BakeOptions save;
  save.visibilityPath = plv;
  bake(makeCornellBox(), other, save);
  ASSERT_TRUE(std::filesystem::exists(plv));

  BakeOptions reuse;
  reuse.visibilityPath = plv;
  reuse.reuseVisibility = true;
  std::string note;
  reuse.log = [&](const std::string& line) { note += line + "\n"; };
  const LightField retraced = bake(makeCornellBox(), settings, reuse);
  EXPECT_FALSE(retraced.stats.reusedVisibility);
  EXPECT_NE(note.find("recomputing"), std::string::npos) << note;
  EXPECT_GT(retraced.stats.visibilityRays, 0u);
  EXPECT_GT(retraced.stats.visibilitySeconds, 0.0);
  // Propagation time excludes the tracing (both are parts of the whole bake's time).
  EXPECT_LE(retraced.stats.propagationSeconds + retraced.stats.visibilitySeconds, retraced.stats.seconds);

  const LightField full = bake(makeCornellBox(), settings, BakeOptions{});
  ASSERT_EQ(retraced.values.size(), full.values.size());
  EXPECT_EQ(std::memcmp(retraced.values.data(), full.values.data(), full.values.size() * sizeof(Rgb)), 0);

  // The retraced field replaced the stale one: a second reuse now succeeds.
  const LightField reused = bake(makeCornellBox(), settings, reuse);
  EXPECT_TRUE(reused.stats.reusedVisibility) << note;
  EXPECT_EQ(std::memcmp(reused.values.data(), full.values.data(), full.values.size() * sizeof(Rgb)), 0);
  std::filesystem::remove_all(dir);
}

TEST_F(BakeTest, VisibilityHashDetectsGeometryButNotAlbedoOrEmission) {
  const Scene base = makeCornellBox();
  const BakeSettings settings = smallSettings();
  const uint64_t h0 = visibilityHash(base, buildParameterisation(base, settings), settings);

  Scene albedoChanged = makeCornellBox();
  albedoChanged.materials[0].bsdf = LambertBsdf{Rgb(0.1f)};
  albedoChanged.materials[3].emission = Rgb(100.0f);
  EXPECT_EQ(visibilityHash(albedoChanged, buildParameterisation(albedoChanged, settings), settings), h0);

  Scene moved = makeCornellBox();
  moved.meshes[2].positions[0].y += 1.0f;  // one corner of the short block, 1 mm higher
  EXPECT_NE(visibilityHash(moved, buildParameterisation(moved, settings), settings), h0);

  Scene mirrored = makeCornellBox();
  mirrored.materials[1].bsdf = MirrorBsdf{};  // a wall becomes a mirror: different transport
  EXPECT_NE(visibilityHash(mirrored, buildParameterisation(mirrored, settings), settings), h0);

  BakeSettings moreDirections = settings;
  moreDirections.gatherDirections = 100;
  EXPECT_NE(visibilityHash(base, buildParameterisation(base, moreDirections), moreDirections), h0);
}

TEST_F(BakeTest, StaleOrCorruptVisibilityFiles) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "plenoptic_bake_test_files";
  std::filesystem::create_directories(dir);
  const std::string plv = (dir / "box.plv").string();
  const Scene scene = makeCornellBox();
  const BakeSettings settings = smallSettings();
  const Parameterisation param = buildParameterisation(scene, settings);
  const Accel accel(scene);
  const VisibilityField field = computeVisibility(scene, accel, param, settings);
  writeVisibility(plv, field);

  VisibilityField read;
  std::string why;
  ASSERT_TRUE(readVisibility(plv, field.hash, read, &why)) << why;
  EXPECT_EQ(read.entryCount(), field.entryCount());
  EXPECT_EQ(read.extras.size(), field.extras.size());
  const std::vector<VisibilityEntry> readEntries = read.decodeAll(), fieldEntries = field.decodeAll();
  EXPECT_EQ(std::memcmp(readEntries.data(), fieldEntries.data(), fieldEntries.size() * sizeof(VisibilityEntry)), 0);
  ASSERT_EQ(read.entryBytes.size(), field.entryBytes.size());
  EXPECT_TRUE(std::equal(read.entryBytes.begin(), read.entryBytes.end(), field.entryBytes.begin()));
  ASSERT_EQ(read.extraOffset.size(), field.extraOffset.size());
  EXPECT_TRUE(std::equal(read.extraOffset.begin(), read.extraOffset.end(), field.extraOffset.begin()));
  EXPECT_EQ(std::memcmp(read.extras.data(), field.extras.data(), field.extras.size() * sizeof(VisibilityExtra)), 0);
  // Compact in memory and on disk: fewer bytes than 8-byte entries.
  EXPECT_LT(field.entryBytes.size(), field.entryCount() * sizeof(VisibilityEntry));
  EXPECT_LT(std::filesystem::file_size(plv), field.entryBytes.size());

  // Stale: a different expected hash is not an error, but a reason.
  EXPECT_FALSE(readVisibility(plv, field.hash ^ 1, read, &why));
  EXPECT_NE(why.find("different geometry"), std::string::npos) << why;
  EXPECT_FALSE(readVisibility((dir / "missing.plv").string(), field.hash, read, &why));

  // Truncated and corrupt files are errors naming the file.
  const auto size = std::filesystem::file_size(plv);
  std::filesystem::copy_file(plv, dir / "truncated.plv", std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(dir / "truncated.plv", size - 5);
  try {
    readVisibility((dir / "truncated.plv").string(), field.hash, read, &why);
    ADD_FAILURE() << "truncated file accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("truncated.plv"), std::string::npos) << e.what();
  }
  {
    std::fstream f(plv, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(size / 2));
    const char junk = 0x5a;
    f.write(&junk, 1);
  }
  EXPECT_THROW(readVisibility(plv, field.hash, read, &why), Error);
  std::filesystem::remove_all(dir);
}

TEST_F(BakeTest, VisibilityFileOfAnOlderVersionIsRetracedAndLyingFramesAreRefused) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "plenoptic_plv_format_test";
  std::filesystem::create_directories(dir);
  const std::string plv = (dir / "box.plv").string();
  const Scene scene = makeCornellBox();
  const BakeSettings settings = smallSettings();
  const Parameterisation param = buildParameterisation(scene, settings);
  const VisibilityField field = computeVisibility(scene, Accel(scene), param, settings);
  writeVisibility(plv, field);
  std::ifstream in(plv, std::ios::binary);
  const std::vector<char> good{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  auto writeVariant = [&](const std::vector<char>& bytes) {
    std::ofstream out(plv, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
  };
  auto resignPayload = [](std::vector<char>& bytes) {  // header: payload XXH64 at byte 48, payload from 56
    const uint64_t hash = xxh64(bytes.data() + 56, bytes.size() - 56);
    std::memcpy(bytes.data() + 48, &hash, 8);
  };
  VisibilityField read;
  std::string why;
  // Version 2 (raw entries): not an error, a reason to trace again.
  auto older = good;
  const uint32_t two = 2;
  std::memcpy(older.data() + 8, &two, 4);
  writeVariant(older);
  EXPECT_FALSE(readVisibility(plv, field.hash, read, &why));
  EXPECT_NE(why.find("older format version 2"), std::string::npos) << why;
  // The frame table at the end made to lie (two frames' stored sizes swapped, consistent total,
  // valid checksum): refused by the frame check before the field is allocated, naming the file.
  auto lying = good;
  uint64_t first, last;
  // The table: stored sizes of the B + 1 frames, then their content sizes (u64 each).
  uint64_t perBlock;
  std::memcpy(&perBlock, lying.data() + 56, 8);
  const uint64_t tableFrames = (field.tixelCount + perBlock - 1) / perBlock + 1;
  const size_t lastAt = lying.size() - 8 * (tableFrames + 1), firstAt = lastAt - 8;  // the last entry block's and the extras' stored sizes
  std::memcpy(&first, lying.data() + firstAt, 8);
  std::memcpy(&last, lying.data() + lastAt, 8);
  ASSERT_NE(first, last);
  std::memcpy(lying.data() + firstAt, &last, 8);
  std::memcpy(lying.data() + lastAt, &first, 8);
  resignPayload(lying);
  writeVariant(lying);
  try {
    readVisibility(plv, field.hash, read, &why);
    ADD_FAILURE() << "a lying frame table was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();  // the entry block's or the extra records' frame, whichever is checked first
    EXPECT_TRUE(what.find("box.plv: visibility block") != std::string::npos ||
                what.find("box.plv: visibility extra records") != std::string::npos)
        << what;
  }
  // A tixel index past the field's end inside a valid frame (written through writeVisibility).
  std::vector<VisibilityEntry> entries = field.decodeAll();
  entries[5].target = uint32_t(field.tixelCount) + 3;
  VisibilityField bad = field;
  bad.setEntries(entries.data());
  writeVisibility(plv, bad);
  try {
    readVisibility(plv, field.hash, read, &why);
    ADD_FAILURE() << "an out-of-range tixel index was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("an entry of tixel 0 points outside the field"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST_F(BakeTest, CornellBoxVisibilityFieldIsSane) {
  const Scene scene = makeCornellBox();
  BakeSettings settings = smallSettings();
  const Parameterisation param = buildParameterisation(scene, settings);
  const Accel accel(scene);
  const VisibilityField field = computeVisibility(scene, accel, param, settings);
  EXPECT_EQ(field.entryCount(), param.tixelCount * 64);
  EXPECT_EQ(field.rays, param.tixelCount * 64);  // no mirrors: one ray per entry
  EXPECT_TRUE(field.extras.empty());             // no glossy or mirror targets
  // The box is open at the front only: a minority of gather rays escape, and no ray from the
  // inside of the room may hit a surface from behind except from tixels under the blocks.
  uint64_t escaped = 0;
  const std::vector<VisibilityEntry> entries = field.decodeAll();
  for (const VisibilityEntry& e : entries) escaped += e.escaped() ? 1 : 0;
  const double fraction = double(escaped) / double(entries.size());
  EXPECT_GT(fraction, 0.05);
  EXPECT_LT(fraction, 0.4);
  // The memory guard's figure, measured on a sample of tixels, is close to what the field holds
  // and well below 8 bytes per entry.
  const VisibilityBytesPerTixel perTixel =
      estimateVisibilityBytesPerTixel(scene, accel, param, settings, {TixelRange{0, param.tixelCount}});
  const double estimate = perTixel.held;
  const double held = double(field.bytes()) / double(field.tixelCount);
  EXPECT_NEAR(estimate / held, 1.0, 0.1) << estimate << " " << held;
  EXPECT_LT(held, 64 * 6.0);
  EXPECT_LT(bakeMemoryEstimate(param.tixelCount, param.valueCount, settings, 0, estimate),
            bakeMemoryEstimate(param.tixelCount, param.valueCount, settings));
  // Streamed, the field holds its extra records and their offsets alone.
  const double streamed = double(field.extraOffset.size() * sizeof(uint64_t) + field.extras.size() * sizeof(VisibilityExtra)) /
                          double(field.tixelCount);
  EXPECT_NEAR(perTixel.streamed / streamed, 1.0, 0.25) << perTixel.streamed << " " << streamed;
  EXPECT_LT(perTixel.streamed, estimate / 4);
}

// The gather's sub-cells are multi-jittered: along each column of cells every sub-column is
// used gridSide/kGatherJitterSide times, and along each row every sub-row; the same tixel
// gets the same pattern, other tixels other patterns.
TEST(GatherJitter, SubCellsAreMultiJitteredPerTixel) {
  constexpr uint32_t J = kGatherJitterSide;
  for (uint32_t gridSide : {12u, 16u, 24u}) {
    for (uint64_t tixel : {0ull, 7ull, 123456ull}) {
      std::vector<uint8_t> subCells;
      gatherSubCells(tixel, gridSide, 3, subCells);
      ASSERT_EQ(subCells.size(), size_t(gridSide) * gridSide);
      for (uint32_t line = 0; line < gridSide; ++line) {
        std::vector<int> columnUse(J, 0), rowUse(J, 0);
        for (uint32_t i = 0; i < gridSide; ++i) {
          ++columnUse[subCells[line + i * gridSide] % J];  // cells of column `line`
          ++rowUse[subCells[i + line * gridSide] / J];     // cells of row `line`
        }
        for (uint32_t j = 0; j < J; ++j) {
          EXPECT_EQ(columnUse[j], int(gridSide / J)) << "grid " << gridSide << " column " << line;
          EXPECT_EQ(rowUse[j], int(gridSide / J)) << "grid " << gridSide << " row " << line;
        }
      }
      std::vector<uint8_t> again, other;
      gatherSubCells(tixel, gridSide, 3, again);
      EXPECT_EQ(again, subCells);
      gatherSubCells(tixel + 1, gridSide, 3, other);
      EXPECT_NE(other, subCells);
    }
  }
}

// The sub-cells are part of the field's contract (every stored entry was traced along them, and
// the propagation recomputes them for normal-mapped tixels): pinned, per grid side, by the
// FNV-1a hash of the patterns of a few tixels and seeds, as the first implementation (one line
// shuffled at a time) computed them.
TEST(GatherJitter, SubCellsArePinned) {
  const std::pair<uint32_t, uint64_t> pinned[] = {{1u, 0xa8c7f832281a39c5ull},  {3u, 0xcb8d1a2d8af983cfull},
                                                  {12u, 0x2e9de3d235ed2c1dull}, {16u, 0x3d5efb42988db9bdull},
                                                  {24u, 0x3d49fca60a331565ull}, {256u, 0x8c683c7689b6b3a5ull}};
  for (const auto& [gridSide, expected] : pinned) {
    Fnv1a64 h;
    std::vector<uint8_t> subCells;
    for (uint64_t tixel : {0ull, 7ull, 123456ull, 1073741822ull})
      for (uint64_t seed : {0ull, 3ull}) {
        gatherSubCells(tixel, gridSide, seed, subCells);
        h.update(subCells.data(), subCells.size());
      }
    EXPECT_EQ(h.digest(), expected) << "grid side " << gridSide;
  }
}

TEST_F(BakeTest, DeterministicWhateverTheThreadCount) {
  // Every random stream is keyed by (tixel, sample), every sum runs in a fixed order and the
  // Gauss–Seidel batches never read what they write: 1 and 2 threads give identical bits.
  BakeSettings settings = smallSettings();
  settings.tixelsAcrossScene = 12;
  settings.tolerance = 1e-3f;
  LightField one, two;
  {
    ThreadPool pool(1);
    one = bake(makeCornellBox(), settings);
  }
  {
    ThreadPool pool(2);
    two = bake(makeCornellBox(), settings);
  }
  ASSERT_EQ(one.values.size(), two.values.size());
  EXPECT_EQ(std::memcmp(one.values.data(), two.values.data(), one.values.size() * sizeof(Rgb)), 0);
  EXPECT_EQ(one.stats.iterations, two.stats.iterations);
}

TEST_F(BakeTest, PresetsAndUnknownPreset) {
  for (const std::string& name : bakePresetNames()) EXPECT_EQ(bakePreset(name).preset, name);
  EXPECT_LT(bakePreset("draft").tixelsAcrossScene, bakePreset("default").tixelsAcrossScene);
  EXPECT_LT(bakePreset("default").tixelsAcrossScene, bakePreset("high").tixelsAcrossScene);
  EXPECT_THROW(bakePreset("ultra"), Error);
  // The names come from kBakePresets, and the error lists them all.
  EXPECT_EQ(bakePresetNames(), (std::vector<std::string>{"draft", "default", "high"}));
  try {
    bakePreset("ultra");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("(choose draft, default or high)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pl

namespace pl {
namespace {

TEST(BakePresets, DefaultConstructedSettingsAreTheDefaultPreset) {
  // lightfield.h promises that BakeSettings{} is bakePreset("default"): code that builds
  // settings without naming a preset gets the documented default, not a third variant.
  const BakeSettings constructed;
  const BakeSettings preset = bakePreset("default");
  EXPECT_EQ(constructed.preset, preset.preset);
  EXPECT_EQ(constructed.tixelsPerUnit, preset.tixelsPerUnit);
  EXPECT_EQ(constructed.tixelsAcrossScene, preset.tixelsAcrossScene);
  EXPECT_EQ(constructed.maxTixelsPerChartSide, preset.maxTixelsPerChartSide);
  EXPECT_EQ(constructed.gatherDirections, preset.gatherDirections);
  EXPECT_EQ(constructed.glossyDirRes, preset.glossyDirRes);
  EXPECT_EQ(constructed.areaLightSamples, preset.areaLightSamples);
  EXPECT_EQ(constructed.tolerance, preset.tolerance);
  EXPECT_EQ(constructed.maxIterations, preset.maxIterations);
  EXPECT_EQ(constructed.mirrorDepth, preset.mirrorDepth);
}

}  // namespace
}  // namespace pl
