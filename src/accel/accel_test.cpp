// Embree ray casting checked against a brute-force Möller–Trumbore reference (double
// precision) on a random triangle soup and on the built-in Cornell box, plus the agreement of
// every query path (single rays, 16-wide packets, streams, occlusion) with each other.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "accel/accel.h"
#include "core/error.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/scene.h"

namespace pl {
namespace {

/// A soup of `count` random triangles (edges up to ~0.2) in the unit cube, split over three
/// meshes so that mesh indices are exercised too.
Scene makeTriangleSoup(int count, uint64_t seed) {
  Scene scene;
  scene.sourcePath = "random-soup";
  scene.materials.push_back({.name = "grey", .bsdf = LambertBsdf{Rgb(0.5f)}});
  Pcg32 rng(seed, 1);
  constexpr int kMeshes = 3;
  scene.meshes.resize(kMeshes);
  for (int i = 0; i < count; ++i) {
    Mesh& mesh = scene.meshes[i % kMeshes];
    const Vec3 centre(rng.uniform(), rng.uniform(), rng.uniform());
    const auto base = static_cast<uint32_t>(mesh.positions.size());
    for (int k = 0; k < 3; ++k)
      mesh.positions.push_back(centre + 0.1f * Vec3(2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1));
    mesh.triangles.push_back({base, base + 1, base + 2});
    mesh.materials.push_back(0);
  }
  for (int m = 0; m < kMeshes; ++m) scene.meshes[m].name = "soup" + std::to_string(m);
  scene.finalize();
  return scene;
}

/// Rays from a box around the scene towards random directions; every 4th ray aims at a
/// random point inside the scene so that a good share of rays hit something.
std::vector<Ray> makeRandomRays(const Scene& scene, int count, uint64_t seed) {
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const Vec3 extent = hi - lo;
  Pcg32 rng(seed, 2);
  std::vector<Ray> rays(count);
  for (int i = 0; i < count; ++i) {
    Ray& r = rays[i];
    r.origin = lo - 0.25f * extent + 1.5f * extent * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    if (i % 4 == 0) {
      const Vec3 target = lo + extent * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
      r.direction = glm::normalize(target - r.origin);
    } else {
      r.direction = sampleUniformSphere({rng.uniform(), rng.uniform()});
    }
  }
  return rays;
}

/// Möller–Trumbore in double precision. Returns (t, b1, b2) when the ray's line meets the
/// triangle with barycentrics ≥ −margin (a negative margin demands being inside by that
/// much) and t in (tMin, tMax).
struct ReferenceHit {
  double t, b1, b2;
};
std::optional<ReferenceHit> mollerTrumbore(const Ray& ray, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                                           double margin) {
  const DVec3 o(ray.origin), d(ray.direction), v0(p0), e1 = DVec3(p1) - v0, e2 = DVec3(p2) - v0;
  const DVec3 p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-300) return std::nullopt;
  const double inv = 1.0 / det;
  const DVec3 s = o - v0;
  const double b1 = glm::dot(s, p) * inv;
  const DVec3 q = glm::cross(s, e1);
  const double b2 = glm::dot(d, q) * inv;
  const double t = glm::dot(e2, q) * inv;
  if (b1 < -margin || b2 < -margin || b1 + b2 > 1.0 + margin) return std::nullopt;
  if (!(t > ray.tMin && t < ray.tMax)) return std::nullopt;
  return ReferenceHit{t, b1, b2};
}

// Embree's watertight float test and the double-precision reference disagree only for rays
// that pass within float rounding of a triangle edge. A triangle is "surely hit" when the
// ray meets it at least kEdgeMargin (barycentric units, ~1e3 float ulps) inside its edges:
// Embree must never miss such a hit. kRelativeT is the float precision of t (relative to
// the scale of the coordinates) allowed when ordering hits.
constexpr double kEdgeMargin = 1e-4;
constexpr double kRelativeT = 1e-5;
// A reported hit point may be this far (relative to its magnitude) from its triangle: the
// float ray equation o + t·d carries a few ulps (≈ 1e-7) of error, 1e-5 leaves room for the
// error of t from Embree's triangle test.
constexpr double kRelativeDistance = 1e-5;

/// Distance from point p to triangle (a, b, c) (closest point by Voronoi regions, Ericson,
/// "Real-Time Collision Detection" §5.1.5).
double distanceToTriangle(const DVec3& p, const DVec3& a, const DVec3& b, const DVec3& c) {
  const DVec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const DVec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + d1 / (d1 - d3) * ab));
  const DVec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + d2 / (d2 - d6) * ac));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return glm::length(p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)));
  const double denom = 1.0 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

struct Verdict {
  bool ok = true;
  std::string why;
};

/// Checks an Embree answer against the reference: a reported hit point must lie on its
/// triangle, and no triangle surely hit may be closer; a miss is only allowed when no
/// triangle is surely hit.
Verdict checkAgainstReference(const Scene& scene, const Ray& ray, const RayHit& hit) {
  double closestSure = kInfinity;
  for (const Mesh& mesh : scene.meshes)
    for (const UVec3& tri : mesh.triangles)
      if (const auto h = mollerTrumbore(ray, mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z],
                                        -kEdgeMargin))
        closestSure = std::min(closestSure, h->t);
  const double tScale = 1.0 + glm::length(DVec3(ray.origin)) + closestSure * (std::isfinite(closestSure) ? 1 : 0);
  if (!hit.hit()) {
    if (std::isfinite(closestSure)) return {false, fmt::format("missed a sure hit at t={}", closestSure)};
    return {};
  }
  if (hit.mesh >= scene.meshes.size() || hit.triangle >= scene.meshes[hit.mesh].triangles.size())
    return {false, "hit an index outside the scene"};
  const Mesh& mesh = scene.meshes[hit.mesh];
  const UVec3 tri = mesh.triangles[hit.triangle];
  const DVec3 p0(mesh.positions[tri.x]), p1(mesh.positions[tri.y]), p2(mesh.positions[tri.z]);
  if (!(hit.t > ray.tMin && hit.t < ray.tMax)) return {false, fmt::format("t={} outside the ray's range", hit.t)};
  // The reported point must lie on the reported triangle, and Embree's barycentrics must
  // name the same point. (Comparing with the plane intersection instead would fail for rays
  // grazing a triangle's plane, where t is ill-conditioned but the hit point is not.)
  const DVec3 point = DVec3(ray.origin) + double(hit.t) * DVec3(ray.direction);
  const double tolerance = kRelativeDistance * (1.0 + glm::length(point));
  const double off = distanceToTriangle(point, p0, p1, p2);
  if (off > tolerance) return {false, fmt::format("hit point is {} away from its triangle", off)};
  const double u = hit.barycentrics.x, v = hit.barycentrics.y;
  const DVec3 fromBarycentrics = (1.0 - u - v) * p0 + u * p1 + v * p2;
  if (glm::length(fromBarycentrics - point) > tolerance)
    return {false, fmt::format("barycentrics name a point {} away from the hit point",
                               glm::length(fromBarycentrics - point))};
  if (closestSure < hit.t - kRelativeT * tScale)
    return {false, fmt::format("a closer triangle at t={} (reported {})", closestSure, hit.t)};
  return {};
}

TEST(Accel, ClosestHitMatchesBruteForceOnATriangleSoup) {
  const Scene scene = makeTriangleSoup(3000, 1);
  const Accel accel(scene);
  const auto rays = makeRandomRays(scene, 2000, 2);
  int hits = 0;
  for (const Ray& ray : rays) {
    RayHit hit;
    const bool any = accel.intersect(ray, hit);
    EXPECT_EQ(any, hit.hit());
    hits += any;
    const Verdict v = checkAgainstReference(scene, ray, hit);
    EXPECT_TRUE(v.ok) << v.why;
  }
  // The test means something only if both hits and misses occur in numbers.
  EXPECT_GT(hits, 300);
  EXPECT_LT(hits, 1900);
}

TEST(Accel, ReferenceCheckRejectsWrongAnswers) {
  // The checker above must be able to fail: feed it a miss, a wrong t and a farther
  // triangle where Embree found the closest one.
  const Scene scene = makeTriangleSoup(3000, 1);
  const Accel accel(scene);
  int tested = 0;
  for (const Ray& ray : makeRandomRays(scene, 400, 2)) {
    RayHit hit;
    if (!accel.intersect(ray, hit)) continue;
    ++tested;
    EXPECT_FALSE(checkAgainstReference(scene, ray, RayHit{}).ok);
    // A wrong t moves the point off the triangle unless the ray grazes its plane.
    const Mesh& mesh = scene.meshes[hit.mesh];
    const UVec3 tri = mesh.triangles[hit.triangle];
    const Vec3 normal = glm::normalize(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                                  mesh.positions[tri.z] - mesh.positions[tri.x]));
    if (std::abs(glm::dot(normal, ray.direction)) > 0.2f) {
      RayHit wrongT = hit;
      wrongT.t += 0.01f;  // 0.01 along the ray: ≥ 2e-3 off the plane, 100× the tolerance
      EXPECT_FALSE(checkAgainstReference(scene, ray, wrongT).ok) << hit.t << " " << glm::dot(normal, ray.direction);
    }
    Ray pastFirst = ray;
    pastFirst.tMin = hit.t * 1.001f;
    RayHit farther;
    if (accel.intersect(pastFirst, farther) && farther.t > hit.t * 1.01f) {
      EXPECT_FALSE(checkAgainstReference(scene, ray, farther).ok);
    }
  }
  EXPECT_GT(tested, 50);
}

TEST(Accel, ClosestHitMatchesBruteForceInTheCornellBox) {
  const Scene scene = makeCornellBox();
  const Accel accel(scene);
  const auto rays = makeRandomRays(scene, 2000, 3);
  int hits = 0;
  for (const Ray& ray : rays) {
    RayHit hit;
    hits += accel.intersect(ray, hit);
    const Verdict v = checkAgainstReference(scene, ray, hit);
    EXPECT_TRUE(v.ok) << v.why;
  }
  // An accel that missed everything would pass the checks above whenever no ray surely hits;
  // the rays must exercise hits in numbers (1109 of 2000 measured).
  EXPECT_GT(hits, 500);
}

TEST(Accel, RespectsTMinAndTMax) {
  const Scene scene = makeTriangleSoup(3000, 4);
  const Accel accel(scene);
  const auto rays = makeRandomRays(scene, 3000, 5);
  int checked = 0;
  for (Ray ray : rays) {
    RayHit first;
    if (!accel.intersect(ray, first)) continue;
    ++checked;
    // tMax just before the first hit: nothing is hit or occluding.
    Ray shortRay = ray;
    shortRay.tMax = first.t * (1.0f - 1e-3f);
    RayHit none;
    EXPECT_FALSE(accel.intersect(shortRay, none));
    EXPECT_FALSE(accel.occluded(shortRay));
    // tMin just past the first hit: the answer is whatever lies beyond, per the reference.
    Ray beyond = ray;
    beyond.tMin = first.t * (1.0f + 1e-3f);
    RayHit next;
    accel.intersect(beyond, next);
    if (next.hit()) {
      EXPECT_GT(next.t, beyond.tMin);
    }
    const Verdict v = checkAgainstReference(scene, beyond, next);
    EXPECT_TRUE(v.ok) << v.why;
  }
  EXPECT_GT(checked, 500);
}

TEST(Accel, OcclusionAgreesWithIntersection) {
  const Scene scene = makeTriangleSoup(3000, 6);
  const Accel accel(scene);
  auto rays = makeRandomRays(scene, 4000, 7);
  Pcg32 rng(8, 8);
  for (Ray& r : rays) r.tMax = 0.2f + 1.5f * rng.uniform();  // finite segments, as shadow rays
  rays.resize(rays.size() - 5);  // not a multiple of the 16-ray packets
  std::vector<uint8_t> many(rays.size()), packets(rays.size());
  accel.occludedMany(rays, many);
  accel.occludedCoherent(rays, packets);
  int blocked = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    RayHit hit;
    const bool hits = accel.intersect(rays[i], hit);
    EXPECT_EQ(accel.occluded(rays[i]), hits) << "ray " << i;
    EXPECT_EQ(many[i] != 0, hits) << "ray " << i;
    EXPECT_EQ(packets[i] != 0, hits) << "ray " << i;
    blocked += hits;
  }
  EXPECT_GT(blocked, 400);
  EXPECT_LT(blocked, 3600);
}

/// Expects the same answers from two query paths; returns the number of hits (so callers can
/// require that the comparison was not made on misses alone).
int expectSameHits(const std::vector<RayHit>& a, const std::vector<RayHit>& b, const char* what) {
  EXPECT_EQ(a.size(), b.size());
  if (a.size() != b.size()) return 0;
  int hits = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].hit(), b[i].hit()) << what << " ray " << i;
    if (!a[i].hit() || !b[i].hit()) continue;
    ++hits;
    EXPECT_EQ(a[i].mesh, b[i].mesh) << what << " ray " << i;
    EXPECT_EQ(a[i].triangle, b[i].triangle) << what << " ray " << i;
    // Packet and single-ray kernels may round differently in the last bits.
    EXPECT_NEAR(a[i].t, b[i].t, 1e-5f * (1.0f + a[i].t)) << what << " ray " << i;
    EXPECT_NEAR(a[i].barycentrics.x, b[i].barycentrics.x, 1e-4f) << what << " ray " << i;
    EXPECT_NEAR(a[i].barycentrics.y, b[i].barycentrics.y, 1e-4f) << what << " ray " << i;
  }
  return hits;
}

TEST(Accel, PacketsAndStreamsAgreeWithSingleRays) {
  const Scene scene = makeTriangleSoup(3000, 9);
  const Accel accel(scene);
  // 16·250 + 7 rays: the last packet and the last stream chunk are partial.
  auto rays = makeRandomRays(scene, 4007, 10);
  Pcg32 rng(11, 11);
  for (size_t i = 0; i < rays.size(); i += 3) rays[i].tMax = 0.3f + rng.uniform();
  for (size_t i = 1; i < rays.size(); i += 5) rays[i].tMin = 0.2f * rng.uniform();
  std::vector<RayHit> single(rays.size()), packet(rays.size()), stream(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) accel.intersect(rays[i], single[i]);
  accel.intersectCoherent(rays, packet);
  accel.intersectIncoherent(rays, stream);
  // Agreement on misses alone would prove nothing: require hits (1798 of 4007 measured).
  EXPECT_GT(expectSameHits(single, packet, "packet"), 900);
  EXPECT_GT(expectSameHits(single, stream, "stream"), 900);
  // Coherent camera-like rays too: a fan from one point.
  std::vector<Ray> fan;
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 41; ++x)
      fan.push_back({Vec3(0.5f, 0.5f, -1.0f), glm::normalize(Vec3((x - 20) / 40.0f, (y - 18) / 36.0f, 1.0f))});
  std::vector<RayHit> fanSingle(fan.size()), fanPacket(fan.size());
  for (size_t i = 0; i < fan.size(); ++i) accel.intersect(fan[i], fanSingle[i]);
  accel.intersectCoherent(fan, fanPacket);
  EXPECT_GT(expectSameHits(fanSingle, fanPacket, "fan packet"), 600);  // 1288 of 1517 measured
}

TEST(Accel, WorksOnACopiedSceneWhoseBuffersLostTheirPadding) {
  // A copy of a finalized Scene has no spare vertex capacity; the Accel then pads a copy of
  // its own instead of sharing (Embree reads 16 bytes at the last vertex). Same answers.
  const Scene scene = makeTriangleSoup(500, 13);
  const Scene copy = scene;  // NOLINT(performance-unnecessary-copy-initialization): the point
  const Accel original(scene), fromCopy(copy);
  const auto rays = makeRandomRays(scene, 1000, 14);
  std::vector<RayHit> a(rays.size()), b(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    original.intersect(rays[i], a[i]);
    fromCopy.intersect(rays[i], b[i]);
  }
  EXPECT_GT(expectSameHits(a, b, "copied scene"), 130);  // 273 of 1000 measured
}

TEST(Accel, BoundsAndEmptySpans) {
  const Scene scene = makeTriangleSoup(200, 12);
  const Accel accel(scene);
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  EXPECT_EQ(accel.boundsMin(), lo);
  EXPECT_EQ(accel.boundsMax(), hi);
  accel.intersectCoherent({}, {});
  accel.intersectIncoherent({}, {});
  accel.occludedMany({}, {});
  accel.occludedCoherent({}, {});
  // A ray pointing away from everything misses.
  RayHit hit;
  EXPECT_FALSE(accel.intersect({hi + Vec3(1.0f), glm::normalize(Vec3(1, 1, 1))}, hit));
  EXPECT_FALSE(hit.hit());
}

// ---- alpha masks ---------------------------------------------------------------------------

/// A masked unit quad at z = 1 (uv = xy, random 4×4 coverage texture, cutoff `cutoff`) over
/// an opaque one at z = 0; the masked quad's mesh also holds an opaque triangle far away so
/// that the filter must tell materials apart within a mesh.
Scene makeMaskedQuads(float cutoff) {
  Scene scene;
  scene.sourcePath = "masked quads";
  Texture mask;
  mask.path = "random coverage";
  mask.decode = ImageDecode::Coverage;
  mask.image = Image(4, 4);
  Pcg32 rng(7, 3);
  for (Rgb& texel : mask.image.pixels) texel = Rgb(rng.uniform());
  scene.textures.push_back(mask);
  Material masked{.name = "masked", .bsdf = LambertBsdf{Rgb(0.5f)}};
  masked.alphaTexture = 0;
  masked.alphaCutoff = cutoff;
  scene.materials.push_back(masked);
  scene.materials.push_back({.name = "opaque", .bsdf = LambertBsdf{Rgb(0.5f)}});
  Mesh top;
  top.name = "masked";
  top.positions = {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {5, 5, 1}, {6, 5, 1}, {5, 6, 1}};
  top.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}, {1, 0}, {0, 1}};
  top.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}};
  top.materials = {0, 0, 1};
  Mesh bottom;
  bottom.name = "floor";
  bottom.positions = {{-1, -1, 0}, {2, -1, 0}, {2, 2, 0}, {-1, 2, 0}};
  bottom.triangles = {{0, 1, 2}, {0, 2, 3}};
  bottom.materials = {1, 1};
  scene.meshes = {top, bottom};
  scene.finalize();
  return scene;
}

// Straight down through the masked quad: where the bilinear coverage at uv is below the
// cutoff the ray reaches the floor (t = 2), elsewhere it stops on the quad (t = 1), and
// occlusion within t < 1.5 says the same. Every query path (single rays, packets, streams)
// goes through the same filter; three cutoffs move the boundary.
TEST(Accel, AlphaMaskCutsHitsAndOcclusionInEveryQueryPath) {
  for (const float cutoff : {0.25f, 0.5f, 0.75f}) {
    const Scene scene = makeMaskedQuads(cutoff);
    const Accel accel(scene);
    const Texture& mask = scene.textures[0];
    Pcg32 rng(11, 5);
    std::vector<Ray> rays, shadowRays;
    std::vector<bool> covered;
    while (rays.size() < 1000) {
      const Vec2 uv(rng.uniform(), rng.uniform());
      const float coverage = mask.sample(uv).r;
      if (std::abs(coverage - cutoff) < 1e-3f) continue;  // too close to call in float
      const Ray ray{Vec3(uv.x, uv.y, 2.0f), Vec3(0.0f, 0.0f, -1.0f), 0.0f, kInfinity};
      rays.push_back(ray);
      shadowRays.push_back(Ray{ray.origin, ray.direction, 0.0f, 1.5f});
      covered.push_back(coverage >= cutoff);
    }
    const size_t holes = size_t(std::count(covered.begin(), covered.end(), false));
    ASSERT_GT(holes, 20u) << "cutoff " << cutoff;  // the test must see both cases
    ASSERT_LT(holes, 980u) << "cutoff " << cutoff;

    std::vector<RayHit> coherent(rays.size()), incoherent(rays.size());
    accel.intersectCoherent(rays, coherent);
    accel.intersectIncoherent(rays, incoherent);
    std::vector<uint8_t> occludedMany(rays.size()), occludedCoherent(rays.size());
    accel.occludedMany(shadowRays, occludedMany);
    accel.occludedCoherent(shadowRays, occludedCoherent);
    for (size_t i = 0; i < rays.size(); ++i) {
      RayHit single;
      ASSERT_TRUE(accel.intersect(rays[i], single));
      EXPECT_EQ(single.mesh, covered[i] ? 0u : 1u) << "cutoff " << cutoff << " ray " << i;
      EXPECT_NEAR(single.t, covered[i] ? 1.0f : 2.0f, 1e-5f);
      for (const RayHit* other : {&coherent[i], &incoherent[i]}) {
        EXPECT_EQ(other->mesh, single.mesh) << "cutoff " << cutoff << " ray " << i;
        EXPECT_EQ(other->triangle, single.triangle);
        EXPECT_EQ(other->t, single.t);
      }
      EXPECT_EQ(accel.occluded(shadowRays[i]), bool(covered[i])) << "cutoff " << cutoff << " ray " << i;
      EXPECT_EQ(occludedMany[i], covered[i] ? 1 : 0);
      EXPECT_EQ(occludedCoherent[i], covered[i] ? 1 : 0);
    }
  }
}

// alphaFactor alone (glTF baseColorFactor.a under alphaMode MASK, no texture) below the
// cutoff removes the material's surfaces entirely; at or above it they are opaque.
TEST(Accel, AlphaFactorWithoutTextureRemovesOrKeepsTheWholeMaterial) {
  for (const float factor : {0.2f, 0.6f}) {
    Scene scene = makeMaskedQuads(0.5f);
    scene.materials[0].alphaTexture = -1;
    scene.materials[0].alphaFactor = factor;
    const Accel accel(scene);
    RayHit hit;
    ASSERT_TRUE(accel.intersect(Ray{Vec3(0.3f, 0.6f, 2.0f), Vec3(0, 0, -1), 0.0f, kInfinity}, hit));
    EXPECT_EQ(hit.mesh, factor >= 0.5f ? 0u : 1u) << "alpha " << factor;
  }
}

// Vertex alphas (glTF COLOR_0's alpha) alone cut the quad where their interpolation is below
// the cutoff: alpha = y here, so rays at y < 0.5 reach the floor.
TEST(Accel, VertexAlphaCutsWhereItsInterpolationIsBelowTheCutoff) {
  Scene scene = makeMaskedQuads(0.5f);
  scene.materials[0].alphaTexture = -1;
  scene.meshes[0].alphas = {0.0f, 0.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
  markVertexColoredMaterials(scene);
  ASSERT_TRUE(scene.materials[0].isMasked());
  const Accel accel(scene);
  for (const float y : {0.1f, 0.4f, 0.6f, 0.9f}) {
    RayHit hit;
    ASSERT_TRUE(accel.intersect(Ray{Vec3(0.45f, y, 2.0f), Vec3(0, 0, -1), 0.0f, kInfinity}, hit));
    EXPECT_EQ(hit.mesh, y >= 0.5f ? 0u : 1u) << "y " << y;
  }
}

}  // namespace
}  // namespace pl
