// Tests of the 16-neighbour light-field lookup.
#include "lightfield/lookup.h"

#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "core/rng.h"
#include "lightfield/paraboloid.h"
#include "lightfield/render_settings.h"
#include "support/quad_mesh.h"

namespace pl {
namespace {

// A light field with one chart of the given kind, frame rotated off the axes so that the
// frame arithmetic is exercised, and values from `field(i, j, a, b)`.
template <typename Field>
LightField makeLightField(ChartKind kind, uint32_t dirRes, Field field) {
  LightField lf;
  Material m;
  m.name = "test";
  m.bsdf = LambertBsdf{Rgb(0.5f, 0.25f, 1.0f)};
  m.emission = Rgb(0.1f, 0.2f, 0.3f);
  lf.scene.materials.push_back(m);
  Chart c;
  c.kind = kind;
  c.material = 0;
  c.origin = Vec3(1.0f, -2.0f, 0.5f);
  const Frame f = Frame::fromNormal(glm::normalize(Vec3(0.3f, 0.4f, 0.8f)));
  c.axisU = f.s;
  c.axisV = f.t;
  c.normal = f.n;
  c.tixelSize = 0.25f;
  c.resU = 5;
  c.resV = 4;
  c.dirRes = kind == ChartKind::Specular ? 0 : dirRes;
  lf.charts.push_back(c);
  lf.values.resize(c.tixelCount() * c.valuesPerTixel());
  for (uint32_t j = 0; j < c.resV; ++j)
    for (uint32_t i = 0; i < c.resU; ++i)
      for (uint32_t b = 0; b < c.dirRes; ++b)
        for (uint32_t a = 0; a < c.dirRes; ++a) lf.values[c.valueIndex(i, j, a, b)] = field(i, j, a, b);
  return lf;
}

Rgb linearField(float i, float j, float a, float b) {
  return Rgb(1.0f + 0.5f * i + 0.25f * j + 0.125f * a - 0.0625f * b, 2.0f - 0.1f * i + 0.3f * j + 0.2f * a + 0.05f * b,
             3.0f + i * 0.01f - j * 0.02f - a * 0.03f + b * 0.04f);
}

TEST(Lookup, GlossyInterpolationReproducesALinearFieldExactly) {
  const uint32_t R = 6;
  const LightField lf = makeLightField(ChartKind::Glossy, R, [](uint32_t i, uint32_t j, uint32_t a, uint32_t b) {
    return linearField(float(i), float(j), float(a), float(b));
  });
  const Chart& c = lf.charts[0];
  Pcg32 rng(1, 2);
  for (int n = 0; n < 2000; ++n) {
    // A point whose grid coordinates are strictly inside the tixel centres' range, and a
    // direction whose texel coordinates are inside the texel centres' range (and the disk).
    const float gu = rng.uniform() * (c.resU - 1), gv = rng.uniform() * (c.resV - 1);
    const Vec3 p = c.origin + (gu + 0.5f) * c.tixelSize * c.axisU + (gv + 0.5f) * c.tixelSize * c.axisV +
                   0.01f * c.normal;  // lookups ignore the offset along the normal
    Vec2 st(2.0f * rng.uniform() - 1.0f, 2.0f * rng.uniform() - 1.0f);
    st *= 0.7f;  // inside the disk and inside the texel-centre range of a 6-texel map
    const Vec3 w = chartWorldDirection(c, paraboloidToDirection(st));
    const Rgb got = exitantRadiance(lf, 0, p, w, Vec2(0.0f));
    const Rgb expected = linearField(gu, gv, paraboloidTexelCoordinate(st.x, R), paraboloidTexelCoordinate(st.y, R));
    // Bilinear interpolation is exact for linear data; float round-off in the frame and map
    // arithmetic (a few ulps of coordinates of size ~5) bounds the error by ~1e-4.
    EXPECT_NEAR(got.r, expected.r, 2e-4f);
    EXPECT_NEAR(got.g, expected.g, 2e-4f);
    EXPECT_NEAR(got.b, expected.b, 2e-4f);
  }
}

TEST(Lookup, HoldsEdgeValuesOutsideTheGrid) {
  const LightField lf = makeLightField(ChartKind::Glossy, 4, [](uint32_t i, uint32_t j, uint32_t a, uint32_t b) {
    return linearField(float(i), float(j), float(a), float(b));
  });
  const Chart& c = lf.charts[0];
  // Far outside the rectangle, beyond the last tixel centre in both u and v; looking along
  // the normal, which maps to (s, t) = (0, 0), between texels 1 and 2 of a 4-texel map.
  const Vec3 p = c.origin + 10.0f * c.axisU + 10.0f * c.axisV;
  const Rgb got = exitantRadiance(lf, 0, p, c.normal, Vec2(0.0f));
  const Rgb expected = linearField(float(c.resU - 1), float(c.resV - 1), 1.5f, 1.5f);
  EXPECT_NEAR(got.r, expected.r, 1e-4f);
  EXPECT_NEAR(got.g, expected.g, 1e-4f);
  EXPECT_NEAR(got.b, expected.b, 1e-4f);
}

TEST(Lookup, DiffuseIsEmissionPlusAlbedoTimesInterpolatedIrradianceOverPi) {
  const LightField lf = makeLightField(ChartKind::Diffuse, 1, [](uint32_t i, uint32_t j, uint32_t, uint32_t) {
    return linearField(float(i), float(j), 0.0f, 0.0f);
  });
  const Chart& c = lf.charts[0];
  const Material& m = lf.scene.materials[0];
  const Rgb albedo = std::get<LambertBsdf>(m.bsdf).albedo;
  const float gu = 2.3f, gv = 1.6f;
  const Vec3 p = c.origin + (gu + 0.5f) * c.tixelSize * c.axisU + (gv + 0.5f) * c.tixelSize * c.axisV;
  const Rgb front = exitantRadiance(lf, 0, p, glm::normalize(c.normal + 0.5f * c.axisU), Vec2(0.3f, 0.3f));
  const Rgb expected = m.emission + albedo * linearField(gu, gv, 0.0f, 0.0f) * kInvPi;
  EXPECT_NEAR(front.r, expected.r, 1e-5f);
  EXPECT_NEAR(front.g, expected.g, 1e-5f);
  EXPECT_NEAR(front.b, expected.b, 1e-5f);
  // From behind a one-sided chart (lightfield.h "Sides"): nothing reflected, and a one-sided
  // emitter does not emit.
  const Rgb back = exitantRadiance(lf, 0, p, -c.normal, Vec2(0.3f, 0.3f));
  EXPECT_EQ(back, Rgb(0.0f));
}

// The fast renderer's four-at-a-time diffuse lookup gives exactly (bit for bit) what one
// lookup at a time gives, for rays landing inside the grid, outside it on every side (held
// edges), in front of and behind the chart, on a one- and a two-sided emitter, and with an
// albedo texture sampled at uvs inside and outside [0, 1] (repeat) and at mip levels below 0,
// between levels, beyond the coarsest and NaN.
TEST(Lookup, FourAtATimeDiffuseLookupEqualsOneAtATimeBitForBit) {
  LightField lf = makeLightField(ChartKind::Diffuse, 1, [](uint32_t i, uint32_t j, uint32_t, uint32_t) {
    return linearField(float(i) * 1.37f, float(j) * 0.91f, 0.0f, 0.0f) * (1.0f + 0.1f * float((i * 7 + j * 3) % 5));
  });
  std::vector<Lanes4> padded;
  for (const Rgb& v : lf.values) padded.push_back(lanes4(v));
  const Chart& c = lf.charts[0];
  Pcg32 rng(21, 4);
  Texture texture;
  texture.path = "random-albedo";
  texture.image = Image(7, 5);
  for (Rgb& texel : texture.image.pixels) texel = Rgb(rng.uniform(), rng.uniform(), rng.uniform());
  texture.finish("lookup_test");
  lf.scene.textures.push_back(texture);
  int compared = 0;
  for (int variant = 0; variant < 4; ++variant) {
    lf.scene.materials[0].twoSidedEmission = variant == 1;
    lf.scene.materials[0].albedoTexture = variant >= 2 ? 0 : -1;
    if (variant == 3) {
      // Sun masks (lightfield.h): a directional light at 60° from the normal and random
      // masks, so that sunIrradianceLanes runs lane by lane too.
      lf.scene.lights.push_back(DirectionalLight{glm::normalize(-c.normal + 1.7f * c.axisU), Rgb(3.0f, 2.0f, 1.0f)});
      lf.sunMaskLightCount = 1;
      for (uint64_t g = 0; g < c.tixelCount(); ++g) lf.sunMasks.push_back(SunMask(rng.next() & 0xffffu));
    }
    const SunLights sun = sunLightsOf(lf);
    const ChartShading shading = chartShading(lf, 0, sun);
    ASSERT_EQ(shading.needsUv, variant >= 2);
    ASSERT_EQ(shading.sunMasks != nullptr, variant == 3);
    for (int group = 0; group < 500; ++group) {
      RaysSoA4 rays;
      Vec3 origin[4], direction[4];
      AlbedoPoint albedo[4];
      float t[4];
      for (int k = 0; k < 4; ++k) {
        albedo[k].uv = Vec2(6.0f * rng.uniform() - 3.0f, 6.0f * rng.uniform() - 3.0f);
        albedo[k].lod = group % 50 == 7 ? std::nanf("") : 6.0f * rng.uniform() - 1.0f;  // 7×5: levels 0…2
        // A target point from 1.5 tixels outside the grid to 1.5 beyond it, seen from either side.
        const float gu = -2.0f + (float(c.resU) + 3.0f) * rng.uniform(), gv = -2.0f + (float(c.resV) + 3.0f) * rng.uniform();
        const Vec3 target = c.origin + (gu + 0.5f) * c.tixelSize * c.axisU + (gv + 0.5f) * c.tixelSize * c.axisV;
        const float side = rng.uniform() < 0.3f ? -1.0f : 1.0f;
        origin[k] = target + side * (1.0f + rng.uniform()) * c.normal + (rng.uniform() - 0.5f) * c.axisU;
        direction[k] = glm::normalize(target - origin[k]);
        t[k] = glm::length(target - origin[k]);
        rays.ox[k] = origin[k].x, rays.oy[k] = origin[k].y, rays.oz[k] = origin[k].z;
        rays.dx[k] = direction[k].x, rays.dy[k] = direction[k].y, rays.dz[k] = direction[k].z;
        rays.t[k] = t[k];
      }
      F4 four[4];
      exitantRadianceDiffuse4(lf.scene, c, shading, padded.data(), rays, albedo, four);
      for (int k = 0; k < 4; ++k) {
        const Rgb one = f4Rgb(exitantRadianceLanes(lf.scene, c, shading, PaddedValues{padded.data()},
                                                   origin[k] + t[k] * direction[k], -direction[k], c.normal, c.normal, albedo[k]));
        const Rgb batch = f4Rgb(four[k]);
        for (int ch = 0; ch < 3; ++ch)
          ASSERT_EQ(std::bit_cast<uint32_t>(batch[ch]), std::bit_cast<uint32_t>(one[ch]))
              << "group " << group << " lookup " << k << " channel " << ch << ": " << batch[ch] << " vs " << one[ch];
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 8000);
}

// The texture LOD's log2 (albedoTextureLod): within 0.0078 of log2 over many octaves, exact at
// powers of two, monotonic, and −∞ / +∞ at the ends (levels 0 and the coarsest).
TEST(Lookup, ApproximateLog2IsCloseExactAtPowersOfTwoAndMonotonic) {
  float previous = -std::numeric_limits<float>::infinity();
  for (float x = 1e-6f; x < 1e6f; x *= 1.0007f) {
    const float got = approximateLog2(x);
    EXPECT_NEAR(got, std::log2(x), 0.0078f) << x;
    EXPECT_GE(got, previous) << x;
    previous = got;
  }
  for (int e = -20; e <= 20; ++e) EXPECT_EQ(approximateLog2(std::ldexp(1.0f, e)), float(e));
  EXPECT_EQ(approximateLog2(0.0f), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(approximateLog2(std::nanf("")), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(approximateLog2(std::numeric_limits<float>::infinity()), 128.0f);
}

TEST(Lookup, SpecularChartsStoreNothingAndReturnZero) {
  LightField lf = makeLightField(ChartKind::Specular, 0, [](uint32_t, uint32_t, uint32_t, uint32_t) { return Rgb(1.0f); });
  EXPECT_TRUE(lf.values.empty());
  EXPECT_EQ(exitantRadiance(lf, 0, lf.charts[0].origin, lf.charts[0].normal, Vec2(0.0f)), Rgb(0.0f));
}

TEST(FollowSpecular, SamplesAMirrorLikeLobeWithoutBias) {
  // A GGX metal too sharp for a map (bake/parameterisation.h isMirrorLike) is followed by one
  // lobe sample per ray: the mean weight over many rays is the lobe's directional albedo, and
  // the sampled directions gather around the mirror direction.
  Scene scene;
  Material metal;
  metal.name = "metal";
  const GgxBsdf ggx{Rgb(0.0f), Rgb(0.9f, 0.6f, 0.3f), 0.01f};
  metal.bsdf = ggx;
  scene.materials.push_back(metal);
  Mesh mesh;
  test_support::addQuad(mesh, Vec3(-1.0f, -1.0f, 0.0f), Vec3(1.0f, -1.0f, 0.0f), Vec3(1.0f, 1.0f, 0.0f), Vec3(-1.0f, 1.0f, 0.0f), 0);
  scene.meshes.push_back(mesh);
  const Vec3 wo = glm::normalize(Vec3(0.3f, 0.2f, 1.0f));  // towards the viewer
  const Vec3 mirror(-wo.x, -wo.y, wo.z);
  RayHit hit;
  hit.mesh = 0;
  hit.triangle = 0;
  hit.barycentrics = Vec2(0.3f, 0.2f);
  hit.t = 2.0f;
  const Vec3 p = positionAt(scene.meshes[0], 0, hit.barycentrics);
  Pcg32 rng(7, 1);
  constexpr int kRays = 20000;
  Rgb sum(0.0f);
  Vec3 meanDirection(0.0f);
  for (int i = 0; i < kRays; ++i) {
    // Rays that differ in their last bits: each its own hash, the same wo to 1e-4.
    const Vec3 d = -glm::normalize(wo + 1e-4f * Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
    const Ray ray{p - 2.0f * d, d, 0.0f, kInfinity};
    Rgb emitted, weight;
    Ray next;
    if (!followSpecular(scene, ray, hit, 0, 8, emitted, next, weight)) continue;
    EXPECT_GT(next.direction.z, 0.0f);
    sum += weight;
    meanDirection += next.direction;
  }
  const Rgb expected = albedo(ggx, wo);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(sum[k] / kRays, expected[k], 0.01f * expected[k]) << k;
  EXPECT_GT(glm::dot(glm::normalize(meanDirection), mirror), 0.9999f);
}

// The renderers' camera samples (render_settings.h pixelSample): a pixel's 16 film points lie
// one in each quarter × quarter of the pixel, and its 16 lens points one in each quarter ×
// quarter of the aperture; neighbouring pixels and another seed get other points.
TEST(PixelSample, StratifiedOverThePixelAndTheLens) {
  constexpr int kSide = 8, kSpp = 16;
  const ZSobolLayout layout(kSide, kSide, kSpp, 3), reseeded(kSide, kSide, kSpp, 4);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      std::vector<int> filmCells(kSpp, 0), lensCells(kSpp, 0);
      for (int k = 0; k < kSpp; ++k) {
        Vec2 film, lens, otherFilm, otherLens, neighbourFilm, neighbourLens;
        pixelSample(layout, x, y, k, film, lens);
        const Vec2 f = film - Vec2(float(x), float(y));
        ASSERT_TRUE(f.x >= 0.0f && f.x < 1.0f && f.y >= 0.0f && f.y < 1.0f) << f.x << " " << f.y;
        ASSERT_TRUE(lens.x >= 0.0f && lens.x < 1.0f && lens.y >= 0.0f && lens.y < 1.0f);
        ++filmCells[size_t(int(f.y * 4.0f) * 4 + int(f.x * 4.0f))];
        ++lensCells[size_t(int(lens.y * 4.0f) * 4 + int(lens.x * 4.0f))];
        pixelSample(reseeded, x, y, k, otherFilm, otherLens);
        EXPECT_NE(film, otherFilm);
        pixelSample(layout, (x + 1) % kSide, y, k, neighbourFilm, neighbourLens);
        EXPECT_NE(f, neighbourFilm - Vec2(float((x + 1) % kSide), float(y)));
      }
      for (int c = 0; c < kSpp; ++c) {
        EXPECT_EQ(filmCells[size_t(c)], 1) << "pixel " << x << "," << y << " film cell " << c;
        EXPECT_EQ(lensCells[size_t(c)], 1) << "pixel " << x << "," << y << " lens cell " << c;
      }
    }
}

// The split at a first hit (firstHitLobeSamples): sample 0 is the unsplit ray's numbers, and
// the kFirstHitLobeSamples samples are a rotated (0,3,2)-net — along each axis one in each
// 1/8 of [0, 1) measured from sample 0's value, and one in each of the 2^j × 2^(3−j) cells so
// measured — for the lobe's numbers and the light sample's alike.
TEST(FollowSpecular, SplitLobeAndLightSamplesAreStratified) {
  static_assert(kFirstHitLobeSamples == 8);
  Pcg32 rng(5, 3);
  for (int r = 0; r < 100; ++r) {
    const Ray ray{Vec3(rng.uniform(), rng.uniform(), rng.uniform()),
                  glm::normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, 1.0f)), 0.0f, kInfinity};
    for (auto numbers : {specularLobeU, nextEventU}) {
      const Vec2 first = numbers(ray, 0);
      EXPECT_EQ(first, numbers(ray, 0));
      for (int j = 0; j <= 3; ++j) {
        std::vector<int> cells(8, 0);
        for (uint32_t k = 0; k < kFirstHitLobeSamples; ++k) {
          const Vec2 u = numbers(ray, k);
          ASSERT_TRUE(u.x >= 0.0f && u.x < 1.0f && u.y >= 0.0f && u.y < 1.0f) << u.x << " " << u.y;
          // The offsets from sample 0, modulo 1 (exact: multiples of 2^-24).
          const float dx = u.x >= first.x ? u.x - first.x : u.x - first.x + 1.0f;
          const float dy = u.y >= first.y ? u.y - first.y : u.y - first.y + 1.0f;
          const int cx = int(dx * float(1 << j)), cy = int(dy * float(1 << (3 - j)));
          ++cells[size_t(cx * (1 << (3 - j)) + cy)];
        }
        for (int c = 0; c < 8; ++c) EXPECT_EQ(cells[size_t(c)], 1) << "cells 2^" << j << " x 2^" << 3 - j;
      }
    }
  }
}

TEST(Lookup, LinearTapClampsAndInterpolates) {
  EXPECT_EQ(linearTap(-0.5f, 4).i0, 0u);
  EXPECT_EQ(linearTap(-0.5f, 4).f, 0.0f);
  EXPECT_EQ(linearTap(3.5f, 4).i0, 3u);
  EXPECT_EQ(linearTap(3.5f, 4).i1, 3u);
  const LinearTap t = linearTap(1.25f, 4);
  EXPECT_EQ(t.i0, 1u);
  EXPECT_EQ(t.i1, 2u);
  EXPECT_FLOAT_EQ(t.f, 0.25f);
  EXPECT_EQ(linearTap(0.7f, 1).i1, 0u);  // a single sample: always that sample
  EXPECT_EQ(linearTap(std::nanf(""), 3).i0, 0u);
}

TEST(Lookup, BranchFreeLinearTapEqualsTheCaseList) {
  // linearTap is written without branches; it must give exactly (bitwise) the taps of the
  // plain case list of its comment, for every count and every kind of x: random values over
  // and beyond the range, exact integers, both clamping edges, ±0, ±∞ and NaN.
  auto reference = [](float x, uint32_t count) {
    LinearTap tap;
    if (!(x > 0.0f)) return tap;
    if (x >= float(count - 1)) {
      tap.i0 = tap.i1 = count - 1;
      return tap;
    }
    tap.i0 = uint32_t(x);
    tap.i1 = tap.i0 + 1;
    tap.f = x - float(tap.i0);
    return tap;
  };
  Pcg32 rng(11, 3);
  for (uint32_t count : {1u, 2u, 3u, 8u, 17u, 64u}) {
    std::vector<float> xs = {0.0f, -0.0f, 1.0f, float(count) - 1.0f, float(count), -1.0f, 1e30f, -1e30f,
                             std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                             std::nanf(""), std::nextafter(float(count) - 1.0f, 0.0f), std::nextafter(0.0f, 1.0f)};
    for (uint32_t k = 0; k < count; ++k) xs.push_back(float(k));
    for (int i = 0; i < 2000; ++i) xs.push_back((rng.uniform() * 1.4f - 0.2f) * float(count));
    for (float x : xs) {
      const LinearTap got = linearTap(x, count), want = reference(x, count);
      EXPECT_EQ(got.i0, want.i0) << "x = " << x << ", count = " << count;
      EXPECT_EQ(got.i1, want.i1) << "x = " << x << ", count = " << count;
      EXPECT_EQ(std::bit_cast<uint32_t>(got.f), std::bit_cast<uint32_t>(want.f)) << "x = " << x << ", count = " << count;
    }
  }
}

// A normal-mapped glossy chart is looked up where the flat chart reflects what the mapped
// normal reflects: mirror(d, n) = mirror(wo, n'). The unmapped normal leaves wo as it is, and a
// lookup that would fall behind the chart (or a viewer behind it) keeps wo.
TEST(NormalMappedLookup, ReflectsAboutTheMappedNormal) {
  Chart c;
  c.normal = Vec3(0.0f, 0.0f, 1.0f);
  const auto mirror = [](const Vec3& w, const Vec3& n) { return 2.0f * glm::dot(w, n) * n - w; };
  const Vec3 wo = glm::normalize(Vec3(0.3f, -0.2f, 1.0f));
  const Vec3 unmapped = normalMappedLookupDirection(c.normal, c.normal, wo);  // two mirrors: float rounding
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(unmapped[k], wo[k], 1e-6f);
  const Vec3 mapped = glm::normalize(Vec3(0.2f, 0.1f, 1.0f));
  const Vec3 d = normalMappedLookupDirection(c.normal, mapped, wo);
  EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
  const Vec3 want = mirror(wo, mapped), got = mirror(d, c.normal);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-5f);
  const Vec3 grazing = glm::normalize(Vec3(1.0f, 0.0f, 0.05f));
  EXPECT_EQ(normalMappedLookupDirection(c.normal, glm::normalize(Vec3(-0.5f, 0.0f, 1.0f)), grazing), grazing);
  const Vec3 behind(0.0f, 0.6f, -0.8f);
  EXPECT_EQ(normalMappedLookupDirection(c.normal, mapped, behind), behind);
}

}  // namespace
}  // namespace pl
