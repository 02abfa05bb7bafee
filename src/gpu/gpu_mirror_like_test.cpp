// The mirror-like lobe's GLSL (gpu_mirror_like.h) against bsdf.h's sample() and pdf() on
// random directions and numbers, for Blinn-Phong and GGX models as narrow as mirror-like
// charts are. Runs on Mesa's llvmpipe through surfaceless EGL where there is no GPU.
#include "gpu/gpu_mirror_like.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "bsdf/bsdf.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "gpu/gpu.h"
#include "scene/scene.h"
#include "support/random_light_field.h"

namespace pl {
namespace {

/// The built-in box with its blocks' materials replaced by narrow lobes (the first models) and
/// a few more materials on no triangle (the light field need not draw them; the queries name
/// them by index).
Scene narrowLobesBox(std::vector<uint32_t>& lobeMaterials) {
  Scene scene = makeCornellBox();
  const std::vector<Bsdf> models = {
      BlinnPhongBsdf{Rgb(0.0f), Rgb(0.9f, 0.7f, 0.4f), 2000.0f},
      BlinnPhongBsdf{Rgb(0.0f), Rgb(0.5f), 20000.0f},
      BlinnPhongBsdf{Rgb(0.0f), Rgb(0.8f, 0.8f, 0.9f), 300.0f},
      GgxBsdf{Rgb(0.0f), Rgb(0.95f, 0.64f, 0.54f), 0.05f},
      GgxBsdf{Rgb(0.0f), Rgb(0.04f), 0.01f},
      GgxBsdf{Rgb(0.0f), Rgb(0.9f), 0.2f},
  };
  for (const Bsdf& model : models) {
    Material m;
    m.name = "lobe" + std::to_string(lobeMaterials.size());
    m.bsdf = model;
    lobeMaterials.push_back(uint32_t(scene.materials.size()));
    scene.materials.push_back(m);
  }
  scene.finalize();
  return scene;
}

/// Directions, weights and densities from a few dozen float operations, pow, sin and cos of
/// the shading language among them, on ill-conditioned inputs: a Blinn-Phong lobe of exponent
/// n puts the sampled half-vector at 1 − cos θh ≈ −ln(u)/n, where an ulp of cos θh is a part in
/// 1e-4 of sin²θh at n = 20 000, so the sampled direction carries that error (bound 5e-4 in
/// length); GGX's D at α = 0.01 divides by cos²θh(α² − 1) + 1, a difference of numbers near 1
/// that falls to α² = 1e-4 at the peak, so a rounding there (a fused multiply-add on one side)
/// moves the density by up to a part in 1e2 (bound 2e-2; the weight f·cos θ/p, where D cancels,
/// 1e-2). A wrong formula is off by far more: a factor of the exponent, of α or of 4 wo·h.
bool nearRelative(float a, float b, float relative) {
  return std::abs(a - b) <= std::max(1e-6f, relative * std::max(std::abs(a), std::abs(b)));
}

TEST(GpuMirrorLike, ShaderLobeMatchesCppSample) {
  std::vector<uint32_t> lobeMaterials;
  const LightField lf = test_support::randomLightField(narrowLobesBox(lobeMaterials), 3);
  EXPECT_EQ(gpuUnsupportedMirrorLike(lf), "");
  GpuRenderer gpu(lf);
  Pcg32 rng(17, 9);
  std::vector<GpuRenderer::LobeQuery> queries(6000);
  for (size_t i = 0; i < queries.size(); ++i) {
    GpuRenderer::LobeQuery& q = queries[i];
    q.material = lobeMaterials[i % lobeMaterials.size()];
    // wo over the whole sphere (below the horizon: nothing), wi near the mirror direction
    // half of the time so that the density is asked inside the lobe.
    q.wo = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    const Vec3 mirrored(-q.wo.x, -q.wo.y, q.wo.z);
    q.wi = rng.uniform() < 0.5f ? glm::normalize(mirrored + 0.03f * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f))
                                : sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    q.u = Vec2(rng.uniform(), rng.uniform());
  }
  const std::vector<GpuRenderer::LobeAnswer> answers = gpu.sampleLobes(queries);
  ASSERT_EQ(answers.size(), queries.size());
  int sampled = 0, lobePdfs = 0, wrong = 0;
  float worstDirection = 0.0f, worstWeight = 0.0f, worstPdf = 0.0f;
  for (size_t i = 0; i < queries.size(); ++i) {
    const GpuRenderer::LobeQuery& q = queries[i];
    const GpuRenderer::LobeAnswer& a = answers[i];
    const Bsdf& model = lf.scene.materials[q.material].bsdf;
    const std::optional<BsdfSample> s = sample(model, q.wo, q.u);
    bool ok = a.sampled == s.has_value();
    if (s && a.sampled) {
      ++sampled;
      const float direction = glm::length(a.sample.wi - s->wi);
      worstDirection = std::max(worstDirection, direction);
      ok = ok && direction <= 5e-4f && nearRelative(a.sample.pdf, s->pdf, 2e-2f);
      for (int c = 0; c < 3; ++c) ok = ok && nearRelative(a.sample.weight[c], s->weight[c], 1e-2f);
      worstWeight = std::max(worstWeight, std::abs(a.sample.weight.r - s->weight.r) / std::max(1e-6f, s->weight.r));
      worstPdf = std::max(worstPdf, std::abs(a.sample.pdf - s->pdf) / std::max(1e-6f, s->pdf));
    }
    const float wiPdf = pdf(model, q.wo, q.wi);
    lobePdfs += wiPdf > 1.0f;
    ok = ok && nearRelative(a.wiPdf, wiPdf, 2e-2f);
    if (!ok && ++wrong <= 5)
      ADD_FAILURE() << "query " << i << " (material " << q.material << "): GPU sampled " << a.sampled << " wi ("
                    << a.sample.wi.x << ", " << a.sample.wi.y << ", " << a.sample.wi.z << ") pdf " << a.sample.pdf
                    << " weight " << a.sample.weight.r << "; C++ " << s.has_value() << " wi (" << (s ? s->wi.x : 0.0f)
                    << ", " << (s ? s->wi.y : 0.0f) << ", " << (s ? s->wi.z : 0.0f) << ") pdf " << (s ? s->pdf : 0.0f)
                    << " weight " << (s ? s->weight.r : 0.0f) << "; pdf(wi) " << a.wiPdf << " vs " << wiPdf;
  }
  std::printf("%d samples, %d densities inside a lobe; worst direction %.2g, weight %.2g, density %.2g (relative)\n",
              sampled, lobePdfs, double(worstDirection), double(worstWeight), double(worstPdf));
  EXPECT_EQ(wrong, 0);
  EXPECT_GT(sampled, 2000);
  EXPECT_GT(lobePdfs, 500);
}

}  // namespace
}  // namespace pl
