// Chart kinds, tixel sizes and the per-tixel work of the parameterisation (fillTixels: gather
// points, coverage, albedo, sun masks); the charts themselves are built in charts.cpp.
#include "bake/parameterisation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <type_traits>

#include "core/error.h"
#include "core/hash.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "light/emitters.h"
#include "light/lights.h"
#include "lightfield/lookup.h"
#include "plf/plt_file.h"

namespace pl {

namespace {

/// θh, the half width at half maximum of the half-vector lobe (bsdf.h lobeHalfWidth). The
/// reflected lobe is about twice as wide as the half-vector lobe, so its full width at half
/// maximum is ≈ 4θh (radians).
float reflectedLobeWidth(const Bsdf& bsdf) { return std::max(4.0f * lobeHalfWidth(bsdf), 1e-4f); }

}  // namespace

uint32_t lobeMapResolution(float lobeWidth) {
  // Near the map centre s = tan(θ/2), so a texel 2/R wide in s spans ≈ 4/R radians; four
  // texels across the lobe's FWHM needs R ≈ 16 / FWHM. (Two are not enough: the directional
  // albedo of a normalised lobe already falls by ~8 % within 20° of the normal, and bilinear
  // interpolation between texels 20° apart misses that.)
  const float wanted = std::ceil(16.0f / std::max(lobeWidth, 1e-4f));
  return uint32_t(std::clamp(wanted, 2.0f, 65536.0f));
}

bool isMirrorLike(const Bsdf& bsdf, const BakeSettings& settings) {
  // Only a model that is all lobe: a diffuse part would need a stored irradiance beside the
  // traced lobe, and rough glass is a glossy chart on both sides.
  if (isDelta(bsdf) || isDiffuse(bsdf) || hasTransmission(bsdf) || !isBlack(diffuseAlbedo(bsdf))) return false;
  // Narrower than half a texel of the largest map the preset allows (a texel spans ≈ 4/R
  // radians): such a map would hold the lobe's reflection as the bilinear tent of texels two
  // or more lobe widths apart, the reflection of a lamp a smear around a wrong core, while
  // the traced lobe, its emitters sampled at each hit (lookup.h MirrorLikeLights), adds
  // little noise.
  const uint32_t cap = std::max<uint32_t>(2, settings.glossyDirRes);
  return lobeMapResolution(reflectedLobeWidth(bsdf)) > kMirrorLikeTexels * cap;
}

ChartKind chartKindOf(const Bsdf& bsdf, const BakeSettings& settings) {
  // Mirrors and smooth glass are followed through (followSpecular), as are lobes too narrow
  // for the preset's maps (isMirrorLike); rough glass stores its exitant radiance on both
  // sides like a glossy chart (isRoughGlassChart).
  if (isDelta(bsdf) || isMirrorLike(bsdf, settings)) return ChartKind::Specular;
  if (isDiffuse(bsdf)) return ChartKind::Diffuse;
  return ChartKind::Glossy;
}

bool mayGrowCurvedCharts(const Material& material, const BakeSettings& settings) {
  if (material.isEmissive()) return false;
  switch (chartKindOf(material.bsdf, settings)) {
    case ChartKind::Diffuse: return true;
    case ChartKind::Glossy: return !hasTransmission(material.bsdf);  // not rough glass
    case ChartKind::Specular: return false;
  }
  return false;
}

uint32_t directionalResolution(const Bsdf& bsdf, const BakeSettings& settings) {
  switch (chartKindOf(bsdf, settings)) {
    case ChartKind::Diffuse: return 1;
    case ChartKind::Specular: return 0;
    case ChartKind::Glossy: break;
  }
  const uint32_t cap = std::max<uint32_t>(2, settings.glossyDirRes);
  const uint32_t wanted = lobeMapResolution(reflectedLobeWidth(bsdf));
  return std::min(wanted, isStrongNarrowLobe(bsdf, settings) ? kStrongNarrowLobeCapFactor * cap : cap);
}

uint32_t chartDirectionalResolution(const Scene& scene, const Chart& c, const BakeSettings& settings) {
  const Bsdf& bsdf = scene.materials[c.material].bsdf;
  const uint32_t res = directionalResolution(bsdf, settings);
  if (c.kind != ChartKind::Glossy || !perTixelLobeWidth(scene, c)) return res;
  const uint32_t cap = std::max<uint32_t>(2, settings.glossyDirRes);
  const float finest = lobeAlphaRange(scene, scene.materials[c.material]).first;
  return std::max(res, std::min(cap, lobeMapResolution(reflectedLobeWidth(withGgxLobeAlpha(bsdf, finest)))));
}

float ggxLobeAlpha(const Bsdf& bsdf) {
  if (const auto* ggx = std::get_if<GgxBsdf>(&bsdf)) return ggx->alpha;
  if (const auto* pbr = std::get_if<GltfPbrBsdf>(&bsdf)) return pbr->alpha;
  return 0.0f;
}

Bsdf withGgxLobeAlpha(const Bsdf& bsdf, float alpha) {
  Bsdf b = bsdf;
  if (auto* ggx = std::get_if<GgxBsdf>(&b)) ggx->alpha = alpha;
  if (auto* pbr = std::get_if<GltfPbrBsdf>(&b)) pbr->alpha = alpha;
  return b;
}

std::pair<float, float> lobeAlphaRange(const Scene& scene, const Material& material) {
  const MetallicRoughnessMap& mr = material.metallicRoughness;
  if (mr.texture < 0) return {ggxLobeAlpha(material.bsdf), ggxLobeAlpha(material.bsdf)};
  float lo = kInfinity, hi = 0.0f;
  for (const Rgb& t : scene.textures[size_t(mr.texture)].image.pixels) {
    const float alpha = ggxAlphaFromRoughness(std::clamp(mr.roughness * t.g, 0.0f, 1.0f));
    lo = std::min(lo, alpha);
    hi = std::max(hi, alpha);
  }
  return lo <= hi ? std::pair{lo, hi} : std::pair{ggxLobeAlpha(material.bsdf), ggxLobeAlpha(material.bsdf)};
}

std::vector<float> lobeAlphaBins(const Scene& scene, const Material& material, uint32_t dirRes) {
  // One texel of an R-texel map spans ≈ 4/R radians (lobeMapResolution): a lobe of that FWHM
  // has θh = 1/R, and GGX θh = atan(α·√(√2 − 1)) (bsdf.h lobeHalfWidth).
  const float texelAlpha = std::tan(1.0f / float(std::max<uint32_t>(dirRes, 2))) / std::sqrt(std::sqrt(2.0f) - 1.0f);
  auto [lo, hi] = lobeAlphaRange(scene, material);
  lo = std::max(lo, texelAlpha);
  hi = std::max(hi, lo);
  const uint32_t count = std::min<uint32_t>(
      kMaxLobeBins, 1 + uint32_t(std::ceil(std::log(hi / lo) / std::log(kLobeBinRatio) - 1e-4f)));
  std::vector<float> bins(count, lo);
  for (uint32_t i = 1; i < count; ++i) bins[i] = lo * std::pow(hi / lo, float(i) / float(count - 1));
  return bins;
}

uint32_t nearestLobeBin(const std::vector<float>& bins, float alpha) {
  // The first bin whose geometric midpoint with the next is above α.
  uint32_t i = 0;
  while (i + 1 < bins.size() && alpha * alpha > bins[i] * bins[i + 1]) ++i;
  return i;
}

bool isStrongNarrowLobe(const Bsdf& bsdf, const BakeSettings& settings) {
  if (isDelta(bsdf) || isDiffuse(bsdf) || hasTransmission(bsdf)) return false;
  // Narrower than two thirds of a texel at the cap (a texel spans ≈ 4/R radians, so the lobe
  // asks for more than 6 × the cap): the map keeps the lobe's reflection of a lamp as the
  // bilinear tent of texels wider than the lobe, its core too dark and its halo too bright.
  const uint32_t cap = std::max<uint32_t>(2, settings.glossyDirRes);
  if (lobeMapResolution(reflectedLobeWidth(bsdf)) <= kStrongNarrowLobeTexels * cap) return false;
  // And strong: what that smear costs grows with the lobe's share of the reflected light. The
  // lobe alone (the model without its diffuse part), at normal incidence, luminance.
  return luminance(albedo(withDiffuseAlbedo(bsdf, Rgb(0.0f)), Vec3(0.0f, 0.0f, 1.0f))) >= kStrongLobeAlbedo;
}

float sceneScale(const Scene& scene, const Accel& accel) {
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const float extent = maxComponent(hi - lo);
  if (!(extent > 0.0f) || !std::isfinite(extent)) fail("{}: scene has no extent to parameterise", scene.sourcePath);
  // Cumulative triangle areas for area-uniform surface points.
  std::vector<std::pair<uint32_t, uint32_t>> triangles;
  std::vector<double> cumulative;
  double total = 0.0;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const UVec3 tri = mesh.triangles[t];
      const DVec3 p0 = mesh.positions[tri[0]], p1 = mesh.positions[tri[1]], p2 = mesh.positions[tri[2]];
      const double area = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
      if (!(area > 0.0)) continue;
      total += area;
      triangles.emplace_back(m, t);
      cumulative.push_back(total);
    }
  }
  if (triangles.empty()) return extent;
  // Free paths from area-uniform points, one side chosen at random, cosine-weighted.
  std::vector<Ray> rays(kSceneScaleRays);
  Pcg32 rng(0x5343414c45ULL, 1);
  for (Ray& ray : rays) {
    const double target = double(rng.uniform()) * total;
    const size_t k = std::min(size_t(std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin()),
                              triangles.size() - 1);
    const Vec2 b = sampleUniformTriangle(Vec2(rng.uniform(), rng.uniform()));
    const SurfaceHit s = surfaceAt(scene, triangles[k].first, triangles[k].second, b);
    const Vec3 n = rng.uniform() < 0.5f ? s.geometricNormal : -s.geometricNormal;
    const Vec3 d = Frame::fromNormal(n).toWorld(sampleCosineHemisphere(Vec2(rng.uniform(), rng.uniform())));
    ray = Ray{offsetRayOrigin(s.position, s.geometricNormal, d), d, 0.0f, kInfinity};
  }
  std::vector<RayHit> hits(rays.size());
  accel.intersectIncoherent(rays, hits);
  double sum = 0.0;
  uint32_t count = 0;
  for (const RayHit& h : hits)
    if (h.hit()) {
      sum += h.t;
      ++count;
    }
  // Too few rays stay in the scene (a single sheet, an open terrain): the extent is the scale.
  if (count < kSceneScaleRays / 16) return extent;
  return std::min(extent, float(1.5 * sum / count));
}

float baseTixelSize(const BakeSettings& settings, float scale) {
  if (settings.tixelsPerUnit > 0.0f) return 1.0f / settings.tixelsPerUnit;
  return scale / std::max(1.0f, settings.tixelsAcrossScene);
}

float chartTixelSize(const Scene& scene, uint32_t material, ChartKind kind, float baseSize) {
  const float density = scene.materials[material].tixelDensity * (kind == ChartKind::Glossy ? kGlossyTixelDensity : 1.0f);
  return baseSize / density;
}

namespace {

// A chart's triangles projected to its grid: coordinates in tixel units, so tixel (i, j)
// covers [i, i+1] × [j, j+1].
struct ChartRaster {
  struct Tri2 {
    Vec2 p[3];
    uint32_t mesh, triangle;
  };
  std::vector<Tri2> tris;
  std::vector<std::vector<uint32_t>> bins;  ///< per tixel: triangles overlapping its square (bbox test)
};

// Barycentrics (b0, b1, b2) of q in 2D triangle t; inside when all are ≥ −eps.
std::array<float, 3> barycentric2(const ChartRaster::Tri2& t, Vec2 q) {
  const Vec2 e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0], d = q - t.p[0];
  const float det = e1.x * e2.y - e1.y * e2.x;
  if (det == 0.0f) return {-1.0f, -1.0f, -1.0f};
  const float b1 = (d.x * e2.y - d.y * e2.x) / det;
  const float b2 = (e1.x * d.y - e1.y * d.x) / det;
  return {1.0f - b1 - b2, b1, b2};
}
bool insideBary(const std::array<float, 3>& b) {
  constexpr float kEps = 1e-6f;  // points on shared edges belong to both triangles
  return b[0] >= -kEps && b[1] >= -kEps && b[2] >= -kEps;
}

Vec2 closestOnSegment(Vec2 a, Vec2 b, Vec2 q) {
  const Vec2 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(q - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return a + t * ab;
}

ChartRaster rasteriseChart(const Scene& scene, const Chart& c, const std::vector<std::pair<uint32_t, uint32_t>>& tris) {
  ChartRaster r;
  r.bins.resize(c.tixelCount());
  const float inv = 1.0f / c.tixelSize;
  for (const auto& [m, t] : tris) {
    const Mesh& mesh = scene.meshes[m];
    ChartRaster::Tri2 t2;
    t2.mesh = m;
    t2.triangle = t;
    for (int k = 0; k < 3; ++k) {
      const Vec3 d = mesh.positions[mesh.triangles[t][k]] - c.origin;
      t2.p[k] = Vec2(glm::dot(d, c.axisU) * inv, glm::dot(d, c.axisV) * inv);
    }
    const uint32_t index = uint32_t(r.tris.size());
    r.tris.push_back(t2);
    const Vec2 lo = glm::min(t2.p[0], glm::min(t2.p[1], t2.p[2]));
    const Vec2 hi = glm::max(t2.p[0], glm::max(t2.p[1], t2.p[2]));
    const int i0 = std::clamp(int(std::floor(lo.x)), 0, int(c.resU) - 1), i1 = std::clamp(int(std::floor(hi.x)), 0, int(c.resU) - 1);
    const int j0 = std::clamp(int(std::floor(lo.y)), 0, int(c.resV) - 1), j1 = std::clamp(int(std::floor(hi.y)), 0, int(c.resV) - 1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) r.bins[size_t(j) * c.resU + i].push_back(index);
  }
  return r;
}

// 4-neighbour breadth-first fill over a chart's tixel grid: `from` holds k at seed tixels and
// UINT32_MAX elsewhere; afterwards every tixel reachable from a seed holds the seed nearest
// to it in breadth-first order. Returns false when there is no seed.
bool fillFromNearestSeed(const Chart& c, std::vector<uint32_t>& from) {
  std::deque<uint32_t> queue;
  for (uint32_t k = 0; k < from.size(); ++k)
    if (from[k] != UINT32_MAX) queue.push_back(k);
  if (queue.empty()) return false;
  while (!queue.empty()) {
    const uint32_t k = queue.front();
    queue.pop_front();
    const uint32_t i = k % c.resU, j = k / c.resU;
    const uint32_t nb[4] = {i > 0 ? k - 1 : UINT32_MAX, i + 1 < c.resU ? k + 1 : UINT32_MAX,
                            j > 0 ? k - c.resU : UINT32_MAX, j + 1 < c.resV ? k + c.resU : UINT32_MAX};
    for (uint32_t q : nb)
      if (q != UINT32_MAX && from[q] == UINT32_MAX) {
        from[q] = from[k];
        queue.push_back(q);
      }
  }
  return true;
}

// For each tixel, the nearest tixel (4-neighbour BFS distance) whose bin is non-empty.
std::vector<uint32_t> nearestNonEmptyBin(const Chart& c, const ChartRaster& r) {
  std::vector<uint32_t> nearest(c.tixelCount(), UINT32_MAX);
  for (uint32_t k = 0; k < nearest.size(); ++k)
    if (!r.bins[k].empty()) nearest[k] = k;
  fillFromNearestSeed(c, nearest);
  return nearest;
}

// Point on the real (3D) triangle at 2D barycentrics b.
Vec3 pointOnTriangle(const Scene& scene, const ChartRaster::Tri2& t, const std::array<float, 3>& b) {
  const Mesh& mesh = scene.meshes[t.mesh];
  const UVec3 tri = mesh.triangles[t.triangle];
  return b[0] * mesh.positions[tri[0]] + b[1] * mesh.positions[tri[1]] + b[2] * mesh.positions[tri[2]];
}

// Sub-samples per tixel side for coverage and footprint-average albedo.
constexpr int kFootprintSamples = 4;

struct FootprintSample {
  bool inside = false;
  uint32_t tri = 0;
  std::array<float, 3> bary{};
};

FootprintSample locate(const ChartRaster& r, uint32_t bin, Vec2 q) {
  FootprintSample s;
  for (uint32_t t : r.bins[bin]) {
    const auto b = barycentric2(r.tris[t], q);
    if (insideBary(b)) {
      s.inside = true;
      s.tri = t;
      s.bary = b;
      return s;
    }
  }
  return s;
}

// A candidate gather point x on a chart (frame f: unit normal n, tangents u, v) is buried
// when it lies inside other geometry — the floor under a baseboard or a block standing on it,
// the part of a wall behind a crossing wall: at least kBuriedMinHits of its kBuriedProbes
// probe rays hit the back side of a surface. The probes leave the front hemisphere at 8
// azimuths, 30° above the tangent plane, plus one along the normal, with no length limit:
// from inside a closed occluder every probe meets its inside, while a point in the open sees
// front sides; a majority is asked for so that a few one-sided sheets wound the other way
// (banners, leaves) do not bury the floor under them. Glass is not counted. Known limit: an
// opaque one-sided sheet facing away from the point and covering most of the probes (a single-
// quad roof whose normal points up, seen from the floor below) still buries it.
constexpr int kBuriedProbes = 9;
constexpr int kBuriedMinHits = 5;

bool buried(const Scene& scene, const Accel& accel, const TixelFrame& f, const Vec3& x) {
  int backHits = 0;
  for (int k = 0; k < kBuriedProbes; ++k) {
    Vec3 d = f.n;
    if (k > 0) {
      const float phi = 2.0f * kPi * float(k - 1) / float(kBuriedProbes - 1);
      d = 0.8660254f * (std::cos(phi) * f.u + std::sin(phi) * f.v) + 0.5f * f.n;
    }
    const Ray ray{offsetRayOrigin(x, f.n, d), d, 0.0f, kInfinity};
    RayHit hit;
    if (!accel.intersect(ray, hit)) continue;
    const Mesh& mesh = scene.meshes[hit.mesh];
    // Glass buries nothing: light passes through it, and a window or a glass table top seen
    // from below is the back of an open sheet, not the inside of a solid.
    if (hasTransmission(scene.materials[mesh.materials[hit.triangle]].bsdf)) continue;
    const UVec3 tri = mesh.triangles[hit.triangle];
    const Vec3 n = glm::cross(mesh.positions[tri[1]] - mesh.positions[tri[0]], mesh.positions[tri[2]] - mesh.positions[tri[0]]);
    if (glm::dot(n, d) > 0.0f) ++backHits;
    if (backHits >= kBuriedMinHits) return true;
  }
  return false;
}

/// The sun masks of tixel (i, j) (bin `bin` of chart raster r) for the lights `lights`
/// (lightfield.h "Sun masks"). Each footprint sub-sample inside the polygon casts one ray
/// towards each light from its point on the surface (lifted off it along its normal): lit when
/// it escapes, shadowed when it meets anything (either side of a surface, as the path
/// tracer's shadow rays) or faces away from the light. A shadowed sub-sample of a planar chart
/// that a wall separates from the tixel's gather point (x, normal n: unburied by construction)
/// is buried — the floor under a wall or a column's base, which nobody sees — and undecided:
/// its bit, like those of sub-samples outside the polygon, is copied from the nearest decided
/// sub-sample, so that the masks do not darken the visible surface next to a contact. A tixel
/// with none decided takes, for all bits, whether the light reaches its gather point. The 16
/// rays of a light leave neighbouring points in one direction: one coherent packet.
SunMaskSlots tixelSunMasks(const Scene& scene, const Accel& accel, const Chart& c, const ChartRaster& r, uint32_t bin,
                           uint32_t i, uint32_t j, const Vec3& x, const Vec3& n, const std::vector<uint32_t>& lights) {
  constexpr int kSamples = kSunMaskSide * kSunMaskSide;
  std::array<Vec3, kSamples> point, normal;
  std::array<bool, kSamples> inside{};
  for (int b = 0; b < kSunMaskSide; ++b)
    for (int a = 0; a < kSunMaskSide; ++a) {
      const int k = b * kSunMaskSide + a;
      const Vec2 q(float(i) + (a + 0.5f) / kSunMaskSide, float(j) + (b + 0.5f) / kSunMaskSide);
      const FootprintSample s = locate(r, bin, q);
      if (!s.inside) continue;
      inside[size_t(k)] = true;
      point[size_t(k)] = pointOnTriangle(scene, r.tris[s.tri], s.bary);
      const ChartRaster::Tri2& t = r.tris[s.tri];
      normal[size_t(k)] = chartShadingNormalAt(c, scene.meshes[t.mesh], t.triangle, Vec2(s.bary[1], s.bary[2]));
    }
  SunMaskSlots masks;
  masks.fill(SunMask(0xffffu));
  std::array<Ray, kSamples> rays;
  std::array<uint8_t, kSamples> blocked;
  for (size_t slot = 0; slot < lights.size(); ++slot) {
    const Vec3 wi = parallelLight(scene.lights[lights[slot]])->towardsLight;  // a sun-masked light: parallel
    // 1 lit, 0 shadowed, −1 undecided.
    std::array<int, kSamples> state;
    state.fill(-1);
    size_t count = 0;
    std::array<int, kSamples> rayOf;
    rayOf.fill(-1);
    for (int k = 0; k < kSamples; ++k) {
      if (!inside[size_t(k)]) continue;
      if (!(glm::dot(normal[size_t(k)], wi) > 0.0f)) {
        state[size_t(k)] = 0;  // faces away: no direct light from it on this side
        continue;
      }
      rays[count] = Ray{offsetRayOrigin(point[size_t(k)], normal[size_t(k)], wi), wi, 0.0f, kInfinity};
      rayOf[size_t(k)] = int(count++);
    }
    accel.occludedCoherent(std::span<const Ray>(rays.data(), count), std::span<uint8_t>(blocked.data(), count));
    for (int k = 0; k < kSamples; ++k) {
      if (rayOf[size_t(k)] < 0) continue;
      if (!blocked[size_t(rayOf[size_t(k)])]) {
        state[size_t(k)] = 1;
        continue;
      }
      // Shadowed — unless the sub-sample lies beyond a wall from the gather point: under
      // or behind something standing on the surface, where no viewer looks (its ray starts
      // inside the occluder). On a planar chart the segment between the two points, lifted
      // off the surface, then meets that wall; on a curved one it may cut through the
      // surface itself, so there every hit counts.
      state[size_t(k)] = 0;
      if (c.curved) continue;
      const Vec3 from = offsetRayOrigin(x, n, n), to = offsetRayOrigin(point[size_t(k)], n, n);
      const float length = glm::length(to - from);
      if (length > 0.0f && accel.occluded(Ray{from, (to - from) / length, 0.0f, length})) state[size_t(k)] = -1;
    }
    // Undecided bits from the nearest decided sub-sample (squared distance in sub-samples; ties
    // to the lower index), or all from the gather point.
    bool anyDecided = false;
    for (int k = 0; k < kSamples; ++k) anyDecided = anyDecided || state[size_t(k)] >= 0;
    int gatherPointLit = 1;
    if (!anyDecided) {
      const float cosTheta = glm::dot(n, wi);
      gatherPointLit = cosTheta > 0.0f && !accel.occluded(Ray{offsetRayOrigin(x, n, wi), wi, 0.0f, kInfinity}) ? 1 : 0;
    }
    SunMask mask = 0;
    for (int k = 0; k < kSamples; ++k) {
      int lit = anyDecided ? state[size_t(k)] : gatherPointLit;
      if (lit < 0) {
        int best = 1 << 30;
        for (int m = 0; m < kSamples; ++m) {
          if (state[size_t(m)] < 0) continue;
          const int du = m % kSunMaskSide - k % kSunMaskSide, dv = m / kSunMaskSide - k / kSunMaskSide;
          if (du * du + dv * dv < best) best = du * du + dv * dv, lit = state[size_t(m)];
        }
      }
      if (lit > 0) mask = SunMask(mask | (1u << k));
    }
    masks[slot] = mask;
  }
  return masks;
}

/// The weights (lightfield.h tiltWeights) of a directionalIrradiance tixel's E and tilted
/// irradiances in the light it sends on: the mean over its footprint samples' mapped normals
/// n' (world; `count` of them; none: the flat surface) of the irradiance about n' times the
/// share (1 + n'·n)/2 of the cosine-weighted hemisphere above n that n' reflects into (the
/// path tracer's Lambertian lobe reflects only above n', lightfield.h). `normal`: the tixel's
/// gather normal.
TiltWeights transportTiltWeights(const Chart& c, const Vec3& normal, const Vec3* mappedNormals, int count) {
  if (count == 0) return TiltWeights{};
  const TixelFrame frame = tiltFrameAround(c, normal);
  TiltWeights mean;
  mean.irradiance = 0.0f;
  for (int s = 0; s < count; ++s) {
    const Vec3 local = frame.toLocal(mappedNormals[s]);
    const TiltWeights w = tiltWeights(local);
    const float share = 0.5f * (1.0f + local.z) / float(count);
    mean.irradiance += w.irradiance * share;
    for (uint32_t k = 0; k < kTiltedNormals; ++k) mean.tilted[k] += w.tilted[k] * share;
  }
  return mean;
}

void fillChartTixels(const Scene& scene, const Accel& accel, const Chart& c,
                     const std::vector<std::pair<uint32_t, uint32_t>>& tris, Parameterisation& p) {
  const ChartRaster r = rasteriseChart(scene, c, tris);
  const std::vector<uint32_t> nearest = nearestNonEmptyBin(c, r);
  const bool probe = c.kind != ChartKind::Specular;
  std::vector<uint8_t> isBuried(c.tixelCount(), 0);
  const Material& material = scene.materials[c.material];
  // The transport albedo: a diffuse chart's albedo, or a glossy chart's diffuse part's
  // (Chart::diffuseValue), averaged over each tixel's footprint when a texture varies it.
  const bool hasAlbedo = c.kind == ChartKind::Diffuse || c.diffuseValue;
  const bool textured = hasAlbedo && material.modelVaries();
  auto albedoAt = [&](const AlbedoPoint& point) {
    return c.kind == ChartKind::Diffuse ? diffuseAlbedoAt(scene, c.material, point)
                                        : glossyDiffuseAlbedoAt(scene, c.material, point);
  };
  // Full resolution (AlbedoPoint's lod 0): the average over the tixel's footprint samples is
  // the filter (the renderers' mip levels would filter twice).
  auto albedoOn = [&](uint32_t tri, const std::array<float, 3>& bary) {
    return albedoAt(albedoPointAt(scene, r.tris[tri].mesh, r.tris[tri].triangle, Vec2(bary[1], bary[2])));
  };
  const Rgb constantAlbedo = hasAlbedo ? albedoAt(AlbedoPoint{}) : Rgb(0.0f);
  // A metallic-roughness texture: the point models' lobe f0, averaged like the albedo.
  const bool tixelF0 = perTixelSpecularF0(scene, c);
  auto f0On = [&](uint32_t tri, const std::array<float, 3>& bary) {
    return specularF0(materialModelAt(scene, material, albedoPointAt(scene, r.tris[tri].mesh, r.tris[tri].triangle,
                                                                       Vec2(bary[1], bary[2]))));
  };
  // Per-tixel lobe widths: the point models' GGX α, averaged like the f0.
  const bool tixelAlpha = perTixelLobeWidth(scene, c);
  auto alphaOn = [&](uint32_t tri, const std::array<float, 3>& bary) {
    return ggxLobeAlpha(materialModelAt(scene, material, albedoPointAt(scene, r.tris[tri].mesh, r.tris[tri].triangle,
                                                                        Vec2(bary[1], bary[2]))));
  };
  // A textured emitter's mean emission texture over each footprint, at full resolution.
  const bool emitterTextured = texturedEmitter(scene, c);
  auto emissionOn = [&](uint32_t tri, const std::array<float, 3>& bary) {
    return emissionModulation(scene, material, r.tris[tri].mesh, r.tris[tri].triangle, Vec2(bary[1], bary[2]));
  };
  // The normal a point of the chart gathers around (chartShadingNormalAt, lightfield.h).
  auto normalAt = [&](const FootprintSample& s) {
    const ChartRaster::Tri2& t = r.tris[s.tri];
    return chartShadingNormalAt(c, scene.meshes[t.mesh], t.triangle, Vec2(s.bary[1], s.bary[2]));
  };
  for (uint32_t j = 0; j < c.resV; ++j)
    for (uint32_t i = 0; i < c.resU; ++i) {
      const uint32_t local = j * c.resU + i;
      const uint64_t g = c.firstTixel + local;
      // Footprint: coverage and mean albedo over the sub-samples inside the polygon.
      int inside = 0;
      Rgb albedoSum(0.0f), emissionSum(0.0f), f0Sum(0.0f);
      float alphaSum = 0.0f;
      // directionalIrradiance: the mapped normals (world, the record's side) at the samples.
      std::array<Vec3, kFootprintSamples * kFootprintSamples> mappedNormals;
      std::array<std::pair<float, FootprintSample>, kFootprintSamples * kFootprintSamples> insideSamples;
      for (int b = 0; b < kFootprintSamples; ++b)
        for (int a = 0; a < kFootprintSamples; ++a) {
          const Vec2 q(float(i) + (a + 0.5f) / kFootprintSamples, float(j) + (b + 0.5f) / kFootprintSamples);
          const FootprintSample s = locate(r, local, q);
          if (!s.inside) continue;
          const Vec2 fromCentre = q - Vec2(float(i) + 0.5f, float(j) + 0.5f);
          insideSamples[size_t(inside)] = {glm::dot(fromCentre, fromCentre), s};
          ++inside;
          if (textured) albedoSum += albedoOn(s.tri, s.bary);
          if (tixelF0) f0Sum += f0On(s.tri, s.bary);
          if (tixelAlpha) alphaSum += alphaOn(s.tri, s.bary);
          if (emitterTextured) emissionSum += emissionOn(s.tri, s.bary);
          if (c.directionalIrradiance) {
            const SurfaceHit hit = surfaceAt(scene, r.tris[s.tri].mesh, r.tris[s.tri].triangle, Vec2(s.bary[1], s.bary[2]));
            mappedNormals[size_t(inside - 1)] = c.isBack ? -hit.shadingNormal : hit.shadingNormal;
          }
        }
      p.coverage[g] = float(inside) / float(kFootprintSamples * kFootprintSamples);

      // Gather point: the centre if it lies on the polygon, else the closest polygon point.
      const Vec2 centre(float(i) + 0.5f, float(j) + 0.5f);
      FootprintSample s = locate(r, local, centre);
      Vec3 point(0.0f);
      if (!s.inside) {
        const uint32_t bin = nearest[local];
        float best = kInfinity;
        Vec2 bestQ = centre;
        uint32_t bestTri = 0;
        for (uint32_t t : r.bins[bin]) {
          const auto& tr = r.tris[t];
          for (int e = 0; e < 3; ++e) {
            const Vec2 q = closestOnSegment(tr.p[e], tr.p[(e + 1) % 3], centre);
            const float d = glm::dot(q - centre, q - centre);
            if (d < best) {
              best = d;
              bestQ = q;
              bestTri = t;
            }
          }
        }
        // Pull the point slightly inside its triangle (towards the centroid, by at most 2 %
        // of a tixel) so that rays from it do not start exactly on a shared edge or crack.
        const auto& tr = r.tris[bestTri];
        const Vec2 centroid = (tr.p[0] + tr.p[1] + tr.p[2]) / 3.0f;
        const float dist = glm::length(centroid - bestQ);
        if (dist > 0.0f) bestQ += (centroid - bestQ) * (std::min(0.02f, 0.5f * dist) / dist);
        s.inside = true;
        s.tri = bestTri;
        s.bary = barycentric2(tr, bestQ);
      }
      Vec3 normal = c.normal;
      if (!r.tris.empty()) {
        point = pointOnTriangle(scene, r.tris[s.tri], s.bary);
        normal = normalAt(s);
      }
      // A buried point gathers from the nearest footprint sub-sample that is not buried; a
      // tixel with none takes a neighbour's point below.
      if (probe && !r.tris.empty() && buried(scene, accel, tixelFrameAround(c, normal), point)) {
        std::sort(insideSamples.begin(), insideSamples.begin() + inside,
                  [](const auto& x, const auto& y) { return x.first < y.first; });
        isBuried[local] = 1;
        for (int k = 0; k < inside; ++k) {
          const FootprintSample& sample = insideSamples[size_t(k)].second;
          const Vec3 q = pointOnTriangle(scene, r.tris[sample.tri], sample.bary);
          const Vec3 qNormal = normalAt(sample);
          if (!buried(scene, accel, tixelFrameAround(c, qNormal), q)) {
            point = q;
            normal = qNormal;
            isBuried[local] = 0;
            break;
          }
        }
      }
      p.gatherPoint[g] = point;
      if (c.curved) p.gatherNormal[g] = normal;
      if (c.directionalIrradiance) p.transportTiltWeights[g] = transportTiltWeights(c, normal, mappedNormals.data(), inside);
      if (isSubsurfaceChart(scene, c) && !p.sunMaskLights.empty())
        p.sunMask[g].fill(SunMask(0));  // the first shot's shadow rays take the masked lights
      else if (c.kind == ChartKind::Diffuse && !p.sunMaskLights.empty())
        p.sunMask[g] = tixelSunMasks(scene, accel, c, r, local, i, j, point, normal, p.sunMaskLights);

      if (emitterTextured && !r.tris.empty()) {
        p.emissionModulation[g] = inside > 0 ? emissionSum / float(inside) : emissionOn(s.tri, s.bary);
        p.emitterTriangle[g] = {r.tris[s.tri].mesh, r.tris[s.tri].triangle};
      }
      if (tixelF0 && !r.tris.empty()) p.specularF0[g] = inside > 0 ? f0Sum / float(inside) : f0On(s.tri, s.bary);
      if (tixelAlpha && !r.tris.empty()) p.lobeAlpha[g] = inside > 0 ? alphaSum / float(inside) : alphaOn(s.tri, s.bary);
      if (hasAlbedo) {
        if (!textured) {
          p.transportAlbedo[g] = constantAlbedo;
        } else if (inside > 0) {
          p.transportAlbedo[g] = albedoSum / float(inside);
        } else {
          p.transportAlbedo[g] = albedoOn(s.tri, s.bary);
        }
      } else {
        p.transportAlbedo[g] = Rgb(0.0f);
      }
    }
  // Buried tixels (wholly under other geometry) gather from the nearest unburied tixel's
  // point (4-neighbour breadth-first order), and take its sun masks, so bilinear lookups next
  // to a contact read the light of the visible side, not the dark inside of the occluder.
  std::vector<uint32_t> source(isBuried.size(), UINT32_MAX);
  for (uint32_t k = 0; k < isBuried.size(); ++k)
    if (!isBuried[k]) source[k] = k;
  if (!fillFromNearestSeed(c, source)) return;  // the whole chart is buried: nothing visible to borrow from
  for (uint32_t k = 0; k < isBuried.size(); ++k)
    if (isBuried[k]) {
      p.borrowedPoint[c.firstTixel + k] = 1;
      p.gatherPoint[c.firstTixel + k] = p.gatherPoint[c.firstTixel + source[k]];
      if (c.curved) p.gatherNormal[c.firstTixel + k] = p.gatherNormal[c.firstTixel + source[k]];
      if (c.directionalIrradiance) p.transportTiltWeights[c.firstTixel + k] = p.transportTiltWeights[c.firstTixel + source[k]];
      // Its sun masks too: its own sub-samples are all inside the occluder (shadowed), and
      // the visible surface next to it reads them through the bilinear mask lookup.
      p.sunMask[c.firstTixel + k] = p.sunMask[c.firstTixel + source[k]];
    }
}

}  // namespace

Parameterisation buildParameterisation(const Scene& scene, const BakeSettings& settings) {
  const Accel accel(scene);
  return buildParameterisation(scene, accel, settings);
}

Parameterisation buildParameterisation(const Scene& scene, const Accel& accel, const BakeSettings& settings) {
  Parameterisation p = buildCharts(scene, accel, settings);
  fillTixels(scene, accel, p, 0, uint32_t(p.charts.size()));
  return p;
}

void recomputeSunMasks(const Scene& scene, const Accel& accel, Parameterisation& p, size_t slot) {
  if (slot >= p.sunMaskLights.size())
    fail("{}: sun mask slot {} is not one of the {} masked lights", scene.sourcePath, slot, p.sunMaskLights.size());
  const std::vector<uint32_t> light{p.sunMaskLights[slot]};
  parallelFor(p.charts.size(), [&](uint64_t ci) {
    const Chart& c = p.charts[ci];
    if (c.kind != ChartKind::Diffuse || isSubsurfaceChart(scene, c)) return;  // (their masks stay empty)
    const ChartRaster r = rasteriseChart(scene, c, p.chartTriangles[ci]);
    // What fillChartTixels did: each tixel's masks at its gather point and normal, then the
    // wholly buried tixels' from their nearest unburied neighbour (the same breadth-first order).
    std::vector<uint32_t> source(c.tixelCount(), UINT32_MAX);
    for (uint32_t local = 0; local < c.tixelCount(); ++local) {
      const uint64_t g = c.firstTixel + local;
      if (p.borrowedPoint[g]) continue;
      source[local] = local;
      const Vec3 normal = c.curved ? p.gatherNormal[g] : c.normal;
      p.sunMask[g][slot] = tixelSunMasks(scene, accel, c, r, local, local % c.resU, local / c.resU, p.gatherPoint[g],
                                         normal, light)[0];
    }
    if (!fillFromNearestSeed(c, source)) return;
    for (uint32_t local = 0; local < c.tixelCount(); ++local)
      if (p.borrowedPoint[c.firstTixel + local]) p.sunMask[c.firstTixel + local][slot] = p.sunMask[c.firstTixel + source[local]][slot];
  });
}

void fillTixels(const Scene& scene, const Accel& accel, Parameterisation& p, uint32_t firstRecord, uint32_t endRecord) {
  if (firstRecord > endRecord || endRecord > p.charts.size())
    fail("fillTixels: records [{}, {}) are not within the {} chart records", firstRecord, endRecord, p.charts.size());
  parallelFor(endRecord - firstRecord, [&](uint64_t k) {
    const uint64_t ci = firstRecord + k;
    fillChartTixels(scene, accel, p.charts[ci], p.chartTriangles[ci], p);
  });
}

std::string tixelSetupPathFor(const std::string& visibilityPath) {
  return std::filesystem::path(visibilityPath).replace_extension(".plt").string();
}

namespace {

std::array<char, 4> tixelSetupTag(const char* name) { return {name[0], name[1], name[2], name[3]}; }

/// The sun masks' array in a .plt (after forEachTixelSetupArray's).
constexpr char kSunMaskTag[] = "SUNM";

void hashMapping(Fnv1a64& h, const TextureMapping& m) {
  h.value(m.uvSet);
  h.value(m.linear);
  h.value(m.offset);
}

template <typename T>
void hashArray(Xxh64Stream& h, const std::vector<T>& v) {
  const uint64_t size = v.size();
  h.update(&size, sizeof(size));
  h.update(v.data(), v.size() * sizeof(T));
}

/// The arrays of `file` that forEachTixelSetupArray(p) names, checked against p's shapes (the
/// same tags, element sizes and counts in the same order, then at most the sun masks), copied
/// into p; the sun masks' array, when present, is left in file. "" when they fit, else what
/// does not (p unchanged).
std::string takeTixelSetupArrays(TixelSetupFile& file, Parameterisation& p, const TixelSetupArray** sunMasks) {
  *sunMasks = nullptr;
  std::string problem;
  size_t index = 0;
  forEachTixelSetupArray(p, [&](const char* tag, const auto& array) {
    using Element = typename std::decay_t<decltype(array)>::value_type;
    const TixelSetupArray* a = index < file.arrays.size() ? &file.arrays[index] : nullptr;
    if (problem.empty() && (!a || a->tag != tixelSetupTag(tag) || a->elementBytes != sizeof(Element) || a->count != array.size()))
      problem = fmt::format("array {} of {} elements of {} bytes expected, the file has {}", tag, array.size(),
                            sizeof(Element),
                            a ? fmt::format("{} of {} elements of {} bytes", std::string(a->tag.data(), 4), a->count,
                                            a->elementBytes)
                              : std::string("no more arrays"));
    ++index;
  });
  if (!problem.empty()) return problem;
  if (index < file.arrays.size()) {
    const TixelSetupArray& a = file.arrays[index];
    if (a.tag != tixelSetupTag(kSunMaskTag) || a.elementBytes != sizeof(SunMaskSlots) || a.count != p.tixelCount ||
        index + 1 != file.arrays.size())
      return fmt::format("{} arrays, expected {} and the sun masks", file.arrays.size(), index);
    *sunMasks = &a;
  }
  index = 0;
  forEachTixelSetupArray(p, [&](const char*, auto& array) {
    if (!array.empty()) std::memcpy(static_cast<void*>(array.data()), file.arrays[index].bytes.data(), file.arrays[index].bytes.size());
    std::vector<unsigned char>().swap(file.arrays[index].bytes);
    ++index;
  });
  return "";
}

}  // namespace

uint64_t modelParameterHash(const Bsdf& bsdf) {
  Fnv1a64 h;
  h.value(uint32_t(bsdf.index()));
  std::visit([&](const auto& b) { std::decay_t<decltype(b)>::parameters(b, [&](const auto& field) { h.value(field); }); },
             bsdf);
  return h.digest();
}

std::vector<float> lightPlacement(const Light& light) {
  std::vector<float> out;
  visitLightParameters(light, [&](const char*, LightParameterKind kind, const auto& field) {
    if (kind == LightParameterKind::Emission) return;
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, float>) {
      out.push_back(field);
    } else {
      out.insert(out.end(), {field.x, field.y, field.z});
    }
  });
  return out;
}

std::vector<uint64_t> tixelSetupKeys(const Scene& scene, const Parameterisation& p) {
  std::vector<uint64_t> keys;
  // Every texture once (its texels are most of the bytes hashed), shared by the keys below.
  std::vector<uint64_t> textureHash(scene.textures.size());
  parallelFor(scene.textures.size(), [&](uint64_t i) {
    const Texture& t = scene.textures[i];
    Xxh64Stream h;
    h.update(&t.image.width, sizeof(t.image.width));
    h.update(&t.image.height, sizeof(t.image.height));
    hashArray(h, t.image.pixels);
    const uint32_t sampling = uint32_t(t.sampling.wrapU) | uint32_t(t.sampling.wrapV) << 8 | uint32_t(t.sampling.nearest) << 16;
    h.update(&sampling, sizeof(sampling));
    textureHash[i] = h.digest();
  });
  Xxh64Stream attributes;
  for (const Mesh& mesh : scene.meshes) {
    hashArray(attributes, mesh.normals);
    hashArray(attributes, mesh.uvs);
    hashArray(attributes, mesh.uvs1);
    hashArray(attributes, mesh.colors);
  }
  hashArray(attributes, textureHash);
  keys.push_back(attributes.digest());
  for (const Material& m : scene.materials) {
    Fnv1a64 h;
    h.value(modelParameterHash(m.bsdf));
    h.value(m.albedoTexture);
    h.value(m.emissionTexture);
    h.value(m.normalTexture);
    h.value(m.normalScale);
    h.value(m.metallicRoughness.texture);
    h.value(m.metallicRoughness.baseColor);
    h.value(m.metallicRoughness.metallic);
    h.value(m.metallicRoughness.roughness);
    for (const TextureMapping* mapping :
         {&m.albedoMapping, &m.alphaMapping, &m.normalMapping, &m.emissionMapping, &m.metallicRoughness.mapping})
      hashMapping(h, *mapping);
    h.value(uint8_t(m.isEmissive()));  // (a textured emitter's footprint means; not the emission's value)
    h.value(uint8_t(m.twoSidedEmission));
    h.value(uint8_t(m.vertexColored));
    h.value(m.tixelDensity);
    keys.push_back(h.digest());
  }
  for (uint32_t l : p.sunMaskLights) {
    Fnv1a64 h;
    h.value(l);
    h.value(uint32_t(scene.lights[l].index()));
    for (float v : lightPlacement(scene.lights[l])) h.value(v);
    keys.push_back(h.digest());
  }
  return keys;
}

void writeTixelSetup(const std::string& path, const Scene& scene, const Parameterisation& p, uint64_t hash,
                     const std::vector<uint32_t>& staleMaterials) {
  std::vector<TixelSetupView> views;
  forEachTixelSetupArray(p, [&](const char* tag, const auto& array) {
    using Element = typename std::decay_t<decltype(array)>::value_type;
    static_assert(std::is_standard_layout_v<Element> && std::is_trivially_destructible_v<Element>);  // stored as its bytes
    views.push_back({tixelSetupTag(tag), uint32_t(sizeof(Element)), uint64_t(array.size()), array.data()});
  });
  views.push_back({tixelSetupTag(kSunMaskTag), uint32_t(sizeof(SunMaskSlots)), uint64_t(p.sunMask.size()), p.sunMask.data()});
  std::vector<uint64_t> keys = tixelSetupKeys(scene, p);
  for (uint32_t m : staleMaterials) keys.at(1 + m) = 0;  // (keys: [0] attributes, then one per material)
  writeTixelSetupFile(path, hash, p.tixelCount, views, keys);
}

bool readTixelSetup(const std::string& path, uint64_t hash, const std::vector<SunMask>& sunMasks, Parameterisation& p,
                    std::string* why) {
  TixelSetupFile file;
  if (!readTixelSetupFile(path, hash, file, why)) return false;
  const size_t lightCount = p.sunMaskLights.size();
  if (file.tixelCount != p.tixelCount)
    fail("{}: the tixel setup has {} tixels, the light field's charts {}", path, file.tixelCount, p.tixelCount);
  if (sunMasks.size() != p.tixelCount * lightCount)
    fail("{}: the light field holds {} sun masks, its charts need {} ({} masked lights)", path, sunMasks.size(),
         p.tixelCount * lightCount, lightCount);
  // The light field's sun masks follow its lights; the file's, the baked ones.
  const TixelSetupArray* savedMasks = nullptr;
  const std::string problem = takeTixelSetupArrays(file, p, &savedMasks);
  if (!problem.empty()) fail("{}: the tixel setup does not fit the light field's charts: {}", path, problem);
  for (uint64_t g = 0; g < p.tixelCount && lightCount > 0; ++g)
    std::copy_n(sunMasks.begin() + int64_t(g * lightCount), lightCount, p.sunMask[g].begin());
  return true;
}

bool reuseTixelSetup(const std::string& path, uint64_t hash, const Scene& scene, const Accel& accel, Parameterisation& p,
                     TixelSetupReuse& out, std::string* why) {
  auto reason = [&](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  out = {};
  TixelSetupFile file;
  if (!readTixelSetupFile(path, hash, file, why)) return false;
  if (file.tixelCount != p.tixelCount)
    return reason(fmt::format("{} was written for {} tixels, these charts have {}", path, file.tixelCount, p.tixelCount));
  const std::vector<uint64_t> keys = tixelSetupKeys(scene, p);
  const size_t materials = scene.materials.size();
  if (file.keys.empty()) return reason(fmt::format("{} was written without the keys of its inputs (an older version)", path));
  if (file.keys.size() != keys.size())
    return reason(fmt::format("{} was written for another number of materials or sun-masked lights", path));
  if (file.keys[0] != keys[0])
    return reason(fmt::format("the meshes' normals, uvs or vertex colours or the textures differ from {}'s", path));
  std::vector<uint8_t> materialChanged(materials, 0);
  for (size_t m = 0; m < materials; ++m) materialChanged[m] = file.keys[1 + m] != keys[1 + m];
  const TixelSetupArray* savedMasks = nullptr;
  const std::string problem = takeTixelSetupArrays(file, p, &savedMasks);
  if (!problem.empty()) return reason(fmt::format("{} does not fit the charts: {}", path, problem));
  if (!savedMasks) return reason(fmt::format("{} holds no sun masks (an older version)", path));
  std::memcpy(static_cast<void*>(p.sunMask.data()), savedMasks->bytes.data(), savedMasks->bytes.size());
  // What changed: the charts of a changed material, filled as fillTixels fills every record
  // (a record's tixels depend only on the record), then the masks of a masked light that moved.
  std::vector<uint32_t> refill;
  for (uint32_t ci = 0; ci < p.charts.size(); ++ci)
    if (materialChanged[p.charts[ci].material]) refill.push_back(ci);
  parallelFor(refill.size(), [&](uint64_t k) {
    const Chart& c = p.charts[refill[k]];
    std::fill_n(p.borrowedPoint.begin() + int64_t(c.firstTixel), c.tixelCount(), uint8_t(0));  // (buildCharts' value)
    fillChartTixels(scene, accel, p.charts[refill[k]], p.chartTriangles[refill[k]], p);
  });
  out.chartsFilled = uint32_t(refill.size());
  for (size_t slot = 0; slot < p.sunMaskLights.size(); ++slot)
    if (file.keys[1 + materials + slot] != keys[1 + materials + slot]) {
      recomputeSunMasks(scene, accel, p, slot);
      ++out.sunMasksTraced;
    }
  return true;
}

}  // namespace pl
