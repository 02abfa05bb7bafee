#pragma once
// The light-field bake, in three steps: 1. parameterisation (parameterisation.h), 2. visibility
// field (visibility.h), 3. propagation (propagation.h) → LightField (docs/design.md, The
// bake). The .plf file is written by plf_file.h. The quality presets are kBakePresets below.
#include "lightfield/lightfield.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace pl {

class Communicator;
struct Parameterisation;
struct VisibilityShard;

/// A named quality preset. Densities are relative to the scene's room scale (sceneScale,
/// parameterisation.h), so a scene in millimetres and one in metres get the same grids; the
/// other BakeSettings (chart size limit, iteration cap, mirror depth, seed, sun masks) are the
/// same for every preset.
struct BakePresetValues {
  const char* name;
  float tixelsAcrossScene;    ///< tixels across the room scale
  uint32_t gatherDirections;  ///< gather rays per tixel (a square: 12², 16², 24²)
  uint32_t glossyDirRes;      ///< cap on the side of a glossy chart's paraboloid map
  uint32_t areaLightSamples;  ///< shadow rays per tixel towards emissive surfaces
  /// Relative change of total outgoing power at which iteration stops, once the remaining
  /// error estimated from the rate of convergence is below it too (propagation.h).
  float tolerance;
  /// Photons of the caustic pass (caustics.h), shot only when the scene has an emissive
  /// surface and a mirror or smooth glass.
  uint64_t causticPhotons;
  /// Random walks per tixel area of the subsurface operator (subsurface.h).
  uint32_t subsurfaceWalks;
};
/// The presets: the one list of their names and values (bakePreset, bakePresetNames, and
/// through them the jobs, the command line and Python; docs/user-guide.md's table shows it).
inline constexpr BakePresetValues kBakePresets[] = {
    // name     across  gather  glossy  area rays  tolerance  caustic photons       subsurface walks
    {"draft",    20.0f,  144,    8,      16,        5e-3f,     uint64_t(1) << 20,    128},
    {"default",  40.0f,  256,    16,     32,        1e-3f,     uint64_t(1) << 22,    256},
    {"high",     60.0f,  576,    24,     64,        2e-4f,     uint64_t(1) << 24,    1024},
};

/// The settings of a named preset; throws pl::Error listing the names for an unknown one.
BakeSettings bakePreset(const std::string& name);
/// The names of kBakePresets, in order (draft, default, high).
std::vector<std::string> bakePresetNames();

/// What a distributed bake measured (docs/design.md, Distributed bake); one process: ranks 1.
struct DistributedBakeStats {
  int ranks = 1;
  uint64_t ownTixels = 0;           ///< tixels this rank updated (rank 0's in the job's stats)
  uint64_t heldTixels = 0;          ///< tixels of its visibility shard (own + rough-glass twins)
  std::vector<double> estimatedCost;     ///< per rank: its share of the estimated cost (sums to 1)
  double setupSeconds = 0.0;        ///< BVH and charts (buildCharts): work every rank repeats (this rank's)
  std::vector<double> tixelSetupSeconds;  ///< per rank: filling its share of the per-tixel setup (fillTixels)
  double tixelSetupExchangeSeconds = 0.0;  ///< this rank's time in that setup's exchange (waits included)
  std::vector<uint64_t> visibilityRays;  ///< per rank: rays it traced (0 when it reused its .plv)
  std::vector<double> visibilitySeconds; ///< per rank
  std::vector<double> propagationSeconds;  ///< per rank
  std::vector<double> firstShotSeconds;    ///< per rank: of propagationSeconds, the first shot
  std::vector<double> gatherSeconds;       ///< per rank: of propagationSeconds, in gatherIteration
  std::vector<double> repeatedSeconds;     ///< per rank: of propagationSeconds, the per-iteration work on all tixels
  uint64_t batches = 0;             ///< propagation batches (one exchange each per iteration)
  uint64_t exchangeBytes = 0;       ///< received by this rank over the propagation
  uint64_t exchanges = 0;           ///< allgatherv calls (one per batch per iteration, plus the first shot's)
  double exchangeSeconds = 0.0;     ///< this rank's time inside the exchanges (waits included)
};

/// Where the propagation reads the visibility field from (docs/design.md, Visibility field).
enum class VisibilityMemory {
  automatic,  ///< held when the bake's estimate with it held fits the memory (and maxMemory), else streamed
  held,       ///< in memory (compact entries)
  streamed,   ///< from its .plv, a block at a time (needs a visibilityPath)
};
/// The name of a mode ("auto", "held", "streamed") and back; parseVisibilityMemory throws
/// pl::UsageError naming `option` and the choices for anything else.
const char* visibilityMemoryName(VisibilityMemory mode);
VisibilityMemory parseVisibilityMemory(const std::string& text, const std::string& option);

struct BakeOptions {
  /// Where the visibility field is saved (and looked for with reuseVisibility); empty = not saved.
  std::string visibilityPath;
  /// Reuse visibilityPath when it exists and its hash matches this scene and settings.
  bool reuseVisibility = false;
  /// Resume from the scratch files that an interrupted bake left beside visibilityPath
  /// (resume.h: the partial field, the propagation checkpoint) when they match this bake;
  /// false: trace and propagate afresh (`bake --fresh`). Nothing is saved or resumed without
  /// a visibilityPath.
  bool resume = true;
  /// Remove the propagation checkpoint when the bake returns (false: the caller removes it
  /// with removePropagationCheckpoint once it has written the light field, so that a bake
  /// killed while writing it resumes at once).
  bool removeCheckpoint = true;
  /// Receives one-line notes for the user (reuse decisions, rates). May be empty.
  std::function<void(const std::string&)> log;
  /// Called once the parameterisation is known, before the visibility field and the values
  /// are allocated, with bakeMemoryEstimate() of this bake; may throw to refuse it (the
  /// command line calls requireMemory, core/memory.h). May be empty.
  std::function<void(uint64_t bytes)> checkMemory;
  /// The most memory the bake may plan to use (`--max-memory`; 0 = the available memory
  /// alone): bounds, beside the estimate, what the propagation may spend on holding the
  /// visibility field decoded (VisibilityShard::holdDecoded; checkMemory does the refusing).
  uint64_t maxMemory = 0;
  /// Whether the visibility field is held in memory or streamed from its .plv (`bake
  /// --visibility-memory`); automatic streams only when holding it does not fit.
  VisibilityMemory visibilityMemory = VisibilityMemory::automatic;
  /// The ranks of a distributed bake (distributed/communicator.h); null = one process. Every
  /// rank calls bake() with the same scene and settings (refused otherwise, before any ray is
  /// traced); each traces and saves its shard of the visibility field (visibilityPath becomes
  /// shardVisibilityPath, shard.h) and every rank returns the whole light field.
  Communicator* communicator = nullptr;
  /// Receives what the distributed bake measured. May be null.
  DistributedBakeStats* distributedStats = nullptr;
  /// Receive the parameterisation and the visibility field (this rank's shard) instead of
  /// their being freed: what relighting needs in memory (relight.h). May be null.
  Parameterisation* keepParameterisation = nullptr;
  VisibilityShard* keepVisibility = nullptr;
};

/// Bytes of the bake's large arrays for this parameterisation and these settings: the
/// visibility field (its encoded entries, per-tixel offsets and extra records: visibilityBytes-
/// PerTixel per held tixel, measured by estimateVisibilityBytesPerTixel, times
/// kVisibilityEstimateMargin; 0 = not measured: 8 bytes per entry) with the .plv writer's
/// buffers (visibilityWriteBufferBytes) and, during propagation, three arrays of RGB values
/// (current, first shot, previous iteration) and a 64-byte transport quad plus a 4-byte change
/// per tixel. What the bake allocates after the check: the scene and the BVH, already resident
/// then, are not in it.
/// visibilityTixels: the tixels of the field this process holds (a rank's shard); 0 = all.
/// streamed: the field is streamed (VisibilityMemory::streamed): visibilityBytesPerTixel is
/// then what it holds of it (VisibilityBytesPerTixel::streamed; 0: 16 bytes, the extra records'
/// offsets and a few records), and the readers' and the writer's block buffers are added
/// (visibilityStreamBufferBytes).
uint64_t bakeMemoryEstimate(uint64_t tixels, uint64_t values, const BakeSettings& settings, uint64_t visibilityTixels = 0,
                            double visibilityBytesPerTixel = 0.0, bool streamed = false);
/// Bytes a streamed field's readers and writer hold: a few entry blocks per thread of the
/// parallel loops (parallelThreads: the block each gather task reads, a rough-glass twin's, the
/// frames written out of order).
uint64_t visibilityStreamBufferBytes(uint32_t gridSide);
/// Margin on a visibility field's size measured on a sample: the sample's tixels are spread
/// evenly, but what they see varies from chart to chart.
inline constexpr double kVisibilityEstimateMargin = 1.15;

/// What the propagation may spend on holding the visibility field decoded, 8 bytes per entry
/// (VisibilityShard::holdDecoded: the gather then skips decoding each tixel in every
/// iteration): a quarter of the memory available beyond the bake's estimate `estimate`, and no
/// more than options.maxMemory leaves beside it. The memory guard's estimate stays the compact
/// field's.
uint64_t decodedFieldBudget(uint64_t estimate, const BakeOptions& options);

/// Removes the propagation checkpoint (resume.h) of a bake with these options (every rank's
/// own, for a distributed bake), if there is one.
void removePropagationCheckpoint(const BakeOptions& options);

/// Bakes `scene` (moved into the result). Throws pl::Error on failures.
LightField bake(Scene scene, const BakeSettings& settings, const BakeOptions& options = {});

}  // namespace pl
