#pragma once
// The light field's subsurface transport (docs/design.md, "Subsurface scattering in the light
// field"). A chart of a subsurface material (bsdf.h SubsurfaceBsdf) is a diffuse chart whose
// light leaves away from where it entered: its boundary is diffuse and index-matched, so the
// light leaving a point is view-independent (one value per tixel, as on a Lambertian chart),
// and it is a linear function of the irradiance arriving over the whole object.
//
// The operator. K[j ← i] is the exitance (W·m⁻²) that leaves subsurface tixel j per unit
// irradiance (W·m⁻²) arriving at subsurface tixel i. It is estimated by random walks — the
// path tracer's own (trace/subsurface_walk.h) — entering at points spread area-uniformly over
// the triangles of every subsurface chart, about `walksPerTixel` per tixel area: a walk
// entering at a point of tixel i, which stands for the area a = (triangle area / its walks),
// and leaving at a point of tixel j with weight w adds w·a / A_j to K[j ← i], A_j the surface
// area under tixel j (the sum of the a of the walks entering there: on a curved chart more
// than its square in the chart's plane; one footprint sub-sample's where none entered). The exitance
// of tixel j is then M_j = Σ_i K[j ← i]·E_i, and its radiance M_j / π. The fraction of the
// light entering tixel i that leaves through tixel j is S[i → j] = K[j ← i]·A_j / A_i; per
// channel Σ_j S[i → j] ≤ 1 (up to the walks' noise): the light the medium does not absorb.
//
// Stored compressed by exit tixel (CSR rows, one per subsurface tixel) for the propagation's
// gather-style product; never written to a file (the bake rebuilds it). A distributed bake
// (shard.h) splits the walks between its ranks by entry record and exchanges their results, so
// that every rank holds the whole operator, the one process's bit for bit. Per entry tixel the
// smallest entries are dropped while their sum stays below kSubsurfaceDroppedFraction of the
// light leaving that tixel's entries (luminance): the energy bound of the truncation.
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace pl {

class Accel;
class Communicator;
struct Scene;
struct Parameterisation;

/// Per entry tixel, the entries dropped from the operator carry at most this fraction of the
/// light (luminance) that leaves the object from that tixel's walks.
inline constexpr float kSubsurfaceDroppedFraction = 1e-3f;

struct SubsurfaceOperator {
  std::vector<uint64_t> rowTixel;   ///< the subsurface tixels (exit tixels j), ascending
  std::vector<uint64_t> rowStart;   ///< row r's entries are [rowStart[r], rowStart[r + 1])
  std::vector<uint64_t> entryTixel; ///< per entry: the entry tixel i
  std::vector<Rgb> weight;          ///< per entry: K[j ← i] (exitance per irradiance)
  std::vector<float> area;          ///< per row: the surface area A_j under the tixel (scene units²)
  uint64_t walks = 0, exited = 0;   ///< walks started, walks that left the medium
  uint64_t walkedHere = 0;          ///< walks this rank started (its share of `walks`)
  uint64_t rays = 0;                ///< rays the walks traced
  uint64_t dropped = 0;             ///< entries dropped by the truncation
  double seconds = 0.0;             ///< time to build it

  bool empty() const { return rowTixel.empty(); }
  uint64_t entries() const { return entryTixel.size(); }
  /// Bytes of its arrays.
  uint64_t bytes() const;
};

/// Builds the operator of every subsurface chart of `param` (empty when there is none), with
/// about `walksPerTixel` walks per tixel area; deterministic for a given seed.
SubsurfaceOperator buildSubsurfaceOperator(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                           uint32_t walksPerTixel, uint64_t seed);
/// The same over the ranks of `comm` (a collective: every rank calls it): the walking records
/// (the subsurface charts' front records) are split into contiguous runs of about equal walk
/// counts, each rank walks its run, and the runs' merged, truncated walks are exchanged (one
/// allgather of their sizes, then in-place allgathervs of the bytes), so that every rank
/// returns the one-process operator bit for bit (each record's walks depend only on the record
/// and the seed); walkedHere counts this rank's walks.
SubsurfaceOperator buildSubsurfaceOperator(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                           uint32_t walksPerTixel, uint64_t seed, Communicator& comm);

/// An upper bound on the bytes buildSubsurfaceOperator allocates for `param` (0 without
/// subsurface charts) on each of `ranks` ranks: every walk kept as its own entry, and its
/// contribution record alive beside the compressed rows (plus, over several ranks, its bytes
/// in the exchange buffer): what the memory guard, bake.h BakeOptions::checkMemory, adds.
uint64_t subsurfaceOperatorBytesEstimate(const Scene& scene, const Parameterisation& param, uint32_t walksPerTixel,
                                         int ranks = 1);

/// exitance[r] = Σ K[rowTixel[r] ← i]·irradiance[i] for every row r; `irradiance` by global
/// tixel index (entries of non-subsurface tixels are never read).
void applySubsurfaceOperator(const SubsurfaceOperator& op, const std::vector<Rgb>& irradiance, std::vector<Rgb>& exitance);

/// Per entry tixel i of the operator (the rows' tixels, in the same order): Σ_j S[i → j], the
/// fraction of the light entering tixel i that leaves the object, per channel.
std::vector<Rgb> subsurfaceLeavingFractions(const SubsurfaceOperator& op);

}  // namespace pl
