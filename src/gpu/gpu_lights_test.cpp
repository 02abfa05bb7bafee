// The light sampler's GLSL (gpu_lights.h) against light/light.h LightSampler on random inputs:
// the same emitter chosen for the same numbers and the same sample (direction, radiance,
// density, shadow target), and the same densities for directions found by other means. Runs
// on Mesa's llvmpipe through surfaceless EGL where there is no GPU.
#include "gpu/gpu_lights.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "gpu/gpu.h"
#include "scene/scene.h"
#include "support/random_light_field.h"
#include "support/sky_map.h"

namespace pl {
namespace {

/// The built-in box with every kind of light the sampler chooses between: its emissive quad,
/// two sphere lights (one small and far, one large), a point light and a constant sky.
Scene allLightsBox() {
  Scene scene = makeCornellBox();
  scene.lights.push_back(SphereLight{Vec3(100.0f, 400.0f, 300.0f), 30.0f, Rgb(20000.0f, 15000.0f, 9000.0f)});
  scene.lights.push_back(SphereLight{Vec3(450.0f, 120.0f, 400.0f), 2.0f, Rgb(4000.0f)});
  scene.lights.push_back(PointLight{Vec3(278.0f, 498.0f, 279.5f), Rgb(25000.0f)});
  scene.environment.constant = Rgb(0.02f, 0.03f, 0.05f);
  scene.finalize();
  return scene;
}

/// |a − b| within float rounding of quantities computed by a few dozen operations, the shading
/// language's sin and cos among them (a few ulp off the C library's; the two agree to 1e-6 on
/// llvmpipe): relative 1e-5 of the larger magnitude, or 1e-6 absolute. A wrong emitter, point
/// or density is off by far more (a sphere light's density off by 0.5 % fails).
/// The largest relative difference near() saw above the absolute floor.
float worstRelative = 0.0f;
bool near(float a, float b) {
  const float difference = std::abs(a - b), scale = std::max(std::abs(a), std::abs(b));
  if (difference > 1e-6f) worstRelative = std::max(worstRelative, difference / scale);
  return difference <= std::max(1e-6f, 1e-5f * scale);
}
bool near(const Vec3& a, const Vec3& b) { return near(a.x, b.x) && near(a.y, b.y) && near(a.z, b.z); }

TEST(GpuLights, ShaderSamplerMatchesCppSampler) {
  const LightField lf = test_support::randomLightField(allLightsBox(), 3);
  const Scene& scene = lf.scene;
  const LightSampler sampler(scene);
  ASSERT_GT(sampler.emissiveTriangleCount(), 0u);
  ASSERT_TRUE(sampler.hasEnvironment());
  ASSERT_TRUE(sampler.hasSphereLights());
  EXPECT_EQ(gpuUnsupportedLights(sampler), "");
  GpuRenderer gpu(lf);

  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const auto entryOfTriangle = sampler.entryOfTriangle();
  std::vector<uint32_t> emissive;  // scene triangle indices of the emitters
  for (uint32_t g = 0; g < entryOfTriangle.size(); ++g)
    if (entryOfTriangle[g] >= 0) emissive.push_back(g);
  ASSERT_FALSE(emissive.empty());
  std::vector<std::pair<uint32_t, uint32_t>> meshTriangle;  // the scene index → (mesh, triangle)
  for (uint32_t m = 0; m < scene.meshes.size(); ++m)
    for (uint32_t t = 0; t < scene.meshes[m].triangles.size(); ++t) meshTriangle.emplace_back(m, t);

  Pcg32 rng(7, 5);
  std::vector<GpuRenderer::LightQuery> queries(6000);
  for (GpuRenderer::LightQuery& q : queries) {
    q.position = lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (hi - lo);
    q.u = Vec2(rng.uniform(), rng.uniform());
    // Half on emitters, half on any triangle (mostly none: density 0).
    q.triangle = rng.uniform() < 0.5f ? emissive[rng.next() % emissive.size()] : rng.next() % uint32_t(meshTriangle.size());
    q.distance = 1000.0f * rng.uniform();
    q.cosLight = 1.2f * rng.uniform() - 0.1f;  // some at or below 0
    q.origin = q.position;
    // Towards a sphere light half of the time, so that sphereLightAlong finds one.
    const Vec3 towards = rng.uniform() < 0.5f ? Vec3(100.0f, 400.0f, 300.0f) : Vec3(450.0f, 120.0f, 400.0f);
    q.direction = rng.uniform() < 0.5f ? glm::normalize(towards + 40.0f * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f) - q.origin)
                                       : sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    q.tMax = rng.uniform() < 0.2f ? 200.0f * rng.uniform() : kInfinity;
  }
  const std::vector<GpuRenderer::LightAnswer> answers = gpu.sampleLights(sampler, queries);
  ASSERT_EQ(answers.size(), queries.size());

  int sampled = 0, deltas = 0, environment = 0, spheres = 0, triangles = 0, emitterPdfs = 0, crossings = 0;
  int wrong = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const GpuRenderer::LightQuery& q = queries[i];
    const GpuRenderer::LightAnswer& a = answers[i];
    const std::optional<LightSample> s = sampler.sample(q.position, q.u);
    bool ok = a.sampled == s.has_value();
    if (s && a.sampled) {
      ++sampled;
      ok = ok && a.sample.delta == s->delta;
      if (s->delta) {
        ++deltas;
      } else {
        ok = ok && a.sample.infinite == s->infinite && near(a.sample.wi, s->wi) && near(a.sample.incident, s->incident) &&
             near(a.sample.pdf, s->pdf);
        if (s->infinite) ++environment;
        else ok = ok && near(a.sample.target, s->target);
        if (!s->infinite) (s->nextEventOnly ? spheres : triangles) += 1;
      }
    }
    const auto [mesh, triangle] = meshTriangle[q.triangle];
    const float emitterPdf = sampler.emitterPdf(mesh, triangle, q.distance, q.cosLight);
    emitterPdfs += emitterPdf > 0.0f;
    ok = ok && near(a.emitterPdf, emitterPdf);
    ok = ok && near(a.environmentPdf, sampler.environmentPdf(q.direction));
    const std::optional<LightSampler::SphereCrossing> crossing =
        sampler.sphereLightAlong(Ray{q.origin, q.direction, 0.0f, q.tMax}, q.position);
    ok = ok && a.sphere == crossing.has_value();
    if (crossing && a.sphere) {
      ++crossings;
      ok = ok && near(a.crossing.radiance, crossing->radiance) && near(a.crossing.pdf, crossing->pdf);
    }
    if (!ok && ++wrong <= 5)
      ADD_FAILURE() << "query " << i << ": GPU sampled " << a.sampled << " pdf " << a.sample.pdf << " wi (" << a.sample.wi.x
                    << ", " << a.sample.wi.y << ", " << a.sample.wi.z << "), C++ " << s.has_value() << " pdf "
                    << (s ? s->pdf : 0.0f) << " wi (" << (s ? s->wi.x : 0.0f) << ", " << (s ? s->wi.y : 0.0f) << ", "
                    << (s ? s->wi.z : 0.0f) << "); emitter pdf " << a.emitterPdf << " vs " << emitterPdf;
  }
  std::printf("%d samples (%d triangle, %d sphere, %d sky, %d delta), %d emitter densities, %d sphere crossings; worst "
              "relative difference %.2g\n",
              sampled, triangles, spheres, environment, deltas, emitterPdfs, crossings, double(worstRelative));
  EXPECT_EQ(wrong, 0);
  // Every kind was drawn, and the densities were asked where they are not 0.
  EXPECT_GT(triangles, 100);
  EXPECT_GT(spheres, 100);
  EXPECT_GT(deltas, 100);
  EXPECT_GT(environment, 10);
  EXPECT_GT(emitterPdfs, 1000);
  EXPECT_GT(crossings, 500);
  EXPECT_GT(sampled, 3000);
}

TEST(GpuLights, RefusesAnEnvironmentMap) {
  Scene scene = makeCornellBox();
  scene.environment.map = std::make_shared<const EnvironmentMap>(test_support::skyWithSun(0.0f));
  scene.finalize();
  const LightSampler sampler(scene);
  EXPECT_EQ(gpuUnsupportedLights(sampler), "environment maps lighting mirror-like lobes");
  const LightField lf = test_support::randomLightField(scene, 4);
  GpuRenderer gpu(lf);
  try {
    gpu.sampleLights(sampler, {GpuRenderer::LightQuery{}});
    ADD_FAILURE() << "an environment map was sampled";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("environment maps"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pl
