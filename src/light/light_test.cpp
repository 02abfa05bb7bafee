// The light sampler and shadow rays: densities consistent with what is sampled, estimators
// against closed forms, the bake's area sampling, thin-glass transmittance.
#include "light/light.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "accel/accel.h"
#include "bsdf/bsdf.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "support/sky_map.h"

namespace pl {
namespace {

uint32_t addMaterial(Scene& scene, const Bsdf& bsdf, const Rgb& emission = Rgb(0.0f), bool twoSided = false) {
  Material m;
  m.name = "m" + std::to_string(scene.materials.size());
  m.bsdf = bsdf;
  m.emission = emission;
  m.twoSidedEmission = twoSided;
  scene.materials.push_back(m);
  return static_cast<uint32_t>(scene.materials.size() - 1);
}

/// The rectangle [x0, x1] × [z0, z1] at height y as two triangles, facing down (−y) or up.
void addRectangle(Mesh& mesh, float x0, float x1, float z0, float z1, float y, bool facingDown, uint32_t material) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  for (const Vec3& p : {Vec3(x0, y, z0), Vec3(x1, y, z0), Vec3(x1, y, z1), Vec3(x0, y, z1)}) mesh.positions.push_back(p);
  // (x0,z0) → (x1,z0) → (x1,z1) winds with normal −y.
  if (facingDown) {
    mesh.triangles.push_back(UVec3(base, base + 1, base + 2));
    mesh.triangles.push_back(UVec3(base, base + 2, base + 3));
  } else {
    mesh.triangles.push_back(UVec3(base, base + 2, base + 1));
    mesh.triangles.push_back(UVec3(base, base + 3, base + 2));
  }
  mesh.materials.push_back(material);
  mesh.materials.push_back(material);
}

Scene finished(Scene scene) {
  scene.sourcePath = "light test";
  scene.finalize();
  return scene;
}

/// Two emitters of different radiance and size (one two-sided), a point light and a constant
/// sky over a floor.
Scene mixedLights() {
  Scene s;
  Mesh mesh;
  mesh.name = "lights";
  addRectangle(mesh, -0.5f, 0.5f, -0.5f, 0.5f, 2.0f, true, addMaterial(s, LambertBsdf{}, Rgb(4.0f, 3.0f, 2.0f)));
  addRectangle(mesh, 1.0f, 1.5f, -1.0f, 0.0f, 1.5f, true, addMaterial(s, LambertBsdf{}, Rgb(1.0f, 2.0f, 6.0f), true));
  addRectangle(mesh, -3.0f, 3.0f, -3.0f, 3.0f, 0.0f, false, addMaterial(s, LambertBsdf{Rgb(0.5f)}));
  s.meshes.push_back(mesh);
  s.lights.push_back(PointLight{{0.0f, 1.0f, 1.0f}, Rgb(2.0f)});
  s.environment.constant = Rgb(0.1f);
  return finished(std::move(s));
}

// Every sample's density is the one emitterPdf / environmentPdf report for the point or
// direction it produced (the path tracer's MIS weights for BSDF-sampled hits rely on it), and
// the three kinds of light are all chosen.
TEST(LightSampler, SampleDensitiesMatchTheLookedUpDensities) {
  const Scene scene = mixedLights();
  const Accel accel(scene);
  const LightSampler lights(scene);
  EXPECT_EQ(lights.emissiveTriangleCount(), 4u);
  EXPECT_EQ(lights.lightCount(), 6u);  // 4 triangles, the point light, the sky
  const Vec3 receiver(0.2f, 0.01f, -0.3f);
  Pcg32 rng(1, 2);
  int triangles = 0, delta = 0, sky = 0;
  for (int i = 0; i < 4000; ++i) {
    const std::optional<LightSample> s = lights.sample(receiver, Vec2(rng.uniform(), rng.uniform()));
    if (!s) continue;  // the back of a one-sided emitter cannot be: none faces away here
    ASSERT_GT(s->pdf, 0.0f);
    if (s->nextEventOnly) {  // the point light, the one scene light here
      ++delta;
      continue;
    }
    if (s->infinite) {
      ++sky;
      EXPECT_NEAR(lights.environmentPdf(s->wi), s->pdf, 1e-5f * s->pdf);
      continue;
    }
    ++triangles;
    RayHit hit;
    ASSERT_TRUE(accel.intersect(Ray{receiver, s->wi, 0.0f, kInfinity}, hit));
    const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
    const float cosLight = std::abs(glm::dot(surface.geometricNormal, s->wi));
    EXPECT_NEAR(lights.emitterPdf(hit.mesh, hit.triangle, hit.t, cosLight), s->pdf, 2e-3f * s->pdf);
    // The shadow ray ends just short of the emitter, on the receiver's side.
    EXPECT_LT(glm::length(s->target - receiver), hit.t);
    EXPECT_GT(glm::length(s->target - receiver), hit.t - 1e-3f);
  }
  EXPECT_GT(triangles, 100);
  EXPECT_GT(delta, 100);
  EXPECT_GT(sky, 100);
  // The floor is no light.
  EXPECT_EQ(lights.emitterPdf(0, 4, 1.0f, 1.0f), 0.0f);
}

// A sphere light, no geometry, is found along a ray by sphereLightAlong with the density the
// sampler gives the same direction (the renderers' MIS at mirror-like lobes relies on it): for
// every sampled direction towards it, the crossing's density is the sample's, its radiance
// I/(πr²); a ray that stops short of the sphere, or misses it, finds none.
TEST(LightSampler, SphereLightsAreFoundAlongRaysWithTheirSampleDensity) {
  Scene s = mixedLights();
  s.lights.push_back(createLight("sphere", {{"position", Vec3(0.3f, 1.5f, 0.2f)}, {"radius", 0.25f},
                                            {"intensity", Rgb(3.0f)}}, "test"));
  s.finalize();
  const LightSampler lights(s);
  ASSERT_TRUE(lights.hasSphereLights());
  const Vec3 receiver(0.2f, 0.01f, -0.3f);
  Pcg32 rng(3, 4);
  int spheres = 0;
  for (int i = 0; i < 4000; ++i) {
    const std::optional<LightSample> l = lights.sample(receiver, Vec2(rng.uniform(), rng.uniform()));
    if (!l || !l->nextEventOnly) continue;
    if (l->delta) continue;  // the point light
    ++spheres;
    const Ray ray{receiver, l->wi, 0.0f, kInfinity};
    const std::optional<LightSampler::SphereCrossing> crossing = lights.sphereLightAlong(ray, receiver);
    ASSERT_TRUE(crossing);
    EXPECT_NEAR(crossing->pdf, l->pdf, 1e-4f * l->pdf);
    EXPECT_EQ(crossing->radiance, Rgb(3.0f) / (kPi * 0.25f * 0.25f));
    EXPECT_FALSE(lights.sphereLightAlong(Ray{receiver, l->wi, 0.0f, 0.5f * glm::length(l->target - receiver)}, receiver));
  }
  EXPECT_GT(spheres, 50);
  EXPECT_FALSE(lights.sphereLightAlong(Ray{receiver, Vec3(0.0f, -1.0f, 0.0f), 0.0f, kInfinity}, receiver));
}

// Irradiance under the corner of a parallel rectangle emitter of radiance Le, w × l at height
// h: E = π·Le·F with the form factor F = 1/(2π)·[a/√(1+a²)·atan(b/√(1+a²)) +
// b/√(1+b²)·atan(a/√(1+b²))], a = w/h, b = l/h. The light estimator Σ Le·cos θ/pdf over
// samples of the quad (two triangles, one 2-D sample choosing the triangle and the point)
// converges to it.
TEST(LightSampler, IrradianceFromARectangleMatchesTheFormFactor) {
  const float w = 1.0f, l = 0.5f, h = 0.8f;
  const Rgb le(2.0f);
  Scene s;
  Mesh mesh;
  mesh.name = "light";
  addRectangle(mesh, 0.0f, w, 0.0f, l, h, true, addMaterial(s, LambertBsdf{}, le));
  s.meshes.push_back(mesh);
  const Scene scene = finished(std::move(s));
  const LightSampler lights(scene);
  const float a = w / h, b = l / h;
  const double formFactor = (a / std::sqrt(1.0 + a * a) * std::atan(b / std::sqrt(1.0 + a * a)) +
                             b / std::sqrt(1.0 + b * b) * std::atan(a / std::sqrt(1.0 + b * b))) /
                            (2.0 * kPiD);
  const double expected = kPiD * le.g * formFactor;
  Pcg32 rng(3, 4);
  const int n = 200000;
  double sum = 0.0, sumSquares = 0.0;
  for (int i = 0; i < n; ++i) {
    const std::optional<LightSample> sample = lights.sample(Vec3(0.0f), Vec2(rng.uniform(), rng.uniform()));
    const double v = sample ? double(sample->incident.g) * sample->wi.y / sample->pdf : 0.0;
    sum += v;
    sumSquares += v * v;
  }
  const double mean = sum / n, standardError = std::sqrt((sumSquares / n - mean * mean) / n);
  EXPECT_NEAR(mean, expected, 4.0 * standardError);
  EXPECT_LT(standardError, 2e-3 * expected);  // the check is meaningful at 1 %
}

// The bake's area sampling: the triangles are chosen ∝ power (π·A·Y(Le), ×2 two-sided), and
// the reported area density is exactly that probability over the triangle's area, so that
// E[1/areaPdf] is the total emitting area.
TEST(LightSampler, EmitterPointsByAreaIntegrateTheArea) {
  const Scene scene = mixedLights();
  const LightSampler lights(scene);
  const double area0 = 1.0, area1 = 0.5;
  const double power0 = area0 * luminance(Rgb(4.0f, 3.0f, 2.0f)), power1 = 2.0 * area1 * luminance(Rgb(1.0f, 2.0f, 6.0f));
  const double p0 = power0 / (power0 + power1);
  // Mesh 0's triangles 0–1 are the first light, 2–3 the second, 4–5 the floor.
  EXPECT_NEAR(lights.emitterAreaPdf(0, 1), p0 / area0, 1e-5 * p0 / area0);
  EXPECT_NEAR(lights.emitterAreaPdf(0, 2), (1.0 - p0) / area1, 1e-5 * (1.0 - p0) / area1);
  EXPECT_EQ(lights.emitterAreaPdf(0, 4), 0.0f);
  Pcg32 rng(5, 6);
  const int n = 100000;
  int onFirst = 0;
  double inverseSum = 0.0;
  for (int i = 0; i < n; ++i) {
    const EmitterPoint e = lights.sampleEmitterPoint(Vec2(rng.uniform(), rng.uniform()));
    ASSERT_NE(e.triangle, nullptr);
    inverseSum += 1.0 / e.areaPdf;
    if (e.triangle->material == 0) {
      ++onFirst;
      EXPECT_NEAR(e.point.y, 2.0f, 1e-5f);
      EXPECT_LE(std::abs(e.point.x), 0.5f + 1e-5f);
    } else {
      EXPECT_NEAR(e.point.y, 1.5f, 1e-5f);
    }
  }
  // Binomial: 4 standard deviations.
  EXPECT_NEAR(double(onFirst) / n, p0, 4.0 * std::sqrt(p0 * (1.0 - p0) / n));
  EXPECT_NEAR(inverseSum / n, area0 + area1, 0.01 * (area0 + area1));
}

// A shadow ray crossing thin sheets is multiplied by each one's straight transmittance
// T'(cos θ); solid glass and opaque surfaces block it; without thin glass in the scene it is
// one plain occlusion ray.
TEST(ShadowRays, ThinGlassTransmitsSolidGlassAndWallsBlock) {
  const DielectricBsdf thin{1.5f, Rgb(0.9f, 0.6f, 0.3f), 0.0f, true};
  DielectricBsdf solid = thin;
  solid.thin = false;
  Scene s;
  Mesh mesh;
  mesh.name = "sheets";
  const uint32_t sheet = addMaterial(s, thin);
  addRectangle(mesh, -5.0f, 5.0f, -5.0f, 5.0f, 1.0f, false, sheet);
  addRectangle(mesh, -5.0f, 5.0f, -5.0f, 5.0f, 2.0f, true, sheet);               // a second sheet, facing down
  addRectangle(mesh, 10.0f, 20.0f, -5.0f, 5.0f, 1.0f, false, addMaterial(s, solid));  // solid glass at x ∈ [10, 20]
  addRectangle(mesh, -20.0f, -10.0f, -5.0f, 5.0f, 1.0f, false, addMaterial(s, LambertBsdf{}));  // a wall
  s.meshes.push_back(mesh);
  const Scene scene = finished(std::move(s));
  const Accel accel(scene);
  const ShadowRays shadows(scene, accel);
  ASSERT_TRUE(shadows.passesThinGlass());
  const float cosTheta = 0.8f;
  const Vec3 up(0.6f, 0.8f, 0.0f);
  Rgb reflectance, straight;
  thinSheetReflectanceTransmittance(thin, cosTheta, reflectance, straight);
  uint64_t rays = 0;
  // Through one sheet (ends between them), through both, and an unbounded ray.
  const Rgb one = shadows.transmittance(*shadowRayTo(Vec3(0.0f), 1.5f / cosTheta * up), rays);
  const Rgb two = shadows.transmittance(*shadowRayTo(Vec3(0.0f), 3.0f / cosTheta * up), rays);
  const Rgb infinite = shadows.transmittance(Ray{Vec3(0.0f), up, 0.0f, kInfinity}, rays);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(one[c], straight[c], 1e-5f);
    EXPECT_NEAR(two[c], straight[c] * straight[c], 1e-5f);
    EXPECT_NEAR(infinite[c], straight[c] * straight[c], 1e-5f);
  }
  EXPECT_EQ(rays, 2u + 3u + 3u);  // one ray per segment between sheets
  EXPECT_EQ(shadows.transmittance(*shadowRayTo(Vec3(15.0f, 0.0f, 0.0f), Vec3(15.0f, 1.5f, 0.0f)), rays), Rgb(0.0f));
  EXPECT_EQ(shadows.transmittance(*shadowRayTo(Vec3(-15.0f, 0.0f, 0.0f), Vec3(-15.0f, 1.5f, 0.0f)), rays), Rgb(0.0f));
  EXPECT_FALSE(shadowRayTo(Vec3(1.0f), Vec3(1.0f)).has_value());

  // The same walls without thin glass: one occlusion ray each.
  Scene opaque = scene;
  opaque.materials[sheet].bsdf = LambertBsdf{};
  opaque.finalize();
  const Accel opaqueAccel(opaque);
  const ShadowRays opaqueShadows(opaque, opaqueAccel);
  EXPECT_FALSE(opaqueShadows.passesThinGlass());
  rays = 0;
  EXPECT_EQ(opaqueShadows.transmittance(*shadowRayTo(Vec3(0.0f), 1.5f / cosTheta * up), rays), Rgb(0.0f));
  EXPECT_EQ(opaqueShadows.transmittance(*shadowRayTo(Vec3(0.0f), 0.5f / cosTheta * up), rays), Rgb(1.0f));
  EXPECT_EQ(rays, 2u);
}

TEST(EnvironmentLight, ConstantPlusMapMixture) {
  // EnvironmentLight = constant + map. Its pdf integrates to 1, sample() reports pdf() and
  // radiance() of its direction, and L/pdf is an unbiased estimator of ∫ L dω.
  const auto map = std::make_shared<const EnvironmentMap>(test_support::skyWithSun(20.0f));
  const Rgb constant(0.3f, 0.2f, 0.1f);
  const EnvironmentLight light(constant, map);
  const double constantPower = 4.0 * kPiD * luminance(constant);
  EXPECT_NEAR(light.mapProbability(), map->integratedLuminance() / (map->integratedLuminance() + constantPower), 1e-6);
  EXPECT_GT(light.mapProbability(), 0.5f);  // the sun dominates
  const int h = 320;
  LatLongMap grid{Image(2 * h, h)};
  double pdfIntegral = 0.0, radianceIntegral = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 2 * h; ++x) {
      const Vec3 d = LatLongMap::direction((x + 0.5) / (2 * h), (y + 0.5) / h);
      pdfIntegral += light.pdf(d) * grid.texelSolidAngle(y);
      radianceIntegral += luminance(light.radiance(d)) * grid.texelSolidAngle(y);
    }
  EXPECT_NEAR(pdfIntegral, 1.0, 3e-3);  // same quadrature error as PdfIntegratesToOne
  Pcg32 rng(5, 1);
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const EnvironmentSample s = light.sample({rng.uniform(), rng.uniform()});
    ASSERT_EQ(s.pdf, light.pdf(s.direction));
    ASSERT_EQ(s.radiance, light.radiance(s.direction));
    const double v = s.pdf > 0.0f ? luminance(s.radiance) / s.pdf : 0.0;
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / n, sigma = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, radianceIntegral, 5.0 * sigma + 1e-3 * radianceIntegral);  // 5σ + quadrature
  // Constant only: uniform sphere sampling, pdf 1/(4π); nothing at all: black, pdf 0.
  const EnvironmentLight uniform(Rgb(1.0f), nullptr);
  EXPECT_FLOAT_EQ(uniform.pdf(Vec3(0, 1, 0)), kUniformSpherePdf);
  EXPECT_TRUE(EnvironmentLight().isBlack());
  EXPECT_EQ(EnvironmentLight().sample({0.5f, 0.5f}).pdf, 0.0f);
}

}  // namespace
}  // namespace pl
