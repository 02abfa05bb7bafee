// The environment furnace (issue 7, item 7), end to end through every renderer: a closed
// Lambertian sphere of albedo a under a constant environment of radiance Le (and no other
// light) reflects exactly a·Le towards every viewer.
//
// Why exactly: the sphere is a convex polyhedron (an icosphere, flat facets, no vertex normals,
// so shading normal = geometric normal). Above any facet's plane the whole polyhedron lies
// behind that plane, so the upper hemisphere of every surface point sees only the environment:
// irradiance E = ∫ Le cos θ dω = π·Le, outgoing radiance Lo = (a/π)·E = a·Le, with no
// interreflection at all. This holds for every point of every facet, and also for points of a
// facet's plane outside the triangle (the bake's tixels whose centre lies outside their
// polygon), which is why the bake must store E = π·Le in EVERY diffuse tixel.
//
// Checked here:
//   * the path tracer (src/trace), every strategy, on every pixel that lies wholly on the
//     sphere's image, and on rays aimed at the sphere from all around it;
//   * the bake (src/lightfield): every tixel's stored irradiance E = π·Le;
//   * the straightforward light-field renderer (src/render) and the fast one (src/realtime):
//     a·Le on the sphere, Le in the background, pixel by pixel;
// once with a constant environment (Environment::constant) and once with an environment MAP
// of constant value (a 16×8 lat-long .hdr written by the test into its own temporary
// directory and read back through loadEnvironmentMap), so that the map's lookup and its importance sampling are exercised.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "accel/accel.h"
#include "camera/camera.h"
#include "core/progress.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "env/env.h"
#include "image/image.h"
#include "bake/bake.h"
#include "realtime/realtime.h"
#include "render/render.h"
#include "scene/scene.h"
#include "support/temp_dir_test.h"
#include "trace/trace.h"

namespace pl {
namespace {

/// Each test writes its constant map into its own fresh directory (test_support::TempDirTest).
class EnvFurnaceTest : public test_support::TempDirTest {
 protected:
  static void SetUpTestSuite() { Progress::setEnabled(false); }
};

/// A unit icosphere (radius 1, centred at the origin): the icosahedron with every triangle
/// split into four `subdivisions` times, new vertices pushed out to the sphere. Triangles
/// wound counter-clockwise seen from outside (geometric normal outwards); no vertex normals,
/// so the surface is exactly the convex polyhedron the renderers see.
Mesh makeIcosphere(int subdivisions, uint32_t material) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<Vec3> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& v : p) v = glm::normalize(v);
  std::vector<UVec3> tris = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                             {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      p.push_back(glm::normalize(p[a] + p[b]));
      const auto index = uint32_t(p.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<UVec3> finer;
    for (const UVec3& tri : tris) {
      const uint32_t ab = midpoint(tri.x, tri.y), bc = midpoint(tri.y, tri.z), ca = midpoint(tri.z, tri.x);
      finer.insert(finer.end(), {UVec3(tri.x, ab, ca), UVec3(tri.y, bc, ab), UVec3(tri.z, ca, bc), UVec3(ab, bc, ca)});
    }
    tris = std::move(finer);
  }
  Mesh mesh;
  mesh.name = "sphere";
  mesh.positions = p;
  mesh.triangles = tris;
  mesh.materials.assign(tris.size(), material);
  return mesh;
}

enum class EnvKind { Constant, Map };
const char* envName(EnvKind kind) { return kind == EnvKind::Constant ? "constant environment" : "constant map"; }

/// The environment radiance (deliberately coloured, so a channel mix-up shows). RGBE keeps
/// 8 mantissa bits per channel under a shared exponent, so the map path reads back values
/// within 1/64 relative of these (the test uses the values actually read).
const Rgb kLe(0.5f, 1.0f, 2.0f);

/// Writes a 16×8 lat-long .hdr of constant radiance kLe to `path` and loads it through the same
/// function the JSON scene's "environment": {"file": ...} uses.
std::shared_ptr<const EnvironmentMap> constantMap(const std::string& path) {
  writeHdrImage(path, Image(16, 8, kLe));
  return loadEnvironmentMap(path);
}

/// The sphere of albedo a under the chosen environment (the map written to mapPath for
/// EnvKind::Map); returns the radiance the environment actually delivers (kLe, or what RGBE
/// stored), after checking that it is constant.
Scene makeSphereScene(float albedo, EnvKind kind, const std::string& mapPath, Rgb& le) {
  Scene scene;
  scene.sourcePath = "sphere under a constant environment";
  Material m;
  m.name = "lambert";
  m.bsdf = LambertBsdf{Rgb(albedo)};
  scene.materials.push_back(m);
  scene.meshes.push_back(makeIcosphere(2, 0));
  if (kind == EnvKind::Constant) {
    scene.environment.constant = kLe;
  } else {
    scene.environment.map = constantMap(mapPath);
  }
  scene.finalize();
  le = scene.environment.radiance(Vec3(0.0f, 1.0f, 0.0f));
  // The map is constant: the bilinear lookup returns the same value in every direction (up to
  // float rounding of the interpolation weights, 1e-6), and RGBE kept it within 1/64.
  Pcg32 rng(7, 1);
  for (int i = 0; i < 100; ++i) {
    const Vec3 dir = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    const Rgb l = scene.environment.radiance(dir);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[c], le[c], 1e-6f * le[c]) << envName(kind);
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(le[c], kLe[c], kLe[c] / 64.0f) << envName(kind);
  return scene;
}

CameraDesc sphereCamera(const Vec3& eye) {
  CameraDesc c;
  c.name = "furnace";
  c.eye = eye;
  c.target = Vec3(0.0f);
  c.fovYDegrees = 50.0f;  // from distance 3.5 the unit sphere (±16.6°) fills the middle ⅔
  return c;
}

/// Pixels whose whole square lies on the sphere's image: the rays through the 4 corners and
/// the centre all hit it. (The image of a convex body is convex, so the square, the convex hull
/// of its corners, is then covered entirely and every jittered sample of the pixel hits.)
std::vector<std::pair<int, int>> pixelsWhollyOnSphere(const Camera& camera, const Accel& accel) {
  std::vector<std::pair<int, int>> inside;
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) {
      bool all = true;
      for (Vec2 f : {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 1), Vec2(0.5f, 0.5f)}) {
        RayHit hit;
        all = all && accel.intersect(camera.generateRay(Vec2(float(x), float(y)) + f, Vec2(0.5f)).ray, hit);
      }
      if (all) inside.emplace_back(x, y);
    }
  return inside;
}

// ---- path tracer --------------------------------------------------------------------------

/// Path-traced image of the sphere: on every pixel wholly on the sphere, a·Le.
///  * BsdfOnly: cosine-weighted sampling of a Lambertian BRDF under a constant environment is
///    a zero-variance estimator (weight a, incident Le, every bounce ray escapes), so every
///    pixel equals a·Le to float rounding: tolerance 1e-5 relative.
///  * Mis and NeeOnly: environment sampling adds noise. These pixels are checked with the
///    per-pixel z-test of trace.h (Šidák-corrected at α = 0.01 over all pixel-channels, using
///    the tracer's own variance estimate), and their mean within 1 % relative, with the
///    standard error of that mean required to be below a third of it (a 3σ margin, so the
///    pass is meaningful). All streams are seeded: the test is deterministic, not flaky.
void checkTracedSphere(float albedo, EnvKind kind, const std::string& mapPath = {}) {
  Rgb le;
  const Scene scene = makeSphereScene(albedo, kind, mapPath, le);
  const Accel accel(scene);
  const PathTracer tracer(scene, accel);
  const Rgb expected = le * albedo;
  const std::string what = std::string(envName(kind)) + ", albedo " + std::to_string(albedo);

  for (const Vec3& eye : {Vec3(0.0f, 0.0f, 3.5f), Vec3(-2.0f, 2.5f, -1.5f)}) {
    const Camera camera(sphereCamera(eye), 24, 24);
    const std::vector<std::pair<int, int>> inside = pixelsWhollyOnSphere(camera, accel);
    ASSERT_GT(inside.size(), 100u) << "about a quarter of the 24×24 pixels lie wholly on the sphere";
    for (TraceStrategy strategy : {TraceStrategy::BsdfOnly, TraceStrategy::Mis, TraceStrategy::NeeOnly}) {
      TraceSettings settings;
      settings.strategy = strategy;
      // NEE alone samples the uniform sphere: half its samples point below the facet (value 0),
      // the others carry 4a·Le·cos θ with cos θ uniform, a relative deviation of √(8/3 − 1) ≈ 1.3
      // per sample; over ~120 pixels × 2048 samples that is a 0.26 % standard error, inside the
      // 3σ margin of the 1 % tolerance. MIS is far less noisy (BSDF sampling is exact here).
      settings.spp = strategy == TraceStrategy::BsdfOnly ? 4 : strategy == TraceStrategy::NeeOnly ? 2048 : 512;
      const TraceResult r = tracer.render(camera, settings);
      EXPECT_EQ(r.stats.nanSamples, 0u);
      const std::string label = what + ", " + strategyName(strategy);
      if (strategy == TraceStrategy::BsdfOnly) {
        for (const auto& [x, y] : inside)
          for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(r.radiance.at(x, y)[c], expected[c], 1e-5f * expected[c]) << label << " pixel " << x << "," << y;
        continue;
      }
      // The on-sphere pixels as a 1-row image, for the z-test against the exact answer.
      const auto n = int(inside.size());
      Image got(n, 1), variance(n, 1);
      for (int i = 0; i < n; ++i) {
        got.pixels[size_t(i)] = r.radiance.at(inside[size_t(i)].first, inside[size_t(i)].second);
        variance.pixels[size_t(i)] = r.variance.at(inside[size_t(i)].first, inside[size_t(i)].second);
      }
      const ImageZTest z = compareImagesZ(got, variance, Image(n, 1, expected), Image(n, 1, Rgb(0.0f)), 0.01);
      EXPECT_TRUE(z.pass) << label << ": " << z.summary();
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0, var = 0.0;
        for (int i = 0; i < n; ++i) {
          sum += got.pixels[size_t(i)][c];
          var += variance.pixels[size_t(i)][c];
        }
        const double mean = sum / n, standardError = std::sqrt(var) / n;
        EXPECT_NEAR(mean / expected[c], 1.0, 0.01) << label << " channel " << c;
        EXPECT_LE(standardError / expected[c], 0.01 / 3.0) << label << " channel " << c;
      }
    }
  }

  // Rays aimed at the sphere from all around it (random eye on a sphere of radius 4, random
  // target within 0.6 of the centre, so every ray hits): the same a·Le whichever side is seen.
  // BSDF sampling only, zero variance as above; tolerance 1e-5 relative (float rounding).
  Pcg32 rng(11, 1);
  TraceSettings settings;
  settings.strategy = TraceStrategy::BsdfOnly;
  settings.spp = 4;
  for (uint64_t i = 0; i < 200; ++i) {
    Ray ray;
    ray.origin = 4.0f * sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    const Vec3 target = 0.6f * rng.uniform() * sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    ray.direction = glm::normalize(target - ray.origin);
    const RadianceEstimate e = tracer.estimateRadiance(ray, settings, i);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(e.mean[c], expected[c], 1e-5f * expected[c]) << what << " ray " << i;
  }
}

TEST_F(EnvFurnaceTest, PathTracerSphereUnderConstantEnvironment) {
  for (float albedo : {0.5f, 0.8f}) checkTracedSphere(albedo, EnvKind::Constant);
}

TEST_F(EnvFurnaceTest, PathTracerSphereUnderConstantEnvironmentMap) {
  for (float albedo : {0.5f, 0.8f}) checkTracedSphere(albedo, EnvKind::Map, path("constant.hdr"));
}

// ---- bake and light-field renderers -------------------------------------------------------

/// Bakes the sphere; every tixel of every (diffuse) chart must hold E = π·Le, and both
/// light-field renderers must show a·Le on the sphere and Le around it.
///
/// Tolerances:
///  * Stored irradiance: the gather sums n = 64 gather rays, each carrying the environment
///    radiance, times π/n. Every gather ray escapes (see the file comment), so the only error
///    is float rounding of that sum: 1e-5 relative. (Propagation adds nothing: the sphere
///    never sees itself, so the first iteration's change is 0.)
///  * Renders: the 16-neighbour interpolation of equal values, times a/π: float rounding,
///    1e-5 relative. Background pixels see the environment through backgroundRadiance(),
///    i.e. the same lookup: also 1e-5. Each pixel is classified by casting its centre ray
///    (1 sample per pixel goes through the pixel centre, render.h).
void checkBakedSphere(float albedo, EnvKind kind, const std::string& mapPath = {}) {
  Rgb le;
  Scene scene = makeSphereScene(albedo, kind, mapPath, le);
  const size_t triangles = scene.triangleCount();
  BakeSettings settings = bakePreset("draft");
  settings.tixelsAcrossScene = 24;  // tixel side 2/24: a few tixels per facet, many outside it
  settings.gatherDirections = 64;
  const LightField lf = bake(std::move(scene), settings);
  const std::string what = std::string(envName(kind)) + ", albedo " + std::to_string(albedo);

  // No two facets of the icosphere are coplanar, but neighbours meet at less than
  // kFlatShadedChartEdgeDegrees: curved charts of several facets (parameterisation.h), each
  // tixel gathering around its facet's normal; all diffuse.
  ASSERT_LT(lf.charts.size(), triangles) << what;
  uint64_t tixels = 0;
  for (const Chart& c : lf.charts) {
    ASSERT_EQ(c.kind, ChartKind::Diffuse) << what;
    for (uint32_t j = 0; j < c.resV; ++j)
      for (uint32_t i = 0; i < c.resU; ++i) {
        const Rgb E = lf.values[c.valueIndex(i, j)];
        for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(E[ch], kPi * le[ch], 1e-5f * kPi * le[ch]) << what << " tixel " << i << "," << j;
        ++tixels;
      }
  }
  EXPECT_GT(tixels, lf.charts.size()) << "some facets should hold several tixels";
  EXPECT_LE(lf.stats.residual, settings.tolerance) << what;
  std::printf("%s: %zu charts, %llu tixels, %u iterations, residual %.2e\n", what.c_str(), lf.charts.size(),
              static_cast<unsigned long long>(tixels), lf.stats.iterations, lf.stats.residual);

  const Accel accel(lf.scene);
  const FastRenderer fast(lf, accel);
  const Rgb onSphere = le * albedo;
  for (const Vec3& eye : {Vec3(0.0f, 0.0f, 3.5f), Vec3(2.0f, -2.5f, 1.5f)}) {
    const Camera camera(sphereCamera(eye), 40, 30);
    RenderSettings rs;
    rs.samplesPerPixel = 1;
    const Image reference = renderLightField(lf, accel, camera, rs);
    const Image fastImage = fast.render(camera, rs);
    int hits = 0, misses = 0;
    for (int y = 0; y < camera.height(); ++y)
      for (int x = 0; x < camera.width(); ++x) {
        RayHit hit;
        const bool onIt = accel.intersect(camera.generateRay(Vec2(x + 0.5f, y + 0.5f), Vec2(0.5f)).ray, hit);
        (onIt ? hits : misses) += 1;
        const Rgb expected = onIt ? onSphere : le;
        for (int ch = 0; ch < 3; ++ch) {
          ASSERT_NEAR(reference.at(x, y)[ch], expected[ch], 1e-5f * expected[ch]) << what << " render, pixel " << x << "," << y;
          ASSERT_NEAR(fastImage.at(x, y)[ch], expected[ch], 1e-5f * expected[ch]) << what << " fast render, pixel " << x << "," << y;
        }
      }
    EXPECT_GT(hits, 200) << what;
    EXPECT_GT(misses, 200) << what;
  }
}

TEST_F(EnvFurnaceTest, BakedSphereUnderConstantEnvironment) {
  for (float albedo : {0.5f, 0.8f}) checkBakedSphere(albedo, EnvKind::Constant);
}

TEST_F(EnvFurnaceTest, BakedSphereUnderConstantEnvironmentMap) {
  for (float albedo : {0.5f, 0.8f}) checkBakedSphere(albedo, EnvKind::Map, path("constant.hdr"));
}

}  // namespace
}  // namespace pl
