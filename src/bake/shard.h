#pragma once
// How the ranks of a distributed bake share the tixels (docs/design.md, Distributed bake).
//
// Propagation is block Gauss–Seidel over batches of whole charts (propagation.h): batch b is
// updated after batches < b, its tixels all at once. A distributed bake keeps exactly that
// order: every batch is split across all ranks, rank r updating the contiguous part
// part(b, r), and the parts are exchanged before the next batch starts. So the result is the
// single-process one bit for bit, whatever the rank count.
//
// The split balances an estimate of each tixel's cost, not the tixel count (see
// estimatedTixelCost): a rank's part of every batch costs about 1/ranks of the batch, so its
// share of visibility rays, first-shot shadow rays and gather work is balanced too (each of
// those is per tixel, and every batch is split the same way).
#include <string>
#include <vector>

#include "bake/visibility.h"

namespace pl {

class Accel;
class Communicator;

struct ShardPlan {
  int ranks = 1;
  std::vector<uint64_t> batchStart;  ///< propagationBatches: batch b is [batchStart[b], batchStart[b + 1])
  /// Per batch, ranks + 1 boundaries: rank r's part of batch b is
  /// [split[b·(ranks+1) + r], split[b·(ranks+1) + r + 1]).
  std::vector<uint64_t> split;
  std::vector<double> rankCost;  ///< estimated cost of every rank's tixels (ray equivalents); 0 for one rank (not estimated)

  size_t batches() const { return batchStart.size() - 1; }
  TixelRange part(size_t batch, int rank) const {
    const size_t at = batch * size_t(ranks + 1) + size_t(rank);
    return {split[at], split[at + 1]};
  }
  /// Rank r's parts of every batch, adjacent ones merged.
  std::vector<TixelRange> owned(int rank) const;
};

/// Estimated cost of tixel g in ray equivalents: its gather rays (N, a mirror chain counted as
/// one ray), its first-shot shadow rays (punctual lights + area-light samples) and, for a
/// glossy tixel, its BSDF evaluations and operator products (dirRes² × (9 × lights +
/// area-light samples + N/8) at kGlossyEvalCost rays each); mirror tixels cost nothing.
double estimatedTixelCost(const Scene& scene, const Parameterisation& param, const BakeSettings& settings, uint64_t g);

/// The split of every propagation batch into `ranks` parts of about equal estimated cost.
/// Deterministic: every rank computes the same plan.
ShardPlan planShards(const Scene& scene, const Parameterisation& param, const BakeSettings& settings, int ranks);

/// The tixels whose visibility rank r traces and keeps: its own, plus the twin records of its
/// rough-glass tixels (a rough-glass record's update gathers its twin's light too).
std::vector<TixelRange> visibilityRanges(const Scene& scene, const Parameterisation& param, const ShardPlan& plan, int rank);

/// The split of the parameterisation's per-tixel setup (fillTixels) between ranks: ranks + 1
/// record boundaries, rank r filling chart records [result[r], result[r + 1]), contiguous runs
/// of about equal estimated cost. A record costs its tixels (each takes 16 footprint
/// sub-samples and, unless specular, a buried-point probe of 9 rays; a specular tixel counts
/// 1/4) plus one. Deterministic: every rank computes the same split.
std::vector<uint32_t> tixelSetupSplit(const Parameterisation& param, int ranks);

/// Items 0 … n − 1 of cumulative cost `prefix` (n + 1 entries, prefix[0] = 0, non-decreasing)
/// split into `ranks` contiguous runs of about equal cost: ranks + 1 boundaries, run r being
/// [result[r], result[r + 1]), each boundary the first item at which the running cost reaches
/// r/ranks of the total.
std::vector<uint32_t> splitByCost(const std::vector<double>& prefix, int ranks);

/// What fillTixelsDistributed measured on this rank.
struct TixelSetupTiming {
  double seconds = 0.0;          ///< filling this rank's records (its share of the divisible work)
  double exchangeSeconds = 0.0;  ///< in the exchange (waiting for the slowest rank included)
};

/// fillTixels over the ranks of `comm`: this rank fills its records of tixelSetupSplit, then
/// each per-tixel array is exchanged (in-place allgathervs, one per windowBytes of the array:
/// the records of a rank are one contiguous run of tixels), so every rank holds the whole
/// parameterisation — the one-process buildParameterisation's bit for bit, since a record's
/// tixels depend only on the record. One rank: fillTixels of every record, no exchange.
/// `param` comes from buildCharts.
TixelSetupTiming fillTixelsDistributed(const Scene& scene, const Accel& accel, Parameterisation& param, Communicator& comm,
                                       uint64_t windowBytes = uint64_t(1) << 30);

/// Rank r's .plv: `path` itself for one rank, else STEM.rankR-of-N.plv beside it.
std::string shardVisibilityPath(const std::string& path, int rank, int ranks);

/// Index in LightField::values of tixel g's first value (valueCount for g = tixelCount).
uint64_t firstValueOf(const Parameterisation& param, uint64_t g);

}  // namespace pl
