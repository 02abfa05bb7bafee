// Tests of curved charts (parameterisation.h "Curved charts"): a smooth mesh becomes a few
// charts whose projection is one-to-one and distortion-bounded, its tixels gather around the
// interpolated normal, and the light field of a coarse smooth cylinder follows the smooth
// closed form where per-triangle charts are faceted.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bake/parameterisation.h"
#include "core/progress.h"
#include "lightfield/lookup.h"
#include "plf/plf_file.h"
#include "support/glossy_spheres.h"

namespace pl {
namespace {

// An open cylinder of radius 1 around the y axis, y ∈ [0, height], `segments` quads around
// and `rings` along it, wound outwards; with `smooth` the vertices carry the radial normal
// (shared by the quads around them), otherwise the mesh has no normals (flat shading).
Scene makeCylinder(uint32_t segments, uint32_t rings, bool smooth, float height = 2.0f) {
  Scene scene;
  scene.sourcePath = smooth ? "smooth cylinder" : "faceted cylinder";
  scene.materials.push_back(Material{"grey", LambertBsdf{Rgb(0.6f)}});
  Mesh mesh;
  for (uint32_t r = 0; r <= rings; ++r)
    for (uint32_t s = 0; s < segments; ++s) {
      const float phi = 2.0f * kPi * float(s) / float(segments);
      mesh.positions.push_back(Vec3(std::cos(phi), height * float(r) / float(rings), std::sin(phi)));
      if (smooth) mesh.normals.push_back(Vec3(std::cos(phi), 0.0f, std::sin(phi)));
    }
  auto index = [&](uint32_t r, uint32_t s) { return r * segments + s % segments; };
  for (uint32_t r = 0; r < rings; ++r)
    for (uint32_t s = 0; s < segments; ++s) {
      // (φ0, y0) → (φ0, y1) → (φ1, y1): (0, dy, 0) × (tangent) points outwards.
      mesh.triangles.push_back(UVec3(index(r, s), index(r + 1, s), index(r + 1, s + 1)));
      mesh.triangles.push_back(UVec3(index(r, s), index(r + 1, s + 1), index(r, s + 1)));
    }
  mesh.materials.assign(mesh.triangles.size(), 0);
  scene.meshes.push_back(mesh);
  scene.finalize();
  return scene;
}

Vec2 gridOf(const Chart& c, const Scene& scene, uint32_t m, uint32_t t, int k) {
  return tixelGridCoordinates(c, scene.meshes[m].positions[scene.meshes[m].triangles[t][k]]);
}

TEST(CurvedCharts, SmoothCylinderIsAFewDistortionBoundedCharts) {
  Progress::setEnabled(false);
  const Scene scene = makeCylinder(64, 4, true);
  BakeSettings settings;
  settings.tixelsPerUnit = 16.0f;
  const Parameterisation p = buildParameterisation(scene, settings);

  // Coverage: every triangle in exactly one front record, triangleChart agreeing.
  std::set<std::pair<uint32_t, uint32_t>> seen;
  size_t fronts = 0;
  const float cosBound = std::cos(2.0f * kCurvedChartConeDegrees * kPi / 180.0f);
  for (uint32_t ci = 0; ci < p.charts.size(); ++ci) {
    const Chart& c = p.charts[ci];
    // Every chart is curved (the 5.6° steps between facets exceed the planar tolerance, and a
    // lone facet's vertex normals leave its plane) and two-sided (an open surface).
    EXPECT_TRUE(c.curved);
    EXPECT_EQ(c.sides, 2);
    if (!c.isBack) {
      ++fronts;
      for (const auto& mt : p.chartTriangles[ci]) {
        EXPECT_TRUE(seen.insert(mt).second) << "triangle in two charts";
        EXPECT_EQ(p.triangleChart[mt.first][mt.second], ci);
      }
    }
    // Distortion bound: every face normal within 2 × the cone of the chart normal, and the
    // tixels shrunk by the most tilted face's cosine, so none is larger than the preset's 1/16
    // on the surface.
    float minCos = 1.0f;
    const float side = c.isBack ? -1.0f : 1.0f;
    for (const auto& [m, t] : p.chartTriangles[ci]) minCos = std::min(minCos, side * glm::dot(triangleNormal(scene.meshes[m], t), c.normal));
    EXPECT_GE(minCos, cosBound);
    EXPECT_LE(c.tixelSize / minCos, (1.0f / 16.0f) * (1.0f + 1e-5f));
    // The grid covers every vertex (1e-3 tixel: rounding), every projected triangle keeps its
    // orientation (the projection is locally one-to-one) …
    std::vector<std::array<Vec2, 3>> projected;
    for (const auto& [m, t] : p.chartTriangles[ci]) {
      std::array<Vec2, 3> q;
      for (int k = 0; k < 3; ++k) {
        q[size_t(k)] = gridOf(c, scene, m, t, k);
        EXPECT_GE(q[size_t(k)].x, -0.5f - 1e-3f);
        EXPECT_LE(q[size_t(k)].x, float(c.resU) - 0.5f + 1e-3f);
        EXPECT_GE(q[size_t(k)].y, -0.5f - 1e-3f);
        EXPECT_LE(q[size_t(k)].y, float(c.resV) - 0.5f + 1e-3f);
      }
      const Vec2 e1 = q[1] - q[0], e2 = q[2] - q[0];
      // (Seen along the front's normal: a back record shares the front's axes.)
      EXPECT_GT(e1.x * e2.y - e1.y * e2.x, 0.0f);
      projected.push_back(q);
    }
    // … and no two triangles overlap in grid space: on a 97 × 97 lattice over the grid no
    // point lies strictly inside (by 1e-3 in barycentrics) two triangles.
    for (int b = 0; b < 97; ++b)
      for (int a = 0; a < 97; ++a) {
        const Vec2 x(-0.5f + float(c.resU) * (float(a) + 0.5f) / 97.0f, -0.5f + float(c.resV) * (float(b) + 0.5f) / 97.0f);
        int inside = 0;
        for (const auto& q : projected) {
          const Vec2 e1 = q[1] - q[0], e2 = q[2] - q[0], d = x - q[0];
          const float det = e1.x * e2.y - e1.y * e2.x;
          const float b1 = (d.x * e2.y - d.y * e2.x) / det, b2 = (e1.x * d.y - e1.y * d.x) / det;
          inside += b1 > 1e-3f && b2 > 1e-3f && 1.0f - b1 - b2 > 1e-3f;
        }
        EXPECT_LE(inside, 1) << "chart " << ci << " overlaps itself at " << x.x << ", " << x.y;
      }
    // Gather normals: the interpolated (radial) normal at the gather point, on the record's
    // side (the facets' normals are 2.8° off it at their edges; nlerp is within 0.05°).
    for (uint64_t g = c.firstTixel; g < c.firstTixel + c.tixelCount(); ++g) {
      const Vec3 x = p.gatherPoint[g];
      const Vec3 radial = glm::normalize(Vec3(x.x, 0.0f, x.z));
      EXPECT_NEAR(glm::length(p.gatherNormal[g]), 1.0f, 1e-5f);
      EXPECT_GT(side * glm::dot(p.gatherNormal[g], radial), 0.9999f);
    }
  }
  EXPECT_EQ(seen.size(), scene.triangleCount());
  // A chart spans at most 2 × 20° of the 360°: at least 9 charts; the greedy growth leaves
  // more (16), against the 64 flat strips the facets would give.
  EXPECT_GE(fronts, 9u);
  EXPECT_LE(fronts, 20u);
  std::printf("smooth cylinder: %zu charts (front records), %llu tixels\n", fronts, (unsigned long long)p.tixelCount);
}

TEST(CurvedCharts, FlatShadedMeshesGatherAroundFaceNormalsAndCreasesStop) {
  Progress::setEnabled(false);
  BakeSettings settings;
  settings.tixelsPerUnit = 16.0f;
  // Without vertex normals, faces meeting at 5.6° (≤ 30°) join curved charts as the smooth
  // cylinder's do, but each tixel gathers around the face normal of its triangle (the path
  // tracer shades flat-shaded meshes with it).
  const Scene cylinder = makeCylinder(64, 4, false);
  const Parameterisation faceted = buildParameterisation(cylinder, settings);
  size_t fronts = 0, curvedFronts = 0;
  for (uint32_t ci = 0; ci < faceted.charts.size(); ++ci) {
    const Chart& c = faceted.charts[ci];
    fronts += c.isBack ? 0 : 1;
    curvedFronts += c.curved && !c.isBack;
    if (!c.curved) continue;  // a lone strip left between two curved charts is planar
    const float side = c.isBack ? -1.0f : 1.0f;
    for (uint64_t g = c.firstTixel; g < c.firstTixel + c.tixelCount(); ++g) {
      // Some face of the chart has exactly this normal (facets of the 64-gon are 5.6° apart).
      float best = -1.0f;
      for (const auto& [m, t] : faceted.chartTriangles[ci])
        best = std::max(best, side * glm::dot(faceted.gatherNormal[g], triangleNormal(cylinder.meshes[m], t)));
      EXPECT_GT(best, 1.0f - 1e-5f);
    }
  }
  EXPECT_GE(fronts, 9u);
  EXPECT_LE(fronts, 20u);
  EXPECT_GE(curvedFronts, fronts / 2);
  // A 24-gon without normals (15° steps, within the 20° cone and the 30° edge bound) joins
  // too (fewer charts than faces; a lone face left between two charts is planar); an 8-gon's
  // faces (45°) do not.
  for (const uint32_t segments : {24u, 8u}) {
    const Parameterisation p = buildParameterisation(makeCylinder(segments, 1, false), settings);
    size_t curved = 0, faces = 0;
    for (const Chart& c : p.charts) {
      curved += c.curved && !c.isBack;
      faces += !c.isBack;
    }
    if (segments == 24) {
      EXPECT_GT(curved, 0u);
      EXPECT_LT(faces, 24u);
    } else {
      EXPECT_EQ(curved, 0u);
      EXPECT_EQ(faces, 8u);
    }
  }
  // Split normals along a crease: an octagonal prism whose every face has its own vertex
  // normals (each face's vertices are separate, welded only by position) stays planar.
  Scene prism;
  prism.sourcePath = "creased prism";
  prism.materials.push_back(Material{"grey", LambertBsdf{Rgb(0.6f)}});
  Mesh mesh;
  for (uint32_t s = 0; s < 8; ++s) {
    const float phi0 = 2.0f * kPi * float(s) / 8.0f, phi1 = 2.0f * kPi * float(s + 1) / 8.0f;
    const Vec3 n(std::cos(0.5f * (phi0 + phi1)), 0.0f, std::sin(0.5f * (phi0 + phi1)));
    const uint32_t base = uint32_t(mesh.positions.size());
    for (const Vec3& q : {Vec3(std::cos(phi0), 0, std::sin(phi0)), Vec3(std::cos(phi0), 1, std::sin(phi0)),
                          Vec3(std::cos(phi1), 1, std::sin(phi1)), Vec3(std::cos(phi1), 0, std::sin(phi1))}) {
      mesh.positions.push_back(q);
      mesh.normals.push_back(n);
    }
    mesh.triangles.push_back(UVec3(base, base + 1, base + 2));
    mesh.triangles.push_back(UVec3(base, base + 2, base + 3));
  }
  mesh.materials.assign(mesh.triangles.size(), 0);
  prism.meshes.push_back(mesh);
  prism.finalize();
  const Parameterisation creased = buildParameterisation(prism, settings);
  fronts = 0;
  for (const Chart& c : creased.charts) {
    EXPECT_FALSE(c.curved);
    fronts += c.isBack ? 0 : 1;
  }
  EXPECT_EQ(fronts, 8u);
}

// Curved glossy charts: the GGX and Blinn-Phong spheres of glossy_spheres.h (smooth meshes of
// 1 088 faces each) are a few curved glossy charts each instead of one chart per triangle,
// their tixels gather around the interpolated (≈ radial) normal and store their maps in a
// frame around it; a rough-glass sphere stays one chart per triangle.
TEST(CurvedCharts, SmoothGlossySpheresAreAFewCurvedGlossyCharts) {
  Progress::setEnabled(false);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("plenoptic_curved_glossy_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const Scene scene = test_support::loadGlossySpheres(dir);
  const Parameterisation p = buildParameterisation(scene, bakePreset("draft"));
  for (const char* name : {"leftSphere", "rightSphere"}) {
    uint32_t material = 0;
    while (material < scene.materials.size() && scene.materials[material].name != name) ++material;
    ASSERT_LT(material, scene.materials.size()) << name;
    // The sphere's centre: the mean of its triangles' vertices (a latitude-longitude sphere).
    size_t triangles = 0;
    Vec3 centre(0.0f);
    for (const Mesh& mesh : scene.meshes)
      for (size_t t = 0; t < mesh.triangles.size(); ++t)
        if (mesh.materials[t] == material) {
          ++triangles;
          for (int k = 0; k < 3; ++k) centre += mesh.positions[mesh.triangles[t][k]];
        }
    centre /= float(3 * triangles);
    size_t records = 0, curved = 0;
    float worstCosine = 1.0f;
    for (const Chart& c : p.charts) {
      if (c.material != material) continue;
      ++records;
      EXPECT_EQ(c.kind, ChartKind::Glossy);
      EXPECT_EQ(c.sides, 1);  // a closed mesh
      if (!c.curved) continue;
      ++curved;
      for (uint64_t g = c.firstTixel; g < c.firstTixel + c.tixelCount(); ++g) {
        const Vec3 n = p.gatherNormal[g];
        EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
        worstCosine = std::min(worstCosine, glm::dot(n, glm::normalize(p.gatherPoint[g] - centre)));
        // The map's frame: orthonormal around the gather normal.
        const TixelFrame f = tixelFrame(p, c, g);
        EXPECT_EQ(f.n, n);
        EXPECT_NEAR(glm::dot(f.u, n), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(f.v, n), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(f.u, f.v), 0.0f, 1e-5f);
      }
    }
    std::printf("%s: %zu triangles, %zu chart records (%zu curved), gather normals within %.2f° of radial\n", name,
                triangles, records, curved, std::acos(std::min(1.0f, worstCosine)) * 180.0f / kPi);
    EXPECT_GT(triangles, 1000u);
    EXPECT_LT(records, triangles / 10);  // planar glossy charts: one per triangle
    EXPECT_GE(curved, records - records / 4);
    EXPECT_GT(worstCosine, std::cos(3.0f * kPi / 180.0f));  // vertex normals of a fine sphere: ≈ radial
  }
  // Rough glass stays planar: one two-sided record pair per triangle of that sphere.
  const std::filesystem::path json = dir / "rough.json";
  std::ofstream(json) << R"({"meshes": [{"file": ")" << PLENOPTIC_TEST_DATA_DIR
                      << R"(/cornell-mcguire/CornellBox-Sphere.obj"}], "materials": {"rightSphere": )"
                      << R"({"type": "dielectric", "ior": 1.6, "roughness": 0.5}}})";
  const Scene rough = loadScene(json.string());
  std::filesystem::remove_all(dir);
  const Parameterisation q = buildParameterisation(rough, bakePreset("draft"));
  size_t glassRecords = 0;
  for (const Chart& c : q.charts) {
    if (!isRoughGlassChart(c, rough.materials[c.material].bsdf)) continue;
    ++glassRecords;
    EXPECT_FALSE(c.curved);
  }
  EXPECT_GT(glassRecords, 1000u);
}

// Light-field radiance at the cylinder's surface at angle φ (mid-height), seen from outside
// along the radius, against the closed form: a convex cylinder under a directional light
// travelling along −x (irradiance E0 = 1, black sky) receives E = cos φ on its lit side and
// nothing else, so L = ρ/π · cos φ with cos φ from the smooth (radial) normal.
double worstArcError(const LightField& lf) {
  const Accel accel(lf.scene);
  const float rho = 0.6f;
  double worst = 0.0;
  for (int k = 0; k <= 100; ++k) {
    const float phi = (-50.0f + float(k)) * kPi / 180.0f;
    const Vec3 eye(3.0f * std::cos(phi), 1.0f, 3.0f * std::sin(phi));
    const Vec3 d = glm::normalize(Vec3(0.0f, 1.0f, 0.0f) - eye);
    RayHit hit;
    EXPECT_TRUE(accel.intersect(Ray{eye, d, 0.0f, kInfinity}, hit));
    const Vec3 position = positionAt(lf.scene.meshes[hit.mesh], hit.triangle, hit.barycentrics);
    const Vec3 radial = glm::normalize(Vec3(position.x, 0.0f, position.z));
    const double expected = rho * kInvPi * std::max(0.0f, radial.x);
    const Rgb L = exitantRadiance(lf, hit, position, -d, 0.0f);  // no texture: no cone
    worst = std::max(worst, std::abs(double(L.r) - expected) / (rho * kInvPi));
  }
  return worst;
}

TEST(CurvedCharts, CoarseSmoothCylinderShadesSmoothly) {
  Progress::setEnabled(false);
  BakeSettings settings = bakePreset("draft");
  settings.tixelsPerUnit = 24.0f;
  settings.tolerance = 1e-4f;
  // 16 segments: the facets' normals are 22.5° apart, so flat shading (the faceted mesh's
  // curved charts gather around face normals) is off the smooth cos φ by up to
  // sin 11.25° · sin 50° ≈ 0.15 (in units of ρ/π) at facet edges.
  Scene smooth = makeCylinder(16, 2, true);
  smooth.lights.push_back(DirectionalLight{Vec3(-1.0f, 0.0f, 0.0f), Rgb(1.0f)});
  Scene faceted = makeCylinder(16, 2, false);
  faceted.lights = smooth.lights;
  const LightField smoothLf = bake(std::move(smooth), settings);
  const LightField facetedLf = bake(std::move(faceted), settings);
  const double smoothError = worstArcError(smoothLf), facetedError = worstArcError(facetedLf);
  std::printf("largest error over the lit arc (units of rho/pi): curved charts %.4f, flat charts %.4f\n", smoothError,
              facetedError);
  // Curved charts: bilinear interpolation of cos φ over 1/24-wide tixels, the gather points
  // lying on the facets (≤ 2 % inside the circle) and nlerp'd normals: within 2 %.
  EXPECT_LT(smoothError, 0.02);
  EXPECT_GT(facetedError, 0.08) << "the control: a flat-shaded mesh stays faceted";

  // The curved flag survives the .plf, and the reloaded field looks up the same.
  const std::string path = (std::filesystem::temp_directory_path() / "curved_charts_test.plf").string();
  writeLightField(path, smoothLf);
  const LightField loaded = readLightField(path);
  std::filesystem::remove(path);
  ASSERT_EQ(loaded.charts.size(), smoothLf.charts.size());
  for (size_t c = 0; c < loaded.charts.size(); ++c) EXPECT_EQ(loaded.charts[c].curved, smoothLf.charts[c].curved);
  EXPECT_TRUE(loaded.charts[0].curved);
  EXPECT_EQ(worstArcError(loaded), smoothError);
}

}  // namespace
}  // namespace pl
