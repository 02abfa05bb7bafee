// The random walk through a subsurface medium (see subsurface_walk.h).
//
// Hero channel with spectral MIS (the one-sample balance heuristic over the channels, as in
// Cycles; Wilkie et al. 2014, "Hero Wavelength Spectral Sampling"): one path serves all three
// channels, whose media differ, instead of a walk per channel that would split the path. At each
// step a channel c is chosen with probability p_c ∝ the path's throughput in it (β · walk weight)
// and a free-flight distance t drawn from σt_c e^(−σt_c t). The distance's density is then the
// mixture p(t) = Σ_j p_j σt_j e^(−σt_j t), and channel k's weight is multiplied by
//   α_k σt_k e^(−σt_k t) / p(t)                          at a scattering event (t before the
//                                                        boundary: σs = α σt, then the phase),
//   e^(−σt_k t_b) / Σ_j p_j e^(−σt_j t_b)                 when the boundary comes first at t_b
// (the probability of flying past t_b in channel k over the mixture's). Each channel's estimate
// is unbiased whichever channel was drawn, and none is drawn where it carries nothing.
// The phase function is isotropic: a uniform direction on the sphere, weight 1.
//
// Only surfaces of subsurface materials bound the medium: the walk passes through any other
// surface inside the mesh (as Cycles' walk sees only its own object). Russian roulette inside:
// once the path's throughput has fallen below 1, a step continues with probability √(max
// channel) (as the path's own roulette, without its 0.95 cap, which would end the long walks of
// high albedos for no loss of theirs); see kMaxWalkSteps for the cap on steps.
#include "trace/subsurface_walk.h"

#include <cmath>

#include "accel/accel.h"
#include "core/sampling.h"

namespace pl {

std::optional<WalkExit> subsurfaceWalk(const Scene& scene, const Accel& accel, const Vec3& position,
                                       const ScatteringFrame& entry, const SubsurfaceMedium& medium,
                                       const Rgb& throughput, Sampler& sampler, uint32_t firstDimension,
                                       uint64_t& rays) {
  auto dimension = [&](uint32_t step, WalkDimension which) {
    return firstDimension + step * kDimensionsPerWalkStep + which;
  };
  sampler.setDimension(dimension(0, kWalkDirection));
  const Vec3 local = sampleCosineHemisphere(sampler.get2D());
  Vec3 direction = entry.frame.toWorld(Vec3(local.x, local.y, -local.z));
  if (!(glm::dot(direction, entry.geometricNormal) < 0.0f)) return std::nullopt;  // grazing, or a bent normal
  Vec3 origin = offsetRayOrigin(position, entry.geometricNormal, direction);
  Rgb weight(1.0f);
  for (uint32_t step = 1; step <= kMaxWalkSteps; ++step) {
    // Channel choice ∝ the path's throughput in each channel.
    const Rgb carried = throughput * weight;
    const float total = carried.r + carried.g + carried.b;
    if (!(total > 0.0f) || !std::isfinite(total)) return std::nullopt;
    const Rgb channelPdf = carried / total;
    sampler.setDimension(dimension(step, kWalkChannel));
    const float uChannel = sampler.get1D() * total;
    const int channel = uChannel < carried.r ? 0 : uChannel < carried.r + carried.g ? 1 : 2;
    sampler.setDimension(dimension(step, kWalkDistance));
    const float distance = -std::log1p(-sampler.get1D()) / medium.sigmaT[channel];

    // The boundary within that distance: the first subsurface surface (others are passed).
    Ray ray{origin, direction, 0.0f, distance};
    float travelled = 0.0f;
    std::optional<RayHit> boundary;
    for (;;) {
      RayHit hit;
      ++rays;
      if (!accel.intersect(ray, hit)) break;
      const uint32_t material = scene.meshes[hit.mesh].materials[hit.triangle];
      if (subsurfaceMedium(scene.materials[material].bsdf)) {
        hit.t += travelled;
        boundary = hit;
        break;
      }
      const SurfaceHit passed = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
      ray.origin = offsetRayOrigin(passed.position, passed.geometricNormal, direction);
      travelled += hit.t;
      ray.tMax = distance - travelled;
      if (!(ray.tMax > 0.0f)) break;
    }

    if (boundary) {
      const Rgb transmittance = glm::exp(-medium.sigmaT * boundary->t);
      weight *= transmittance / glm::dot(channelPdf, transmittance);
      if (!isFinite(weight)) return std::nullopt;
      return WalkExit{surfaceAt(scene, boundary->mesh, boundary->triangle, boundary->barycentrics), direction, weight};
    }
    const Rgb density = medium.sigmaT * glm::exp(-medium.sigmaT * distance);
    weight *= medium.alpha * density / glm::dot(channelPdf, density);
    if (!isFinite(weight)) return std::nullopt;
    origin += distance * direction;
    sampler.setDimension(dimension(step, kWalkDirection));
    direction = sampleUniformSphere(sampler.get2D());

    const float carriedMax = maxComponent(throughput * weight);
    if (carriedMax < 1.0f) {
      const float q = std::sqrt(carriedMax);
      sampler.setDimension(dimension(step, kWalkRoulette));
      if (!(sampler.get1D() < q)) return std::nullopt;
      weight /= q;
    }
  }
  return std::nullopt;
}

}  // namespace pl
