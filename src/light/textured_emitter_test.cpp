// Textured emitters in the light sampler: the per-triangle means that weight the choice, an
// irradiance against its closed form for a checker (nearest-filtered, so piecewise constant),
// next-event estimation against plain uniform area sampling for a bilinear texture under a
// uv transform, and triangles whose texture is black under them (probability 0, still right).
#include "light/light.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "core/rng.h"

namespace pl {
namespace {

/// The rectangle [x0, x1] × [z0, z1] at height y facing down (−y), as two triangles, with uvs
/// u from uMin at x0 to uMax at x1 and v from 0 at z0 to 1 at z1.
void addPanel(Mesh& mesh, float x0, float x1, float z0, float z1, float y, uint32_t material, float uMin = 0.0f,
              float uMax = 1.0f) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  for (const Vec3& p : {Vec3(x0, y, z0), Vec3(x1, y, z0), Vec3(x1, y, z1), Vec3(x0, y, z1)}) mesh.positions.push_back(p);
  for (const Vec2& uv : {Vec2(uMin, 0.0f), Vec2(uMax, 0.0f), Vec2(uMax, 1.0f), Vec2(uMin, 1.0f)}) mesh.uvs.push_back(uv);
  mesh.triangles.push_back(UVec3(base, base + 1, base + 2));  // winds with normal −y
  mesh.triangles.push_back(UVec3(base, base + 2, base + 3));
  mesh.materials.push_back(material);
  mesh.materials.push_back(material);
}

/// A texture of w × h texels, texel (x, y) (row 0 at the top, v = 1) = texel(x, y).
Texture makeTexture(int w, int h, const std::function<Rgb(int, int)>& texel, TextureSampling sampling = {}) {
  Texture t;
  t.path = "test texture";
  t.image = Image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t.image.at(x, y) = texel(x, y);
  t.sampling = sampling;
  return t;
}

/// One emissive material with texture 0 and a floor-less scene holding `mesh`.
Scene emitterScene(Mesh mesh, Texture texture, const Rgb& emission, TextureMapping mapping = {}) {
  Scene s;
  s.sourcePath = "textured emitter test";
  Material m;
  m.name = "panel";
  m.emission = emission;
  m.emissionTexture = 0;
  m.emissionMapping = mapping;
  s.materials.push_back(m);
  s.textures.push_back(std::move(texture));
  mesh.name = "panel";
  s.meshes.push_back(std::move(mesh));
  s.finalize();
  return s;
}

/// Mean and standard error of f over n draws.
struct Estimate {
  DVec3 mean{0.0}, standardError{0.0};
};
Estimate estimate(int n, const std::function<Rgb()>& f) {
  DVec3 sum(0.0), squares(0.0);
  for (int i = 0; i < n; ++i) {
    const DVec3 v(f());
    sum += v;
    squares += v * v;
  }
  Estimate e;
  e.mean = sum / double(n);
  e.standardError = glm::sqrt(glm::max(DVec3(0.0), squares / double(n) - e.mean * e.mean) / double(n));
  return e;
}

/// Irradiance at the origin (normal +y) from next-event samples of `lights`, n of them.
Estimate neeIrradiance(const LightSampler& lights, int n, uint64_t seed) {
  Pcg32 rng(seed, 7);
  return estimate(n, [&]() {
    const std::optional<LightSample> s = lights.sample(Vec3(0.0f), Vec2(rng.uniform(), rng.uniform()));
    return s ? s->incident * (std::max(0.0f, s->wi.y) / s->pdf) : Rgb(0.0f);
  });
}

/// Form factor from the origin (normal +y) to the parallel rectangle [0, x] × [0, z] at height
/// h facing it, signed by the corner's quadrant so that rectangles add up by superposition.
double cornerFormFactor(double x, double z, double h) {
  const double a = std::abs(x) / h, b = std::abs(z) / h;
  const double f = (a / std::sqrt(1.0 + a * a) * std::atan(b / std::sqrt(1.0 + a * a)) +
                    b / std::sqrt(1.0 + b * b) * std::atan(a / std::sqrt(1.0 + b * b))) /
                   (2.0 * kPiD);
  return (x < 0.0) != (z < 0.0) ? -f : f;
}
double rectangleFormFactor(double x0, double x1, double z0, double z1, double h) {
  return cornerFormFactor(x1, z1, h) - cornerFormFactor(x0, z1, h) - cornerFormFactor(x1, z0, h) +
         cornerFormFactor(x0, z0, h);
}

// The mean over a triangle by the midpoint rule: exact for a texture whose edge runs along the
// sub-triangles' edges (the left half of the uv square white: ¼ of the triangle (0,0), (1,0),
// (1,1), ¾ of (0,0), (1,1), (0,1)), and exactly the texel for a constant one.
TEST(TexturedEmitters, MeanOverATriangle) {
  TextureSampling nearest;
  nearest.nearest = true;
  Mesh mesh;
  addPanel(mesh, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f, 0);
  const Scene halves = emitterScene(mesh, makeTexture(2, 1, [](int x, int) { return Rgb(x == 0 ? 1.0f : 0.0f); }, nearest),
                                    Rgb(1.0f));
  EXPECT_NEAR(meanEmissionModulation(halves, 0, 0).r, 0.25f, 1e-6f);  // uvs (0,0), (1,0), (1,1): ¼ left of u = ½
  EXPECT_NEAR(meanEmissionModulation(halves, 0, 1).r, 0.75f, 1e-6f);  // uvs (0,0), (1,1), (0,1): ¾
  const Scene constant = emitterScene(mesh, makeTexture(3, 3, [](int, int) { return Rgb(0.25f, 0.5f, 2.0f); }), Rgb(1.0f));
  EXPECT_EQ(meanEmissionModulation(constant, 0, 1), Rgb(0.25f, 0.5f, 2.0f));
  // Triangles are chosen ∝ their textured power: 0.25 against 0.75 of the same area.
  const LightSampler lights(halves);
  EXPECT_NEAR(lights.emitterAreaPdf(0, 0) / lights.emitterAreaPdf(0, 1), 0.25f / 0.75f, 1e-5f);
}

// A checker-textured panel above a point: nearest filtering makes Le constant on each texel's
// rectangle, so E = Σ_texels π·Le·F(rectangle) in closed form (corner form factors by
// superposition). The estimator is unbiased whatever the texture: its mean matches to within
// four standard errors, and the standard error is small enough for that to mean something.
TEST(TexturedEmitters, CheckerPanelIrradianceMatchesTheClosedForm) {
  const float x0 = -0.3f, x1 = 0.9f, z0 = -0.6f, z1 = 0.4f, h = 0.7f;
  const Rgb emission(2.0f, 3.0f, 4.0f);
  const Rgb dark(0.25f, 0.5f, 0.1f);
  TextureSampling nearest;
  nearest.nearest = true;
  const int side = 4;
  auto checker = [&](int x, int y) { return (x + y) % 2 == 0 ? Rgb(1.0f) : dark; };
  Mesh mesh;
  addPanel(mesh, x0, x1, z0, z1, h, 0);
  const Scene scene = emitterScene(mesh, makeTexture(side, side, checker, nearest), emission);
  // Texel (x, y) covers u ∈ [x, x+1)/4 and v ∈ (1 − (y+1)/4, 1 − y/4]: x ↦ world x, v ↦ world z.
  DVec3 expected(0.0);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const double ua = double(x) / side, ub = double(x + 1) / side;
      const double va = 1.0 - double(y + 1) / side, vb = 1.0 - double(y) / side;
      const double f = rectangleFormFactor(x0 + ua * (x1 - x0), x0 + ub * (x1 - x0), z0 + va * (z1 - z0),
                                           z0 + vb * (z1 - z0), h);
      expected += kPiD * f * DVec3(emission * checker(x, y));
    }
  const LightSampler lights(scene);
  const Estimate e = neeIrradiance(lights, 200000, 11);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(e.mean[c], expected[c], 4.0 * e.standardError[c]) << "channel " << c;
    EXPECT_LT(e.standardError[c], 5e-3 * expected[c]) << "channel " << c;
  }
}

// Next-event estimation (triangles ∝ textured power, points uniform within them, the texel at
// the point) against the plainest estimator — a uniform point on the panel's rectangle, its
// uv mapped by hand, Le·cos·cos/r²·A — for a bilinear, repeating texture under a uv transform:
// the two means agree to within four combined standard errors.
TEST(TexturedEmitters, NextEventEstimationAgreesWithUniformAreaSampling) {
  const float x0 = -0.8f, x1 = 0.5f, z0 = -0.2f, z1 = 1.1f, h = 0.6f;
  const Rgb emission(5.0f);
  Pcg32 texels(3, 9);
  const Texture texture = makeTexture(5, 3, [&](int, int) {
    const float r = texels.uniform();
    return r < 0.3f ? Rgb(0.0f) : Rgb(r, r * r, 1.0f - r);
  });
  TextureMapping mapping;
  mapping.linear = Mat2(Vec2(1.5f, 0.3f), Vec2(0.0f, 2.0f));
  mapping.offset = Vec2(0.2f, 0.1f);
  Mesh mesh;
  addPanel(mesh, x0, x1, z0, z1, h, 0);
  const Scene scene = emitterScene(mesh, texture, emission, mapping);
  const Texture& t = scene.textures[0];
  const LightSampler lights(scene);
  const Estimate nee = neeIrradiance(lights, 200000, 12);
  Pcg32 rng(13, 14);
  const double area = double(x1 - x0) * double(z1 - z0);
  const Estimate uniform = estimate(400000, [&]() {
    const Vec2 uv(rng.uniform(), rng.uniform());
    const Vec3 p(x0 + uv.x * (x1 - x0), h, z0 + uv.y * (z1 - z0));
    const float r2 = glm::dot(p, p);
    const float cosine = h / std::sqrt(r2);  // the same at the receiver and the emitter
    return emission * t.sample(mapping.linear * uv + mapping.offset) * float(cosine * cosine / r2 * area);
  });
  for (int c = 0; c < 3; ++c) {
    const double combined = std::sqrt(nee.standardError[c] * nee.standardError[c] +
                                      uniform.standardError[c] * uniform.standardError[c]);
    EXPECT_NEAR(nee.mean[c], uniform.mean[c], 4.0 * combined) << "channel " << c;
    EXPECT_LT(combined, 1e-2 * uniform.mean[c]) << "channel " << c;
  }
}

// A panel whose texture is black everywhere under it (the right half of a clamped texture whose
// left half is lit) gets probability 0: it is no light, samples never land on it, its
// densities are 0 — and the estimate is still the lit panel's closed form. A triangle whose
// midpoint reads all miss a texel that still reaches it through the bilinear filter keeps a
// small positive weight (meanEmissionModulation's floor).
TEST(TexturedEmitters, BlackFootprintsHaveProbabilityZero) {
  TextureSampling clampedNearest;
  clampedNearest.wrapU = clampedNearest.wrapV = TextureWrap::ClampToEdge;
  clampedNearest.nearest = true;
  auto leftHalf = [](int x, int) { return Rgb(x < 4 ? 1.0f : 0.0f); };
  Mesh mesh;
  addPanel(mesh, -0.5f, 0.5f, -0.5f, 0.5f, 1.0f, 0, 0.0f, 0.45f);  // lit: u < 0.5
  addPanel(mesh, 2.0f, 3.0f, -0.5f, 0.5f, 1.0f, 0, 0.75f, 1.0f);   // black: texels 6 and 7
  const Rgb emission(3.0f);
  const Scene scene = emitterScene(mesh, makeTexture(8, 2, leftHalf, clampedNearest), emission);
  const LightSampler lights(scene);
  EXPECT_EQ(lights.emissiveTriangleCount(), 2u);
  EXPECT_GT(lights.emitterAreaPdf(0, 0), 0.0f);
  EXPECT_EQ(lights.emitterAreaPdf(0, 2), 0.0f);
  EXPECT_EQ(lights.emitterAreaPdf(0, 3), 0.0f);
  EXPECT_EQ(lights.emitterPdf(0, 3, 1.0f, 1.0f), 0.0f);
  Pcg32 rng(21, 22);
  for (int i = 0; i < 2000; ++i) {
    const EmitterPoint p = lights.sampleEmitterPoint(Vec2(rng.uniform(), rng.uniform()));
    ASSERT_LT(p.point.x, 1.0f);
    ASSERT_GT(p.areaPdf, 0.0f);
  }
  const double expected = kPiD * 3.0 * rectangleFormFactor(-0.5, 0.5, -0.5, 0.5, 1.0);
  const Estimate e = neeIrradiance(lights, 100000, 23);
  EXPECT_NEAR(e.mean.r, expected, 4.0 * e.standardError.r);

  // Bilinear and clamped, one lit texel at the left edge: it reaches u < 1.5/16 = 0.09375.
  TextureSampling clamped;
  clamped.wrapU = clamped.wrapV = TextureWrap::ClampToEdge;
  Mesh slivers;
  addPanel(slivers, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f, 0, 0.09f, 0.5f);  // its left sliver sees the texel
  addPanel(slivers, 2.0f, 3.0f, 0.0f, 1.0f, 1.0f, 0, 0.2f, 0.5f);   // never
  const Scene edge = emitterScene(slivers, makeTexture(16, 1, [](int x, int) { return Rgb(x == 0 ? 1.0f : 0.0f); }, clamped),
                                  emission);
  EXPECT_EQ(meanEmissionModulation(edge, 0, 0), Rgb(1.0f / 16.0f));  // all 16 reads black: max / n²
  EXPECT_EQ(meanEmissionModulation(edge, 0, 2), Rgb(0.0f));
  EXPECT_GT(LightSampler(edge).emitterAreaPdf(0, 0), 0.0f);
}

}  // namespace
}  // namespace pl
