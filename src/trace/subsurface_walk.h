#pragma once
// The random walk through a subsurface medium (bsdf.h SubsurfaceBsdf): the one implementation
// that the path tracer (path_tracer.cpp) and the light-field bake's subsurface operator
// (bake/subsurface.h) both run, so the two cannot model the medium differently.
#include <cstdint>
#include <optional>

#include "bsdf/bsdf.h"
#include "core/math.h"
#include "core/sampler.h"
#include "scene/scene.h"

namespace pl {

class Accel;

/// A walk takes at most kMaxWalkSteps scattering events; one that has not left by then is
/// absorbed. Its throughput is then below α^kMaxWalkSteps ≤ 0.011 for the largest α the
/// mapping gives (A → 1: α = 1 − e^−6.8), and walks that long are rare (in a half-space the
/// chance of leaving after n steps falls as n^−3/2): what is lost is below 1e-5 of the light.
/// It bounds the work of a walk whose throughput stays high.
inline constexpr uint32_t kMaxWalkSteps = 4096;
/// Sampler dimensions per walk step: step k draws from firstDimension + k·kDimensionsPerWalkStep
/// + WalkDimension (step 0: the entry direction).
inline constexpr uint32_t kDimensionsPerWalkStep = 5;
enum WalkDimension : uint32_t { kWalkChannel = 0, kWalkDistance = 1, kWalkDirection = 2, kWalkRoulette = 4 };
/// The sampler dimensions one walk may use: (kMaxWalkSteps + 1) steps.
inline constexpr uint64_t kWalkDimensions = uint64_t(kMaxWalkSteps + 1) * kDimensionsPerWalkStep;

/// Where a random walk left the medium.
struct WalkExit {
  SurfaceHit surface;  ///< the exit point on the mesh
  Vec3 direction;      ///< the walk's last direction (it crosses the surface outwards)
  Rgb weight;          ///< the walk's throughput, entry to exit (per channel)
};

/// A random walk from an entry point at `position` on a subsurface surface (`entry`: its frame
/// turned to the outside, where the light comes from) to the point where it leaves the mesh;
/// nullopt when it is absorbed (roulette, kMaxWalkSteps) or cannot start (a grazing or bent
/// normal). It enters cosine-distributed about the inward normal with weight 1 (the boundary
/// is diffuse and index-matched). `throughput` is the light's throughput before the walk (the
/// path's; 1 for light entering unweighted): the channel choice and the roulette follow it.
/// Draws from `sampler` at dimensions [firstDimension, firstDimension + kWalkDimensions);
/// counts its rays in `rays`. The .cpp describes the estimator.
std::optional<WalkExit> subsurfaceWalk(const Scene& scene, const Accel& accel, const Vec3& position,
                                       const ScatteringFrame& entry, const SubsurfaceMedium& medium,
                                       const Rgb& throughput, Sampler& sampler, uint32_t firstDimension,
                                       uint64_t& rays);

}  // namespace pl
