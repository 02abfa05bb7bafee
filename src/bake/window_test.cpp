// The bake's first shot sees point, spot and directional lights through thin glass exactly as
// the path tracer's next-event estimation does (issue 14, item 4b): both trace their shadow
// rays with light/light.h's ShadowRays, which multiplies by each sheet's straight
// transmittance T'(cos θ) and stops at any other surface.
#include <gtest/gtest.h>

#include <cmath>

#include "accel/accel.h"
#include "core/progress.h"
#include "bake/bake.h"
#include "lightfield/lookup.h"
#include "scene/scene.h"
#include "trace/trace.h"

namespace pl {
namespace {

/// A horizontal square of half-size h at height y, facing up, as two triangles.
void addSquare(Mesh& mesh, float y, float h, uint32_t material) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  for (const Vec3& p : {Vec3(-h, y, -h), Vec3(-h, y, h), Vec3(h, y, h), Vec3(h, y, -h)}) mesh.positions.push_back(p);
  mesh.triangles.push_back(UVec3(base, base + 1, base + 2));
  mesh.triangles.push_back(UVec3(base, base + 2, base + 3));
  mesh.materials.push_back(material);
  mesh.materials.push_back(material);
}

constexpr float kAlbedo = 0.8f;
const DielectricBsdf kWindow{1.5f, Rgb(0.9f, 0.6f, 0.3f), 0.0f, true};

/// A Lambertian floor (half-size 5, y = 0), a thin tinted window (half-size 2, y = 1) above it
/// and one light; the sky is black.
Scene windowScene(const Light& light, bool glassIsThin) {
  Scene scene;
  scene.sourcePath = "window test";
  Material floor;
  floor.name = "floor";
  floor.bsdf = LambertBsdf{Rgb(kAlbedo)};
  Material window;
  window.name = "window";
  DielectricBsdf glass = kWindow;
  glass.thin = glassIsThin;
  window.bsdf = glass;
  scene.materials = {floor, window};
  Mesh mesh;
  mesh.name = "floor and window";
  addSquare(mesh, 0.0f, 5.0f, 0);
  addSquare(mesh, 1.0f, 2.0f, 1);
  scene.meshes.push_back(mesh);
  scene.lights.push_back(light);
  scene.finalize();
  return scene;
}

/// The light field's exitant radiance at floor point (x, 0, z), seen from straight above,
/// after the first shot alone (no propagation iterations: the direct light only).
Rgb lightFieldDirect(const LightField& lf, float x, float z) {
  const Vec3 p(x, 0.0f, z);
  for (uint32_t ci = 0; ci < lf.charts.size(); ++ci) {
    const Chart& c = lf.charts[ci];
    if (c.kind != ChartKind::Diffuse || std::abs(glm::dot(p - c.origin, c.normal)) > 1e-4f) continue;
    return exitantRadiance(lf, ci, p, Vec3(0.0f, 1.0f, 0.0f), Vec2(0.0f));
  }
  ADD_FAILURE() << "no floor chart";
  return Rgb(0.0f);
}

/// The path tracer's direct light (one scattering event) at floor point (x, 0, z).
Rgb tracedDirect(const Scene& scene, float x, float z) {
  const Accel accel(scene);
  const PathTracer tracer(scene, accel);
  TraceSettings settings;
  settings.spp = 16;
  settings.maxDepth = 1;
  // From just above the floor, looking straight down (below the window, so the camera ray
  // does not cross it).
  const Ray ray{Vec3(x, 0.5f, z), Vec3(0.0f, -1.0f, 0.0f), 0.0f, kInfinity};
  return tracer.estimateRadiance(ray, settings, 7).mean;
}

BakeSettings directOnly() {
  BakeSettings settings = bakePreset("draft");
  settings.tixelsAcrossScene = 40;  // 0.25-unit tixels on the floor
  settings.maxTixelsPerChartSide = 64;
  settings.maxIterations = 0;  // the first shot only
  return settings;
}

class WindowTest : public ::testing::Test {
 protected:
  void SetUp() override { Progress::setEnabled(false); }
};

// A sun (directional light of irradiance E, travelling at θ from the vertical) over a floor of
// albedo ρ: under the window L = ρ/π·E·cos θ·T'(cos θ), beside it ρ/π·E·cos θ. The light
// field, the path tracer and this closed form agree. The irradiance is uniform, so the light
// field's interpolation is exact and the tolerance is float rounding.
TEST_F(WindowTest, SunThroughAThinWindowReachesTheLightField) {
  const float theta = 0.5f;
  const Rgb irradiance(3.0f, 2.0f, 1.0f);
  const Scene scene = windowScene(DirectionalLight{Vec3(std::sin(theta), -std::cos(theta), 0.0f), irradiance}, true);
  const LightField lf = bake(scene, directOnly());
  Rgb reflectance, straight;
  thinSheetReflectanceTransmittance(kWindow, std::cos(theta), reflectance, straight);
  const Rgb open = kAlbedo * kInvPi * irradiance * std::cos(theta);
  // (0, 0, 0) sees the sun through the window at x = −tan θ ≈ −0.55; (4, 0, 0) past its edge
  // at x ≈ 3.45 (the window ends at 2).
  struct Point {
    float x, z;
    Rgb expected;
  };
  for (const Point& p : {Point{0.0f, 0.5f, open * straight}, Point{-1.0f, -1.0f, open * straight},
                         Point{4.0f, 0.0f, open}}) {
    const Rgb field = lightFieldDirect(lf, p.x, p.z), traced = tracedDirect(scene, p.x, p.z);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(field[c], p.expected[c], 1e-4f * p.expected[c]) << "light field at x=" << p.x << " channel " << c;
      EXPECT_NEAR(traced[c], p.expected[c], 1e-4f * p.expected[c]) << "path tracer at x=" << p.x << " channel " << c;
    }
  }
  // The tint is really applied (T' is coloured), not just a pass.
  EXPECT_LT(lightFieldDirect(lf, 0.0f, 0.5f).b, 0.5f * open.b);
}

// A point light of intensity I above the window: the floor tixels under it receive
// I cos θ/d²·T'(cos θ). The irradiance varies over the floor, so the light field (bilinear
// over tixels) is compared with the closed form at a tixel-scale tolerance (2 %; the path
// tracer at 1e-4). With the window made of solid glass the floor stays dark in both: only thin
// sheets are crossed by shadow rays.
TEST_F(WindowTest, PointLightThroughThinWindowButNotThroughSolidGlass) {
  const Rgb intensity(10.0f);
  const Vec3 light(0.0f, 3.0f, 0.0f);
  for (const bool thin : {true, false}) {
    const Scene scene = windowScene(PointLight{light, intensity}, thin);
    const LightField lf = bake(scene, directOnly());
    for (const float x : {0.0f, 0.5f}) {
      const float d2 = x * x + 9.0f, cosTheta = 3.0f / std::sqrt(d2);
      Rgb reflectance, straight;
      thinSheetReflectanceTransmittance(kWindow, cosTheta, reflectance, straight);
      const Rgb expected = thin ? kAlbedo * kInvPi * intensity * cosTheta / d2 * straight : Rgb(0.0f);
      const Rgb field = lightFieldDirect(lf, x, 0.0f), traced = tracedDirect(scene, x, 0.0f);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(traced[c], expected[c], 1e-4f * expected[c] + 1e-7f) << "path tracer x=" << x << " thin " << thin;
        EXPECT_NEAR(field[c], expected[c], 0.02f * expected[c] + 1e-7f) << "light field x=" << x << " thin " << thin;
      }
    }
  }
}

}  // namespace
}  // namespace pl
