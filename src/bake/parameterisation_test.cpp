// Tests of chart construction and tixel grids.
#include "bake/parameterisation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <utility>

#include "bake/bake.h"
#include "core/progress.h"
#include "lightfield/lookup.h"

namespace pl {
namespace {

double triangleArea(const Scene& s, uint32_t m, uint32_t t) {
  const Mesh& mesh = s.meshes[m];
  const UVec3 tri = mesh.triangles[t];
  return 0.5 * glm::length(glm::cross(DVec3(mesh.positions[tri[1]] - mesh.positions[tri[0]]),
                                      DVec3(mesh.positions[tri[2]] - mesh.positions[tri[0]])));
}

TEST(Parameterisation, CornellBoxCharts) {
  Progress::setEnabled(false);
  const Scene scene = makeCornellBox();
  BakeSettings settings;
  settings.tixelsAcrossScene = 32;
  const Parameterisation p = buildParameterisation(scene, settings);
  // 5 room quads + the light + 2 blocks × 5 faces: every quad is one planar chart (the
  // measured walls are non-planar by at most 3.2 mm, within the 0.5 % plane tolerance). All
  // are open surfaces; the room's backs face nothing (black sky), but the light's back (the
  // ceiling) and the blocks' insides (the room behind their planes) get back records: 16 + 12.
  size_t backs = 0;
  for (const Chart& c : p.charts) backs += c.isBack ? 1 : 0;
  EXPECT_EQ(p.charts.size() - backs, 16u);
  EXPECT_EQ(backs, 12u);

  // Every triangle is in exactly one front chart (and its back record), and triangleChart
  // agrees with chartTriangles.
  std::set<std::pair<uint32_t, uint32_t>> seen;
  double chartAreaSum = 0.0, sceneArea = 0.0;
  for (uint32_t c = 0; c < p.charts.size(); ++c) {
    if (p.charts[c].isBack) {
      EXPECT_EQ(p.chartTriangles[c], p.chartTriangles[c - 1]);
      continue;
    }
    for (const auto& mt : p.chartTriangles[c]) {
      EXPECT_TRUE(seen.insert(mt).second) << "triangle in two charts";
      EXPECT_EQ(p.triangleChart[mt.first][mt.second], c);
      EXPECT_EQ(scene.meshes[mt.first].materials[mt.second], p.charts[c].material);
    }
    chartAreaSum += p.chartArea[c];
  }
  EXPECT_EQ(seen.size(), scene.triangleCount());
  for (uint32_t m = 0; m < scene.meshes.size(); ++m)
    for (uint32_t t = 0; t < scene.meshes[m].triangles.size(); ++t) sceneArea += triangleArea(scene, m, t);
  EXPECT_NEAR(chartAreaSum, sceneArea, 1e-9 * sceneArea);

  for (uint32_t c = 0; c < p.charts.size(); ++c) {
    const Chart& chart = p.charts[c];
    // Orthonormal, right-handed frames (left-handed for back records: the normal negated); the
    // normal is the triangles' winding normal (negated for back records). 1e-5: float rounding
    // of unit vectors (a few ulps of 1).
    const float side = chart.isBack ? -1.0f : 1.0f;
    EXPECT_NEAR(glm::dot(chart.axisU, chart.axisV), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(side * glm::cross(chart.axisU, chart.axisV) - chart.normal), 0.0f, 1e-5f);
    const auto [m, t] = p.chartTriangles[c][0];
    const Mesh& mesh = scene.meshes[m];
    const Vec3 n = glm::normalize(glm::cross(mesh.positions[mesh.triangles[t][1]] - mesh.positions[mesh.triangles[t][0]],
                                             mesh.positions[mesh.triangles[t][2]] - mesh.positions[mesh.triangles[t][0]]));
    EXPECT_GT(side * glm::dot(n, chart.normal), 0.999f);
    EXPECT_EQ(chart.kind, ChartKind::Diffuse);
    EXPECT_EQ(chart.dirRes, 1u);
    // The grid covers the chart: every vertex maps inside [−½, res − ½] in grid coordinates
    // (1e-3 of a tixel: float rounding of coordinates up to res ≤ 64).
    for (const auto& [mm, tt] : p.chartTriangles[c])
      for (int k = 0; k < 3; ++k) {
        const Vec2 g = tixelGridCoordinates(chart, scene.meshes[mm].positions[scene.meshes[mm].triangles[tt][k]]);
        EXPECT_GE(g.x, -0.5f - 1e-3f);
        EXPECT_LE(g.x, chart.resU - 0.5f + 1e-3f);
        EXPECT_GE(g.y, -0.5f - 1e-3f);
        EXPECT_LE(g.y, chart.resV - 0.5f + 1e-3f);
      }
    // Covered area (coverage × tixel area, 4×4 sub-samples) approximates the chart area;
    // the sub-sampling error is at most about one tixel row along the perimeter.
    double covered = 0.0;
    for (uint64_t k = 0; k < chart.tixelCount(); ++k) covered += p.coverage[chart.firstTixel + k];
    covered *= double(chart.tixelSize) * chart.tixelSize;
    const double perimeterBound = 2.0 * (chart.resU + chart.resV) * double(chart.tixelSize) * chart.tixelSize;
    EXPECT_NEAR(covered, p.chartArea[c], 0.25 * perimeterBound) << "chart " << c;
    // Gather points lie on the chart's plane, within the chart's rectangle.
    for (uint64_t k = 0; k < chart.tixelCount(); ++k) {
      const Vec3 q = p.gatherPoint[chart.firstTixel + k];
      EXPECT_EQ(p.tixelChart[chart.firstTixel + k], c);
      EXPECT_NEAR(glm::dot(q - chart.origin, chart.normal), 0.0f, 5.0f);  // ≤ the 3.2 mm non-planarity
      const Vec2 g = tixelGridCoordinates(chart, q);
      EXPECT_GE(g.x, -0.51f);
      EXPECT_LE(g.x, chart.resU - 0.49f);
    }
  }
  // The room's walls are ~550 mm, the largest extent ~559 mm. Its room scale is smaller than
  // that (an open box with two blocks inside: a mean free path of ≈ 240 mm, scale ≈ 360 mm),
  // and 32 tixels across it make every chart's tixels scale/32 wide.
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const float scale = sceneScale(scene, Accel(scene));
  EXPECT_GT(scale, 0.5f * maxComponent(hi - lo));
  EXPECT_LT(scale, 0.8f * maxComponent(hi - lo));
  for (const Chart& chart : p.charts) EXPECT_EQ(chart.tixelSize, scale / 32.0f);
  EXPECT_GE(p.charts[0].resU, uint32_t(550.0f / (scale / 32.0f)));
  EXPECT_EQ(p.tixelCount, p.valueCount);  // all diffuse: one value per tixel
}

// An axis-aligned box [0, size.x] × [0, size.y] × [0, size.z] of 12 triangles, one material.
Scene makeBox(Vec3 size, Material material) {
  Scene scene;
  scene.sourcePath = "box";
  scene.materials.push_back(material);
  Mesh box;
  for (int k = 0; k < 8; ++k) box.positions.push_back(Vec3(k & 1 ? size.x : 0, k & 2 ? size.y : 0, k & 4 ? size.z : 0));
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    box.triangles.push_back({f[0], f[1], f[2]});
    box.triangles.push_back({f[0], f[2], f[3]});
  }
  box.materials.assign(box.triangles.size(), 0);
  scene.meshes.push_back(box);
  scene.finalize();
  return scene;
}

TEST(Parameterisation, SceneScaleOfACubeIsItsSide) {
  // A closed cube of side a: free paths leaving its walls cosine-weighted average 4V/S = 2a/3
  // inside (Cauchy), and rays leaving outwards escape, so the scale is a (± the estimator's
  // noise: chords have a standard deviation of ≈ 0.4a; over the ≈ 8192 inside rays the mean's
  // is ≈ 0.5 %).
  const Scene cube = makeBox(Vec3(3.0f), Material{"grey", LambertBsdf{Rgb(0.5f)}});
  const Accel accel(cube);
  EXPECT_NEAR(sceneScale(cube, accel), 3.0f, 0.06f);
  // A long corridor 1 × 1 × 8: its free paths are those of its 1 × 1 section (mostly), so the
  // scale stays near its width, not its length.
  const Scene corridor = makeBox(Vec3(1.0f, 1.0f, 8.0f), Material{"grey", LambertBsdf{Rgb(0.5f)}});
  const Accel corridorAccel(corridor);
  const float corridorScale = sceneScale(corridor, corridorAccel);
  EXPECT_GT(corridorScale, 0.9f);
  EXPECT_LT(corridorScale, 1.5f);
  // A lone quad: every ray escapes, so the scale is its extent.
  Scene quad;
  quad.sourcePath = "quad";
  quad.materials.push_back(Material{"grey", LambertBsdf{Rgb(0.5f)}});
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.materials = {0, 0};
  quad.meshes.push_back(mesh);
  quad.finalize();
  const Accel quadAccel(quad);
  EXPECT_EQ(sceneScale(quad, quadAccel), 2.0f);
}

TEST(Parameterisation, NoChartIsCoarsenedAndMaterialsRefine) {
  // Every chart of the Cornell box has the preset's tixel size, however small (the light) or
  // large (the walls), even at a density whose walls need hundreds of tixels a side.
  const Scene scene = makeCornellBox();
  BakeSettings settings;
  settings.tixelsAcrossScene = 300;
  const Parameterisation p = buildParameterisation(scene, settings);
  const float base = baseTixelSize(settings, sceneScale(scene, Accel(scene)));
  uint32_t widest = 0;
  for (const Chart& c : p.charts) {
    EXPECT_EQ(c.tixelSize, base);
    widest = std::max(widest, std::max(c.resU, c.resV));
  }
  EXPECT_GT(widest, 200u);
  // A material's tixel_density and glossiness refine its charts.
  Material dense{"dense", LambertBsdf{Rgb(0.5f)}};
  dense.tixelDensity = 2.5f;
  const Scene denseBox = makeBox(Vec3(1.0f), dense);
  const Scene glossyBox = makeBox(Vec3(1.0f), Material{"glossy", BlinnPhongBsdf{Rgb(0.3f), Rgb(0.3f), 20.0f}});
  const Scene plainBox = makeBox(Vec3(1.0f), Material{"plain", LambertBsdf{Rgb(0.5f)}});
  settings.tixelsAcrossScene = 8;
  const float plain = buildParameterisation(plainBox, settings).charts[0].tixelSize;
  EXPECT_FLOAT_EQ(buildParameterisation(denseBox, settings).charts[0].tixelSize, plain / 2.5f);
  EXPECT_FLOAT_EQ(buildParameterisation(glossyBox, settings).charts[0].tixelSize, plain / kGlossyTixelDensity);
}

TEST(Parameterisation, TexturedTixelsUseTheFootprintAverageAlbedo) {
  // A unit quad (uv = xy) whose albedo texture is black for u < ½ and white for u > ½, with a
  // 4 × 4 tixel grid: each tixel's transport albedo is the mean of the texture over its
  // footprint, compared with a brute-force 64 × 64 average of Texture::sample. The bake's
  // 4 × 4 sub-samples differ from it only where the texture's bilinear transition (1/64 wide)
  // cuts a footprint, hence 0.05.
  Scene scene;
  scene.sourcePath = "textured quad";
  Texture texture;
  texture.path = "halves";
  texture.image = Image(64, 1);
  for (int x = 32; x < 64; ++x) texture.image.at(x, 0) = Rgb(1.0f, 0.5f, 0.25f);
  texture.average = Rgb(0.5f, 0.25f, 0.125f);
  scene.textures.push_back(texture);
  Material m;
  m.name = "textured";
  m.bsdf = LambertBsdf{Rgb(0.8f)};
  m.albedoTexture = 0;
  scene.materials.push_back(m);
  Mesh quad;
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  quad.triangles = {{0, 1, 2}, {0, 2, 3}};
  quad.materials = {0, 0};
  scene.meshes.push_back(quad);
  scene.finalize();
  BakeSettings settings;
  settings.tixelsAcrossScene = 4;
  const Parameterisation p = buildParameterisation(scene, settings);
  ASSERT_EQ(p.charts.size(), 1u);
  const Chart& c = p.charts[0];
  ASSERT_EQ(c.tixelCount(), 16u);
  for (uint32_t j = 0; j < 4; ++j)
    for (uint32_t i = 0; i < 4; ++i) {
      // The tixel's footprint in world (= uv) space, from the chart frame.
      Rgb expected(0.0f);
      for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
          const Vec3 q = c.origin + (float(i) + (x + 0.5f) / 64.0f) * c.tixelSize * c.axisU +
                         (float(j) + (y + 0.5f) / 64.0f) * c.tixelSize * c.axisV;
          expected += 0.8f * texture.sample(Vec2(q.x, q.y));
        }
      expected /= 64.0f * 64.0f;
      const Rgb got = p.transportAlbedo[c.firstTixel + j * 4 + i];
      EXPECT_NEAR(got.r, expected.r, 0.05f) << i << "," << j;
      EXPECT_NEAR(got.b, expected.b, 0.05f) << i << "," << j;
    }
  // And the texture did make a difference across the quad.
  float lo = 1.0f, hi = 0.0f;
  for (uint32_t t = 0; t < 16; ++t) {
    lo = std::min(lo, p.transportAlbedo[t].r);
    hi = std::max(hi, p.transportAlbedo[t].r);
  }
  EXPECT_LT(lo, 0.05f);
  EXPECT_GT(hi, 0.75f);
}

TEST(Parameterisation, TixelsOutsideTheTriangleGatherFromInsideIt) {
  // A right triangle covers half of its bounding rectangle: the tixels beyond its hypotenuse
  // must still gather from a point on the triangle (closest point, pulled slightly inside).
  Scene scene;
  scene.sourcePath = "triangle";
  scene.materials.push_back(Material{"grey", LambertBsdf{Rgb(0.5f)}});
  Mesh tri;
  tri.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  tri.triangles = {{0, 1, 2}};
  tri.materials = {0};
  scene.meshes.push_back(tri);
  scene.finalize();
  BakeSettings settings;
  settings.tixelsAcrossScene = 8;
  const Parameterisation p = buildParameterisation(scene, settings);
  ASSERT_EQ(p.charts.size(), 1u);
  const Chart& c = p.charts[0];
  int outside = 0;
  for (uint64_t t = 0; t < c.tixelCount(); ++t) {
    const Vec3 q = p.gatherPoint[c.firstTixel + t];
    // Inside the triangle x ≥ 0, y ≥ 0, x + y ≤ 2 (up to float round-off), on its plane.
    EXPECT_GE(q.x, -1e-5f);
    EXPECT_GE(q.y, -1e-5f);
    EXPECT_LE(q.x + q.y, 2.0f + 1e-5f);
    EXPECT_EQ(q.z, 0.0f);
    if (p.coverage[c.firstTixel + t] == 0.0f) ++outside;
  }
  EXPECT_GT(outside, 0);  // the grid does have tixels entirely outside the polygon
}

TEST(Parameterisation, GatherPointsUnderAContactMoveOut) {
  // A 4 × 4 floor (tixels 0.25 wide) with a closed 2 × 2 × 1 box standing on [1, 3]²: the ring
  // of floor tixels just under the box's sides would gather from inside the box (dark, the
  // leak along baseboards); they must gather from outside its footprint. With the box lifted
  // off the floor (no contact) the same tixels keep their own centres.
  for (const float lift : {0.0f, 0.5f}) {
    Scene scene = makeBox(Vec3(2.0f, 2.0f, 1.0f), Material{"box", LambertBsdf{Rgb(0.5f)}});
    for (Vec3& v : scene.meshes[0].positions) v += Vec3(1.0f, 1.0f, lift);
    Mesh floor;
    floor.positions = {{0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0}};
    floor.triangles = {{0, 1, 2}, {0, 2, 3}};
    floor.materials = {0, 0};
    scene.meshes.push_back(floor);
    scene.finalize();
    BakeSettings settings;
    settings.tixelsPerUnit = 4.0f;
    const Parameterisation p = buildParameterisation(scene, settings);
    const Chart& c = p.charts[p.triangleChart[1][0]];
    ASSERT_EQ(c.tixelCount(), 256u);
    int ring = 0, moved = 0;
    for (uint32_t k = 0; k < c.tixelCount(); ++k) {
      const Vec3 centre = c.origin + (float(k % c.resU) + 0.5f) * c.tixelSize * c.axisU + (float(k / c.resU) + 0.5f) * c.tixelSize * c.axisV;
      const float inside = std::min(std::min(centre.x - 1.0f, 3.0f - centre.x), std::min(centre.y - 1.0f, 3.0f - centre.y));
      if (!(inside > 0.0f && inside < 0.2f)) continue;  // the ring just inside the footprint's edge
      ++ring;
      const Vec3 q = p.gatherPoint[c.firstTixel + k];
      const bool underBox = q.x > 1.0f && q.x < 3.0f && q.y > 1.0f && q.y < 3.0f;
      if (lift == 0.0f) {
        EXPECT_FALSE(underBox) << "tixel " << k << " gathers from " << q.x << "," << q.y;
      }
      if (glm::length(q - centre) > 1e-4f) ++moved;
    }
    EXPECT_EQ(ring, 28);
    if (lift > 0.0f) {
      EXPECT_EQ(moved, 0);
    } else {
      EXPECT_GT(moved, 0);
    }
  }
}

TEST(Parameterisation, DirectionalResolutionByMaterial) {
  BakeSettings settings;
  settings.glossyDirRes = 16;
  EXPECT_EQ(directionalResolution(LambertBsdf{}, settings), 1u);
  EXPECT_EQ(directionalResolution(MirrorBsdf{}, settings), 0u);
  const uint32_t wide = directionalResolution(BlinnPhongBsdf{Rgb(0.3f), Rgb(0.3f), 8.0f}, settings);
  const uint32_t narrow = directionalResolution(BlinnPhongBsdf{Rgb(0.3f), Rgb(0.3f), 80.0f}, settings);
  EXPECT_LT(wide, narrow);  // sharper lobes need finer maps
  EXPECT_LE(narrow, 16u);
  EXPECT_EQ(directionalResolution(BlinnPhongBsdf{Rgb(0.3f), Rgb(0.1f), 100000.0f}, settings), 16u);  // capped
  EXPECT_LT(directionalResolution(GgxBsdf{Rgb(0.2f), Rgb(0.04f), 0.5f}, settings),
            directionalResolution(GgxBsdf{Rgb(0.2f), Rgb(0.04f), 0.1f}, settings));
}

TEST(Parameterisation, StrongNarrowLobesGetTwiceTheCap) {
  // Blinn-Phong exponent 1000 (FWHM 8.5°, R 108) over a diffuse colour, specular 0.35: narrower
  // than two thirds of a texel at the draft (8) and default (16) caps, not at high's (24).
  const BlinnPhongBsdf strong{Rgb(0.6f), Rgb(0.35f), 1000.0f};
  const BlinnPhongBsdf weak{Rgb(0.6f), Rgb(0.1f), 1000.0f};  // the same lobe, a weak one
  ASSERT_EQ(lobeMapResolution(4.0f * lobeHalfWidth(strong)), 108u);
  for (const auto& [preset, strongRes] : {std::pair<const char*, uint32_t>{"draft", 16u}, {"default", 32u}, {"high", 24u}}) {
    const BakeSettings settings = bakePreset(preset);
    SCOPED_TRACE(preset);
    EXPECT_EQ(isStrongNarrowLobe(strong, settings), std::string(preset) != "high");
    EXPECT_EQ(directionalResolution(strong, settings), strongRes);
    EXPECT_FALSE(isStrongNarrowLobe(weak, settings));
    EXPECT_EQ(directionalResolution(weak, settings), settings.glossyDirRes);
    // A GGX dielectric's lobe (f0 0.04) is weak however narrow: roughness 0.05 keeps the cap.
    EXPECT_FALSE(isStrongNarrowLobe(GgxBsdf{Rgb(0.8f), Rgb(0.04f), 0.0025f}, settings));
    // A lobe that asks for no more than the doubled cap gets what it asks for: GGX metal
    // roughness 0.3 (R 70) at draft is mirror-like (no map); at default a strong narrow lobe
    // only if R > 96, so it keeps 16.
    EXPECT_EQ(directionalResolution(GgxBsdf{Rgb(0.0f), Rgb(0.9f), 0.09f}, settings),
              std::string(preset) == "draft" ? 0u : settings.glossyDirRes);
  }
  // Rough glass, mirrors and Lambert are never strong narrow lobes.
  const BakeSettings settings = bakePreset("default");
  EXPECT_FALSE(isStrongNarrowLobe(DielectricBsdf{1.5f, Rgb(1.0f), 0.0025f}, settings));
  EXPECT_FALSE(isStrongNarrowLobe(MirrorBsdf{}, settings));
  EXPECT_FALSE(isStrongNarrowLobe(LambertBsdf{}, settings));
}

// Per-tixel lobe widths (lobeAlphaBins): the α bins of a metallic-roughness texture whose
// roughness runs 0.1 → 1 span its α range geometrically, neighbours at most kLobeBinRatio
// apart, from one map texel's lobe (α below it raised to it) up to α = 1; a tixel takes the
// bin nearest its α by ratio.
TEST(Parameterisation, LobeAlphaBinsSpanTheTextureFromOneMapTexel) {
  Scene scene;
  Texture ramp;
  ramp.decode = ImageDecode::Data;
  ramp.image = Image(2, 1);
  ramp.image.at(0, 0) = Rgb(0.0f, 0.1f, 1.0f);
  ramp.image.at(1, 0) = Rgb(0.0f, 1.0f, 1.0f);
  scene.textures.push_back(ramp);
  Material metal;
  metal.bsdf = gltfMetallicRoughnessModel(Rgb(0.8f), 1.0f, 0.7f);
  metal.metallicRoughness = {0, TextureMapping{}, Rgb(0.8f), 1.0f, 1.0f};
  const auto [least, greatest] = lobeAlphaRange(scene, metal);
  EXPECT_FLOAT_EQ(least, ggxAlphaFromRoughness(0.1f));
  EXPECT_FLOAT_EQ(greatest, 1.0f);
  for (uint32_t dirRes : {8u, 16u}) {
    const std::vector<float> bins = lobeAlphaBins(scene, metal, dirRes);
    const float texelAlpha = std::tan(1.0f / float(dirRes)) / std::sqrt(std::sqrt(2.0f) - 1.0f);
    ASSERT_GE(bins.size(), 2u);
    EXPECT_LE(bins.size(), kMaxLobeBins);
    EXPECT_NEAR(bins.front(), texelAlpha, 1e-6f);
    EXPECT_NEAR(bins.back(), 1.0f, 1e-5f);
    for (size_t i = 1; i < bins.size(); ++i) EXPECT_LE(bins[i] / bins[i - 1], kLobeBinRatio * 1.0001f);
    // Bins more than needed would cost operators: one fewer would be too far apart.
    EXPECT_GT(std::pow(1.0f / texelAlpha, 1.0f / float(bins.size() - 2)), kLobeBinRatio);
    EXPECT_EQ(nearestLobeBin(bins, 0.001f), 0u);
    EXPECT_EQ(nearestLobeBin(bins, 2.0f), bins.size() - 1);
    for (uint32_t i = 0; i < bins.size(); ++i) {
      EXPECT_EQ(nearestLobeBin(bins, bins[i] * 1.05f), i);
      EXPECT_EQ(nearestLobeBin(bins, bins[i] / 1.05f), i);
    }
  }
}

TEST(Parameterisation, MapResolutionFollowsTheLobeWidth) {
  // Four texels across the reflected lobe's FWHM, a texel spanning ≈ 4/R radians: R = 16/FWHM.
  EXPECT_EQ(lobeMapResolution(1.0f), 16u);
  EXPECT_EQ(lobeMapResolution(0.5f), 32u);
  EXPECT_EQ(lobeMapResolution(0.1f), 160u);
  EXPECT_EQ(lobeMapResolution(100.0f), 2u);  // at least 2
  // GGX α: the reflected FWHM is 4·atan(α·√(√2 − 1)).
  const float alpha = 0.09f;
  BakeSettings settings;
  settings.glossyDirRes = 128;
  const uint32_t expected = uint32_t(std::ceil(16.0f / (4.0f * std::atan(alpha * std::sqrt(std::sqrt(2.0f) - 1.0f)))));
  EXPECT_EQ(directionalResolution(GgxBsdf{Rgb(0.2f), Rgb(0.04f), alpha}, settings), expected);
}

TEST(Parameterisation, MetalLobesNarrowerThanHalfATexelAtTheCapAreMirrorLike) {
  for (const char* preset : {"draft", "default", "high"}) {
    const BakeSettings settings = bakePreset(preset);
    SCOPED_TRACE(preset);
    // A near-mirror metal (roughness 0.05, α = 0.0025): followed through, nothing stored.
    const GgxBsdf metal{Rgb(0.0f), Rgb(0.9f), 0.0025f};
    EXPECT_TRUE(isMirrorLike(metal, settings));
    EXPECT_EQ(chartKindOf(metal, settings), ChartKind::Specular);
    EXPECT_EQ(directionalResolution(metal, settings), 0u);
    // The same lobe over a diffuse part keeps its map (a traced lobe has no stored diffuse part).
    const GgxBsdf dielectric{Rgb(0.8f), Rgb(0.04f), 0.0025f};
    EXPECT_FALSE(isMirrorLike(dielectric, settings));
    EXPECT_EQ(chartKindOf(dielectric, settings), ChartKind::Glossy);
    EXPECT_EQ(directionalResolution(dielectric, settings), settings.glossyDirRes);
    // A rough metal (roughness 0.6) is resolved by every preset's map.
    const GgxBsdf rough{Rgb(0.0f), Rgb(0.9f), 0.36f};
    EXPECT_FALSE(isMirrorLike(rough, settings));
    EXPECT_EQ(chartKindOf(rough, settings), ChartKind::Glossy);
    // GGX metal roughness 0.3 (FWHM 13°, R 70): below half a texel of the draft map (29°),
    // traced there; the default and high maps keep it.
    EXPECT_EQ(isMirrorLike(GgxBsdf{Rgb(0.0f), Rgb(0.9f), 0.09f}, settings), std::string(preset) == "draft");
    // Rough glass and mirrors keep their kinds.
    EXPECT_FALSE(isMirrorLike(DielectricBsdf{1.5f, Rgb(1.0f), 0.0025f}, settings));
    EXPECT_FALSE(isMirrorLike(MirrorBsdf{}, settings));
    // The rule: mirror-like exactly when the lobe asks for more than kMirrorLikeTexels × the cap.
    for (float a = 0.001f; a < 0.5f; a *= 1.1f) {
      const GgxBsdf m{Rgb(0.0f), Rgb(0.9f), a};
      const float fwhm = 4.0f * lobeHalfWidth(m);
      EXPECT_EQ(isMirrorLike(m, settings), lobeMapResolution(fwhm) > kMirrorLikeTexels * settings.glossyDirRes) << a;
    }
  }
  // Mirror-like charts are planar (never grown curved).
  Material m;
  m.bsdf = GgxBsdf{Rgb(0.0f), Rgb(0.9f), 0.0025f};
  EXPECT_FALSE(mayGrowCurvedCharts(m, bakePreset("default")));
  m.bsdf = GgxBsdf{Rgb(0.0f), Rgb(0.9f), 0.36f};
  EXPECT_TRUE(mayGrowCurvedCharts(m, bakePreset("default")));
}

}  // namespace
}  // namespace pl
