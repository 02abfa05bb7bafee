// Caustics: photons from the emissive triangles and sphere lights through specular chains (see caustics.h).
#include "bake/caustics.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <variant>

#include "accel/accel.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "core/sampler.h"
#include "core/sampling.h"
#include "core/timing.h"
#include "lightfield/lookup.h"

namespace pl {

namespace {

// Photons per parallel work item (their deposits are concatenated in item order).
constexpr uint64_t kPhotonsPerBlock = 4096;

/// The share of the tent kernel of a tixel (clamp-to-edge bilinear weights, as linearTap gives
/// them) that falls on the footprint of the tixel `offset` (−1, 0, 1) away along an axis of
/// `count` tixels, for tixel index i: ∫ over the footprint [i+offset−½, i+offset+½] of the
/// weight. Its own footprint holds 3/8 on each inner side and ½ on a side at the grid's edge
/// (where the clamp gives weight 1 up to the edge); each neighbour 1/8. They sum to 1.
float tentShare(uint32_t i, int offset, uint32_t count) {
  if (offset == 0) return (i == 0 ? 0.5f : 0.375f) + (i + 1 == count ? 0.5f : 0.375f);
  if ((offset < 0 && i == 0) || (offset > 0 && i + 1 >= count)) return 0.0f;
  return 0.125f;
}

/// ∫ over the chart's surface of tixel (i, j)'s tent kernel (scene units²): tixelSize² times
/// the kernel's shares of the footprints of the tixel and its eight neighbours, each times
/// that footprint's covered fraction (coverage taken as uniform inside a footprint). A fully
/// covered chart gives tixelSize² everywhere, edges included.
double kernelArea(const Parameterisation& param, const Chart& c, uint32_t i, uint32_t j) {
  double sum = 0.0;
  for (int dv = -1; dv <= 1; ++dv) {
    const float sv = tentShare(j, dv, c.resV);
    if (sv == 0.0f) continue;
    for (int du = -1; du <= 1; ++du) {
      const float su = tentShare(i, du, c.resU);
      if (su == 0.0f) continue;
      const uint64_t g = c.firstTixel + uint64_t(int64_t(j) + dv) * c.resU + uint64_t(int64_t(i) + du);
      sum += double(su) * sv * param.coverage[g];
    }
  }
  return sum * double(c.tixelSize) * c.tixelSize;
}

/// The flux weight of one specular step: followSpecular's radiance weight, times η'² at a
/// refraction through solid glass (η' = η on the side the photon goes to / η on the side it
/// came from), since radiance, not flux, is scaled by 1/η'² there.
Rgb fluxWeight(const Scene& scene, const Chart& chart, const Vec3& frontNormal, const Ray& arriving, const Ray& next,
               const Rgb& radianceWeight) {
  const auto* glass = std::get_if<DielectricBsdf>(&scene.materials[chart.material].bsdf);
  if (!glass || glass->thin) return radianceWeight;
  const float before = glm::dot(arriving.direction, frontNormal), after = glm::dot(next.direction, frontNormal);
  if (!(before * after > 0.0f)) return radianceWeight;  // reflected
  const float eta = after < 0.0f ? glass->ior : 1.0f / glass->ior;  // into the inside (the back) or out of it
  return radianceWeight * (eta * eta);
}

struct PhotonState {
  uint32_t photon;  ///< index within the block (deposit order)
  Rgb flux;         ///< W
  bool sphere = false;  ///< from a sphere light
};

}  // namespace

bool shootsCaustics(const Parameterisation& param, const LightSampler& lights, const BakeSettings& settings) {
  return settings.causticPhotons > 0 && (lights.emissiveTriangleCount() > 0 || lights.hasSphereLights()) &&
         std::any_of(param.charts.begin(), param.charts.end(), [](const Chart& c) { return c.kind == ChartKind::Specular; });
}

CausticPhotons traceCausticPhotons(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                   const LightSampler& lights, const BakeSettings& settings, Progress* progress) {
  CausticPhotons result;
  if (!shootsCaustics(param, lights, settings)) return result;
  const auto start = SteadyClock::now();
  const uint64_t photons = std::min<uint64_t>(settings.causticPhotons, uint64_t(1) << 32);
  const uint64_t blocks = (photons + kPhotonsPerBlock - 1) / kPhotonsPerBlock;
  // Independent scrambles of the emitter point, the direction, the direction's index shuffle
  // and the side, all from the seed.
  const uint64_t seedHash = mix64(settings.seed ^ 0xca05ca05ca05ca05ULL);
  const uint32_t pointSeed = uint32_t(seedHash), directionSeed = uint32_t(seedHash >> 32);
  const uint32_t shuffleSeed = uint32_t(mix64(seedHash + 1)), sideSeed = uint32_t(mix64(seedHash + 2));
  // Sphere lights shoot their share of the photons by power (luminance), after the emissive
  // triangles' (photon indices trianglePhotons … photons − 1), each sphere chosen ∝ its power.
  std::vector<const SphereLight*> spheres;
  std::vector<float> spherePowers;
  for (const Light& light : scene.lights)
    if (const auto* sphere = std::get_if<SphereLight>(&light); sphere && sphere->power(0.0f) > 0.0f) {
      spheres.push_back(sphere);
      spherePowers.push_back(sphere->power(0.0f));
    }
  const Distribution1D sphereChoice(spherePowers);
  const double trianglePower = lights.emissiveTrianglePower();
  const uint64_t spherePhotons =
      spheres.empty() ? 0 : uint64_t(double(photons) * sphereChoice.total() / (sphereChoice.total() + trianglePower) + 0.5);
  const uint64_t trianglePhotons = photons - spherePhotons;
  const float invTrianglePhotons = trianglePhotons > 0 ? 1.0f / float(trianglePhotons) : 0.0f;
  const float invSpherePhotons = spherePhotons > 0 ? 1.0f / float(spherePhotons) : 0.0f;

  std::vector<std::vector<std::pair<uint32_t, CausticDeposit>>> blockDeposits(blocks);
  std::atomic<uint64_t> rayCount{0}, landedCount{0};
  parallelFor(blocks, [&](uint64_t block) {
    const uint64_t first = block * kPhotonsPerBlock, count = std::min(kPhotonsPerBlock, photons - first);
    std::vector<Ray> rays, nextRays;
    std::vector<RayHit> hits;
    std::vector<PhotonState> states, nextStates;
    auto& deposits = blockDeposits[block];
    for (uint64_t p = 0; p < count; ++p) {
      const uint32_t index = uint32_t(first + p);
      const Vec2 uPoint(fixedToUnit(scrambledSobol(index, 0, pointSeed)), fixedToUnit(scrambledSobol(index, 1, pointSeed)));
      // The direction's points come from a nested uniform shuffle of the index (Burley 2020),
      // so they are a Sobol net of their own, not correlated with the emitter point's.
      const uint32_t shuffled = reverseBits32(owenScrambleReversed(reverseBits32(index), shuffleSeed));
      const Vec2 uDirection(fixedToUnit(scrambledSobol(shuffled, 0, directionSeed)),
                            fixedToUnit(scrambledSobol(shuffled, 1, directionSeed)));
      if (first + p >= trianglePhotons) {
        // A sphere light's photon: a point uniform on the sphere (area 4πr²), a cosine-distributed
        // direction about its outward normal; flux π·Le·4πr²/(P(sphere)·N) = 4π·I/(P(sphere)·N).
        float remapped = 0.0f;
        const size_t chosen = sphereChoice.sample(uPoint.x, &remapped);
        const SphereLight& sphere = *spheres[chosen];
        const Vec3 normal = sampleUniformSphere(Vec2(remapped, uPoint.y));
        const Vec3 dir = glm::normalize(Frame::fromNormal(normal).toWorld(sampleCosineHemisphere(uDirection)));
        const Rgb flux = sphere.intensity * (4.0f * kPi * invSpherePhotons / sphereChoice.probability(chosen));
        if (isBlack(flux)) continue;
        rays.push_back(Ray{offsetRayOrigin(sphere.position + sphere.radius * normal, normal, dir), dir, 0.0f, kInfinity});
        states.push_back({uint32_t(p), flux, true});
        continue;
      }
      const EmitterPoint e = lights.sampleEmitterPoint(uPoint);
      if (!e.triangle || !(e.areaPdf > 0.0f)) continue;
      const EmissiveTriangle& tri = *e.triangle;
      if (param.charts[param.triangleChart[tri.mesh][tri.triangle]].kind == ChartKind::Specular) continue;  // no lamp here (visibility.cpp)
      const bool back = tri.twoSided && (owenScrambleReversed(index, sideSeed) & 0x80000000u) != 0;
      const Vec3 normal = back ? -tri.normal : tri.normal;
      const Vec3 dir = glm::normalize(Frame::fromNormal(normal).toWorld(sampleCosineHemisphere(uDirection)));
      const float sideProbability = tri.twoSided ? 0.5f : 1.0f;
      const Rgb flux =
          tri.Le(glm::dot(dir, tri.normal)) * e.modulation * (kPi * invTrianglePhotons / (e.areaPdf * sideProbability));
      if (isBlack(flux)) continue;
      rays.push_back(Ray{offsetRayOrigin(e.point, tri.normal, dir), dir, 0.0f, kInfinity});
      states.push_back({uint32_t(p), flux});
    }
    uint64_t landed = 0;
    for (uint32_t depth = 0; !rays.empty(); ++depth) {
      hits.resize(rays.size());
      accel.intersectIncoherent(rays, hits);
      rayCount += rays.size();
      nextRays.clear();
      nextStates.clear();
      for (size_t r = 0; r < rays.size(); ++r) {
        const Ray& ray = rays[r];
        const RayHit& hit = hits[r];
        if (!hit.hit()) continue;
        const Mesh& mesh = scene.meshes[hit.mesh];
        const uint32_t chartIndex =
            facingChart(param.charts.data(), param.triangleChart[hit.mesh][hit.triangle], -ray.direction, mesh, hit.triangle);
        const Chart& c = param.charts[chartIndex];
        if (c.kind == ChartKind::Specular) {
          // A sphere light's light reaches a surface through a specular chain in the path
          // tracer only when the chain's vertex nearest the light is a lobe (next-event
          // estimation there): through a mirror or glass first it is in neither (caustics.h).
          if (states[r].sphere && depth == 0 && !isMirrorLikeRecord(c, scene.materials[c.material].bsdf)) continue;
          Rgb emitted, weight;
          Ray next;
          if (!followSpecular(scene, ray, hit, depth, settings.mirrorDepth, emitted, next, weight)) continue;
          const Rgb flux = states[r].flux * fluxWeight(scene, c, triangleNormal(mesh, hit.triangle), ray, next, weight);
          if (isBlack(flux)) continue;
          nextRays.push_back(next);
          nextStates.push_back({states[r].photon, flux, states[r].sphere});
          continue;
        }
        // Not specular: direct light at the first hit (shadow rays and gather count it); after
        // a specular chain, a caustic on the front (or a two-sided back) of a diffuse chart.
        if (depth == 0 || c.kind != ChartKind::Diffuse) continue;
        if (glm::dot(ray.direction, chartNormalAt(c, mesh, hit.triangle)) > 0.0f) continue;  // a one-sided chart from behind
        const Vec2 grid = tixelGridCoordinates(c, ray.origin + hit.t * ray.direction);
        const LinearTap tu = linearTap(grid.x, c.resU), tv = linearTap(grid.y, c.resV);
        const uint32_t is[2] = {tu.i0, tu.i1}, js[2] = {tv.i0, tv.i1};
        const float wu[2] = {1.0f - tu.f, tu.f}, wv[2] = {1.0f - tv.f, tv.f};
        bool any = false;
        for (int b = 0; b < 2; ++b)
          for (int a = 0; a < 2; ++a) {
            const float w = wu[a] * wv[b];
            if (!(w > 0.0f)) continue;
            const double area = kernelArea(param, c, is[a], js[b]);
            if (!(area > 1e-3 * double(c.tixelSize) * c.tixelSize)) continue;
            const uint64_t g = c.firstTixel + uint64_t(js[b]) * c.resU + is[a];
            deposits.push_back({states[r].photon, CausticDeposit{g, -ray.direction, states[r].flux * float(double(w) / area)}});
            any = true;
          }
        landed += any ? 1 : 0;
      }
      std::swap(rays, nextRays);
      std::swap(states, nextStates);
    }
    // Photon order (a photon's own deposits keep their order).
    std::stable_sort(deposits.begin(), deposits.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    landedCount += landed;
    if (progress) progress->advance(count);
  });

  size_t total = 0;
  for (const auto& list : blockDeposits) total += list.size();
  result.deposits.reserve(total);
  for (auto& list : blockDeposits) {
    for (const auto& item : list) result.deposits.push_back(item.second);
    std::vector<std::pair<uint32_t, CausticDeposit>>().swap(list);
  }
  result.photons = photons;
  result.landed = landedCount.load();
  result.rays = rayCount.load();
  result.seconds = secondsSince(start);
  return result;
}

}  // namespace pl
