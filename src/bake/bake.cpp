// The bake driver and its presets (see bake.h).
#include "bake/bake.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <future>
#include <optional>

#include "accel/accel.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "bake/first_shot.h"
#include "bake/parameterisation.h"
#include "bake/propagation.h"
#include "bake/resume.h"
#include "bake/shard.h"
#include "bake/subsurface.h"
#include "bake/visibility.h"
#include "distributed/communicator.h"

namespace pl {

BakeSettings bakePreset(const std::string& name) {
  const BakePresetValues* preset = nullptr;
  for (const BakePresetValues& p : kBakePresets)
    if (name == p.name) preset = &p;
  if (!preset) fail("unknown bake preset '{}' (choose {})", name, alternatives(bakePresetNames()));
  BakeSettings s;
  s.preset = name;
  s.tixelsPerUnit = 0.0f;  // density from the scene's room scale (sceneScale)
  s.tixelsAcrossScene = preset->tixelsAcrossScene;
  s.gatherDirections = preset->gatherDirections;
  s.glossyDirRes = preset->glossyDirRes;
  s.areaLightSamples = preset->areaLightSamples;
  s.tolerance = preset->tolerance;
  s.causticPhotons = preset->causticPhotons;
  s.subsurfaceWalks = preset->subsurfaceWalks;
  s.maxTixelsPerChartSide = 16384;
  s.maxIterations = 200;
  s.mirrorDepth = 256;
  return s;
}

const char* visibilityMemoryName(VisibilityMemory mode) {
  switch (mode) {
    case VisibilityMemory::held: return "held";
    case VisibilityMemory::streamed: return "streamed";
    default: return "auto";
  }
}

VisibilityMemory parseVisibilityMemory(const std::string& text, const std::string& option) {
  for (VisibilityMemory mode : {VisibilityMemory::automatic, VisibilityMemory::held, VisibilityMemory::streamed})
    if (text == visibilityMemoryName(mode)) return mode;
  throw UsageError(fmt::format("{}: unknown value '{}' (choose auto, held or streamed)", option, text));
}

uint64_t visibilityStreamBufferBytes(uint32_t gridSide) {
  // Per thread: two readers (a gather task's and a rough-glass twin's), each a block's frame
  // and content, and as many blocks again waiting in the writer; a block's content is at most
  // the sizes and the largest encodings.
  const uint32_t n = gridSide * gridSide;
  const uint64_t blockBytes = visibilityBlockTixels(n) * (sizeof(uint32_t) + maxEncodedTixelBytes(n));
  return uint64_t(std::max(1, parallelThreads())) * 6 * blockBytes;
}

uint64_t bakeMemoryEstimate(uint64_t tixels, uint64_t values, const BakeSettings& settings, uint64_t visibilityTixels,
                            double visibilityBytesPerTixel, bool streamed) {
  const uint64_t directions = uint64_t(gatherGridSide(settings.gatherDirections)) * gatherGridSide(settings.gatherDirections);
  const uint64_t held = visibilityTixels > 0 ? visibilityTixels : tixels;
  // Unmeasured: 8 bytes per entry (more than the encoding takes but for the rarest fields) and
  // the two per-tixel offsets; streamed, the extra records' offsets and one record per tixel.
  // Measured: the sample's figure with kVisibilityEstimateMargin.
  const uint64_t unmeasured = streamed ? sizeof(uint64_t) + sizeof(VisibilityExtra)
                                       : directions * sizeof(VisibilityEntry) + 2 * sizeof(uint64_t);
  const uint64_t visibility = visibilityBytesPerTixel > 0.0
                                  ? uint64_t(double(held) * visibilityBytesPerTixel * kVisibilityEstimateMargin)
                                  : held * unmeasured;
  constexpr uint64_t kQuadBytes = 64, kChangeBytes = 4, kValueArrays = 3;
  // Writing the .plv compresses it a batch of blocks at a time beside the field; a streamed
  // field is read and written a few blocks per thread at a time.
  const uint32_t side = gatherGridSide(settings.gatherDirections);
  const uint64_t writeBuffers = streamed ? visibilityStreamBufferBytes(side) : visibilityWriteBufferBytes(side);
  // Sun masks: every slot in the parameterisation, then the light field's copy (at most as many).
  const uint64_t sunMasks = settings.sunMasks ? sizeof(SunMaskSlots) * 2 : 0;
  return visibility + writeBuffers + values * kValueArrays * sizeof(Rgb) + tixels * (kQuadBytes + kChangeBytes + sunMasks);
}

std::vector<std::string> bakePresetNames() {
  std::vector<std::string> names;
  for (const BakePresetValues& p : kBakePresets) names.emplace_back(p.name);
  return names;
}

namespace {

using Note = std::function<void(const std::string&)>;

/// Every rank must bake the same geometry, parameterisation and settings (the job compares the
/// scene files first; this also covers the files they reference), or the exchanged values
/// would mean different tixels: refused before any ray is traced.
void requireSameBakeOnEveryRank(Communicator& comm, uint64_t hash, const Scene& scene) {
  if (comm.size() <= 1) return;
  uint64_t rank0Hash = 0;
  const std::string differ = comm.ranksDiffering(hash, rank0Hash);
  if (!differ.empty())
    fail("{}: rank(s) {} of {} have a different scene geometry, parameterisation or settings than rank 0 "
         "(visibility hash {:016x}, rank 0 {:016x}); every rank must bake the same scene",
         scene.sourcePath, differ, comm.size(), hash, rank0Hash);
}

void noteParameterisation(const Note& note, const Parameterisation& param, double setupSeconds,
                          const TixelSetupTiming& tixelSetup, int ranks) {
  uint64_t byKind[3] = {0, 0, 0}, tixelsByKind[3] = {0, 0, 0};
  for (const Chart& c : param.charts) {
    ++byKind[size_t(c.kind)];
    tixelsByKind[size_t(c.kind)] += c.tixelCount();
  }
  note(fmt::format("parameterisation: {} charts ({} diffuse, {} glossy, {} specular), {} tixels ({} diffuse, {} glossy), "
                   "{} values; room scale {:.4g}, tixel size {:.4g} (scene units); BVH and charts {:.2f} s, "
                   "tixels {:.2f} s{}",
                   param.charts.size(), byKind[0], byKind[1], byKind[2], param.tixelCount, tixelsByKind[0],
                   tixelsByKind[1], param.valueCount, param.sceneScale, param.baseTixelSize, setupSeconds,
                   tixelSetup.seconds,
                   ranks > 1 ? fmt::format(" (this rank's share; exchanged in {:.2f} s)", tixelSetup.exchangeSeconds) : ""));
}

/// This rank's share of the bake (shard.h): the tixels whose visibility it holds and those it updates.
struct RankShare {
  std::vector<TixelRange> held;  ///< visibilityRanges: its own tixels and the rough-glass twins they need
  uint64_t heldTixels = 0, ownTixels = 0;
  double totalCost = 0.0;  ///< Σ plan.rankCost (0 for one rank: not estimated)
};

RankShare rankShare(const Scene& scene, const Parameterisation& param, const ShardPlan& plan, int rank, const Note& note) {
  RankShare share;
  share.held = visibilityRanges(scene, param, plan, rank);
  for (const TixelRange& r : share.held) share.heldTixels += r.size();
  for (const TixelRange& r : plan.owned(rank)) share.ownTixels += r.size();
  for (double c : plan.rankCost) share.totalCost += c;
  if (plan.ranks > 1) {
    double largest = 0.0;
    for (double c : plan.rankCost) largest = std::max(largest, c);
    note(fmt::format("distributed: {} ranks, {} batches split by estimated cost (largest share {:.1f} %, even {:.1f} %); "
                     "rank {} updates {} tixels and holds the visibility of {}",
                     plan.ranks, plan.batches(), share.totalCost > 0 ? 100.0 * largest / share.totalCost : 0.0,
                     100.0 / plan.ranks, rank, share.ownTixels, share.heldTixels));
  }
  return share;
}

/// The header of the saved field at `visibilityPath` when `bake --reuse-visibility` may read it
/// (present, of this version); nullopt otherwise (traced, as without the flag). A corrupt file
/// throws pl::Error naming it.
std::optional<VisibilityFileInfo> reusableVisibility(const std::string& visibilityPath) {
  std::error_code ec;
  if (visibilityPath.empty() || !std::filesystem::exists(visibilityPath, ec)) return std::nullopt;
  VisibilityFileInfo info = readVisibilityInfo(visibilityPath);
  if (info.version != kPlvVersion) return std::nullopt;
  return info;
}

/// The tixel setup saved beside the field to reuse (parameterisation.h reuseTixelSetup) into
/// param, from buildCharts: true when it belongs to this field and, after what the scene
/// changed is recomputed, to this scene — when the field's hash then matches (else param's
/// charts are built again: false, the caller fills the tixels). The .plt is then already right.
bool reuseSavedTixelSetup(const Scene& scene, const Accel& accel, const BakeSettings& settings,
                          const VisibilityFileInfo& field, const BakeOptions& options, Parameterisation& param,
                          TixelSetupTiming& timing, const Note& note) {
  const auto start = std::chrono::steady_clock::now();
  const std::string path = tixelSetupPathFor(options.visibilityPath);
  std::string why;
  TixelSetupReuse reuse;
  bool ok = reuseTixelSetup(path, field.hash, scene, accel, param, reuse, &why);
  if (ok && visibilityHash(scene, param, settings) != field.hash) {
    ok = false;
    why = fmt::format("the visibility field {} was traced for other geometry or charts", options.visibilityPath);
  }
  if (!ok) {
    note(fmt::format("tixel setup: filling the tixels, because {}", why));
    param = buildCharts(scene, accel, settings);
    return false;
  }
  timing.seconds = secondsSince(start);
  note(fmt::format("tixel setup: reused {} ({} charts of changed materials filled again, sun masks of {} moved "
                   "lights traced again) in {:.2f} s",
                   path, reuse.chartsFilled, reuse.sunMasksTraced, timing.seconds));
  if (!reuse.unchanged()) writeTixelSetup(path, scene, param, field.hash);
  return true;
}

/// The visibility field (this rank's shard) and the propagation through it.
struct Transport {
  VisibilityShard visibility;
  bool reused = false;  ///< the field was read from options.visibilityPath, not traced
  PropagationResult propagation;
};

}  // namespace

uint64_t decodedFieldBudget(uint64_t estimate, const BakeOptions& options) {
  const std::optional<uint64_t> available = availableMemoryBytes();
  if (!available || *available <= estimate) return 0;
  uint64_t budget = (*available - estimate) / 4;
  if (options.maxMemory > 0) budget = std::min(budget, options.maxMemory > estimate ? options.maxMemory - estimate : 0);
  return budget;
}

namespace {
/// Whether this bake streams its visibility field (options.visibilityMemory): automatic streams
/// when the estimate with the field held exceeds the memory available or options.maxMemory (and
/// there is a .plv to stream from, `visibilityPath`). Says so when it streams.
bool streamVisibility(const BakeOptions& options, const std::string& visibilityPath, uint64_t heldEstimate,
                      uint64_t streamedEstimate, const Note& note) {
  constexpr double kGiB = double(uint64_t(1) << 30);
  if (options.visibilityMemory == VisibilityMemory::held) return false;
  if (options.visibilityMemory == VisibilityMemory::streamed) {
    if (visibilityPath.empty())
      throw UsageError("--visibility-memory streamed: the field is streamed from its .plv, and this bake saves none");
    note(fmt::format("visibility: streamed from {} (--visibility-memory streamed; estimated memory {:.2f} GiB, held "
                     "{:.2f} GiB)",
                     visibilityPath, streamedEstimate / kGiB, heldEstimate / kGiB));
    return true;
  }
  if (visibilityPath.empty()) return false;
  std::optional<uint64_t> limit = availableMemoryBytes();
  if (options.maxMemory > 0) limit = std::min(limit.value_or(options.maxMemory), options.maxMemory);
  if (!limit || heldEstimate <= *limit) return false;
  note(fmt::format("visibility: streamed from {}, because holding it would take the bake to {:.2f} GiB, over the "
                   "{:.2f} GiB {} (streamed: {:.2f} GiB)",
                   visibilityPath, heldEstimate / kGiB, *limit / kGiB,
                   options.maxMemory > 0 && *limit == options.maxMemory ? "of --max-memory" : "available",
                   streamedEstimate / kGiB));
  return true;
}

/// Reads the saved field of `held` into `visibility` (readVisibility's checks; false and *why
/// when it is not this bake's), decoded as it is checked when the budget holds it decoded
/// (VisibilityShard::holdDecoded's rule, without decoding it twice).
bool readHeldField(const std::string& visibilityPath, uint64_t shardHash, const Parameterisation& param,
                   const BakeSettings& settings, const std::vector<TixelRange>& held, uint64_t decodedBudget,
                   bool streamed, VisibilityShard& visibility, std::string* why) {
  uint64_t heldTixels = 0;
  for (const TixelRange& r : held) heldTixels += r.size();
  const uint64_t side = gatherGridSide(settings.gatherDirections);
  const bool hold = !streamed && heldTixels > 0 && heldTixels * side * side * sizeof(VisibilityEntry) <= decodedBudget;
  VisibilityField field;
  std::vector<VisibilityEntry> decoded;
  if (!readVisibility(visibilityPath, shardHash, field, why, param.tixelCount, hold ? &decoded : nullptr, streamed))
    return false;
  visibility = VisibilityShard::of(std::move(field), held);
  if (hold) visibility.decoded = FieldArray<VisibilityEntry>(std::move(decoded));
  return true;
}

/// The checkpoint of an interrupted propagation of this bake (resume.h), read into `checkpoint`
/// with this rank's field when both match it and every rank has them at the same iteration
/// (collective: every rank calls it). Says why not when a checkpoint was there.
bool resumableCheckpoint(const std::string& visibilityPath, uint64_t shardHash, uint64_t key, const Parameterisation& param,
                         const std::vector<TixelRange>& held, bool streamed, Communicator& comm,
                         PropagationCheckpoint& checkpoint, VisibilityShard& visibility, const Note& note) {
  const std::string path = propagationCheckpointPath(visibilityPath);
  std::error_code ec;
  const bool present = std::filesystem::exists(path, ec);
  std::string why;
  bool ok = readPropagationCheckpoint(path, key, param.valueCount, checkpoint, &why);
  VisibilityField field;
  if (ok && !readVisibility(visibilityPath, shardHash, field, &why, param.tixelCount, nullptr, streamed)) ok = false;
  // Every rank must start from the same iteration (the checkpoints of ranks killed at
  // different moments may differ by one).
  const uint64_t mine = ok ? uint64_t(checkpoint.progress.iterations) + 1 : 0;
  for (uint64_t theirs : comm.allgather(mine))
    if (theirs != mine) {
      ok = false;
      if (why.empty()) why = "the ranks' checkpoints are of different iterations";
    }
  if (!ok) {
    if (present) note(fmt::format("propagation: not resuming from {}, because {}", path, why));
    return false;
  }
  visibility = VisibilityShard::of(std::move(field), held);
  note(fmt::format("propagation: resuming the interrupted bake from {} after iteration {}{} (visibility field read "
                   "from {})",
                   path, checkpoint.progress.iterations, checkpoint.progress.converged ? " (converged)" : "",
                   visibilityPath));
  return true;
}

/// Reads the saved field when asked to and it matches `hash`, else traces (and saves) it; and
/// propagates. A saved field is read on its own thread while propagation starts with the
/// shadow rays of the first shot, which do not need it; propagation waits for it after them.
/// With a visibility path, the trace is journalled and the propagation checkpointed so that
/// an interrupted bake resumes (resume.h), from a checkpoint before anything else.
Transport traceAndPropagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const BakeSettings& settings, const BakeOptions& options, Communicator& comm,
                            const ShardPlan& plan, const std::vector<TixelRange>& held, uint64_t hash, uint64_t decodedBudget,
                            bool streamed, bool keepFirstShotBySource, const Note& note) {
  const std::string visibilityPath = shardVisibilityPath(options.visibilityPath, comm.rank(), comm.size());
  const uint64_t shardHash = visibilityShardHash(hash, held, param.tixelCount);
  Transport t;
  PropagationOptions resume;
  resume.keepFirstShotBySource = keepFirstShotBySource;
  PropagationCheckpoint checkpoint;
  if (!visibilityPath.empty()) {
    const std::string checkpointPath = propagationCheckpointPath(visibilityPath);
    const uint64_t key = propagationKey(shardHash, scene, settings);
    const uint64_t stopAfter = testStopAfter("PLENOPTIC_TEST_STOP_AFTER_ITERATIONS");
    resume.save = [checkpointPath, key, stopAfter, saved = uint64_t(0)](const PropagationProgress& at,
                                                                        const TransportState& state) mutable {
      PropagationProgress progress = at;
      progress.key = key;
      writePropagationCheckpoint(checkpointPath, progress, state.direct, state.punctualGlossy, state.current);
      if (stopAfter > 0 && ++saved == stopAfter) std::_Exit(kExitFailure);  // the test hook: "killed" here
    };
    if (options.resume) {
      if (resumableCheckpoint(visibilityPath, shardHash, key, param, held, streamed, comm, checkpoint, t.visibility, note)) {
        resume.from = &checkpoint;
        t.reused = true;
        t.visibility.holdDecoded(decodedBudget);
      }
    } else {
      std::error_code ec;
      if (std::filesystem::exists(checkpointPath, ec))
        note(fmt::format("propagation: ignoring the checkpoint {} (--fresh)", checkpointPath));
      comm.allgather(uint64_t(0));  // (resumableCheckpoint's collective, which every rank calls)
    }
  }
  auto computeAndSave = [&] {
    std::optional<VisibilityJournal> journal;
    if (!visibilityPath.empty()) journal.emplace(partialVisibilityPath(visibilityPath), options.resume, note);
    // Streamed: written to the .plv as it is traced (then read from it), never held.
    t.visibility = computeVisibilityShard(scene, accel, param, settings, held, true, journal ? &*journal : nullptr,
                                          streamed ? visibilityPath : std::string());
    const VisibilityField& f = t.visibility.field;
    note(fmt::format("visibility: {} rays in {:.2f} s ({:.1f} Mrays/s), {:.1f} MB{}", f.rays, f.seconds,
                     f.seconds > 0 ? f.rays / f.seconds * 1e-6 : 0.0, f.bytes() / 1e6,
                     streamed ? fmt::format(" held, entries streamed to {}", visibilityPath) : ""));
    if (!visibilityPath.empty() && !streamed) writeVisibility(visibilityPath, f);
    if (journal) journal->finish();
    t.visibility.holdDecoded(decodedBudget);
  };
  if (resume.from) {
    t.propagation = propagate(scene, accel, param, [&]() -> const VisibilityShard& { return t.visibility; }, settings,
                              comm, plan, resume);
  } else if (options.reuseVisibility && !visibilityPath.empty()) {
    std::string why;
    double readSeconds = 0.0;
    std::future<bool> read = std::async(std::launch::async, [&] {
      const auto readStart = std::chrono::steady_clock::now();
      const bool ok =
          readHeldField(visibilityPath, shardHash, param, settings, held, decodedBudget, streamed, t.visibility, &why);
      readSeconds = secondsSince(readStart);
      return ok;
    });
    t.propagation = propagate(scene, accel, param, [&]() -> const VisibilityShard& {
      t.reused = read.get();
      if (t.reused) {
        note(fmt::format("visibility: reusing {} ({} tixels × {} directions, read in {:.2f} s, overlapping the shadow rays)",
                         visibilityPath, t.visibility.field.tixelCount, t.visibility.field.directionsPerTixel(),
                         readSeconds));
      } else {
        note(fmt::format("visibility: recomputing, because {}", why));
        computeAndSave();
      }
      return t.visibility;
    }, settings, comm, plan, resume);
  } else {
    computeAndSave();
    t.propagation = propagate(scene, accel, param, [&]() -> const VisibilityShard& { return t.visibility; }, settings,
                              comm, plan, resume);
  }
  const PropagationResult& prop = t.propagation;
  note(fmt::format("propagation: {} iterations, residual {:.2e}, {:.2f} s (first shot {:.2f} s, {} shadow rays)",
                   prop.iterations, prop.residual, prop.seconds, prop.firstShotSeconds, prop.shadowRays));
  if (prop.subsurfaceWalks > 0)
    note(fmt::format("subsurface: {} tixels, {} walks{} ({} rays) in {:.2f} s (of the first shot), operator {} entries, "
                     "{:.1f} MB",
                     prop.subsurfaceTixels, prop.subsurfaceWalks,
                     comm.size() > 1 ? fmt::format(", {} of them on rank {}", prop.subsurfaceWalkedHere, comm.rank()) : "",
                     prop.subsurfaceRays, prop.subsurfaceSeconds, prop.subsurfaceEntries, prop.subsurfaceBytes / 1e6));
  if (prop.causticPhotons > 0)
    note(fmt::format("caustics: {} photons, {} reached a diffuse surface through mirrors or glass, {:.2f} s (of the first shot)",
                     prop.causticPhotons, prop.causticPhotonsLanded, prop.causticSeconds));
  return t;
}

/// Every rank's figures, in rank order: collectives, so every rank calls it, in the same order.
DistributedBakeStats gatherDistributedStats(Communicator& comm, const ShardPlan& plan, const RankShare& share,
                                            double setupSeconds, const TixelSetupTiming& tixelSetup,
                                            const Transport& t, const Note& note) {
  const int ranks = comm.size();
  const PropagationResult& prop = t.propagation;
  const uint64_t rays = t.reused ? 0 : t.visibility.field.rays;
  const double visibilitySeconds = t.reused ? 0.0 : t.visibility.field.seconds;
  auto gatherDoubles = [&](double value) {
    std::vector<double> out;
    for (uint64_t bits : comm.allgather(std::bit_cast<uint64_t>(value))) out.push_back(std::bit_cast<double>(bits));
    return out;
  };
  DistributedBakeStats distributed;
  distributed.ranks = ranks;
  distributed.ownTixels = share.ownTixels;
  distributed.heldTixels = share.heldTixels;
  // (One rank: no costs are estimated, its share is the whole.)
  for (double c : plan.rankCost)
    distributed.estimatedCost.push_back(share.totalCost > 0 ? c / share.totalCost : 1.0 / ranks);
  distributed.setupSeconds = setupSeconds;
  distributed.tixelSetupSeconds = gatherDoubles(tixelSetup.seconds);
  distributed.tixelSetupExchangeSeconds = tixelSetup.exchangeSeconds;
  distributed.visibilityRays = comm.allgather(rays);
  distributed.visibilitySeconds = gatherDoubles(visibilitySeconds);
  distributed.propagationSeconds = gatherDoubles(prop.seconds);
  distributed.firstShotSeconds = gatherDoubles(prop.firstShotSeconds);
  distributed.gatherSeconds = gatherDoubles(prop.gatherSeconds);
  distributed.repeatedSeconds = gatherDoubles(prop.repeatedSeconds);
  distributed.batches = plan.batches();
  distributed.exchangeBytes = prop.exchangeBytes;
  distributed.exchanges = comm.exchanges();
  distributed.exchangeSeconds = prop.exchangeSeconds;
  if (ranks > 1)
    note(fmt::format("distributed: rank {} received {:.1f} MB in {} exchanges, {:.2f} s inside them", comm.rank(),
                     prop.exchangeBytes / 1e6, comm.exchanges(), prop.exchangeSeconds));
  return distributed;
}

/// The bake's statistics (lightfield.h BakeStats) but its total time and peak memory, which
/// the caller adds last: visibility time is the slowest rank's, rays are every rank's.
BakeStats bakeStats(const Parameterisation& param, const Transport& t, const DistributedBakeStats& distributed) {
  double slowestVisibility = 0.0;
  uint64_t totalRays = 0;
  for (int r = 0; r < distributed.ranks; ++r) {
    slowestVisibility = std::max(slowestVisibility, distributed.visibilitySeconds[size_t(r)]);
    totalRays += distributed.visibilityRays[size_t(r)];
  }
  BakeStats stats;
  stats.visibilitySeconds = slowestVisibility;
  stats.propagationSeconds = t.propagation.seconds;
  stats.iterations = t.propagation.iterations;
  stats.residual = t.propagation.residual;
  stats.tixels = param.tixelCount;
  stats.values = param.valueCount;
  stats.visibilityRays = totalRays;
  stats.reusedVisibility = t.reused;
  stats.visibilityMemory = t.visibility.streamed() ? "streamed" : "held";
  stats.causticPhotons = t.propagation.causticPhotons;
  stats.causticPhotonsLanded = t.propagation.causticPhotonsLanded;
  stats.causticSeconds = t.propagation.causticSeconds;
  return stats;
}

}  // namespace

void removePropagationCheckpoint(const BakeOptions& options) {
  if (options.visibilityPath.empty()) return;
  const int rank = options.communicator ? options.communicator->rank() : 0;
  const int ranks = options.communicator ? options.communicator->size() : 1;
  std::error_code ec;
  std::filesystem::remove(propagationCheckpointPath(shardVisibilityPath(options.visibilityPath, rank, ranks)), ec);
}

LightField bake(Scene scene, const BakeSettings& settings, const BakeOptions& options) {
  SingleProcess single;
  Communicator& comm = options.communicator ? *options.communicator : single;
  const auto start = std::chrono::steady_clock::now();
  const Note note = [&](const std::string& text) {
    if (options.log) options.log(text);
  };
  LightField lf;
  lf.scene = std::move(scene);
  lf.settings = settings;
  // 1. Parameterisation. The BVH and the charts are per scene: every rank builds them. The
  // per-tixel part (footprints and buried-point probes, most of the time on a large scene) is
  // divided between the ranks and exchanged (shard.h fillTixelsDistributed).
  const Accel accel(lf.scene);
  Parameterisation param = buildCharts(lf.scene, accel, settings);
  const double setupSeconds = secondsSince(start);
  // Reusing the field of one process: its tixel setup too, where it is still this scene's.
  const std::optional<VisibilityFileInfo> reusable =
      comm.size() == 1 && options.reuseVisibility ? reusableVisibility(options.visibilityPath) : std::nullopt;
  TixelSetupTiming tixelSetup;
  const bool setupReused = reusable && reuseSavedTixelSetup(lf.scene, accel, settings, *reusable, options, param,
                                                            tixelSetup, note);
  if (!setupReused) tixelSetup = fillTixelsDistributed(lf.scene, accel, param, comm);
  const uint64_t hash = visibilityHash(lf.scene, param, settings);
  requireSameBakeOnEveryRank(comm, hash, lf.scene);
  noteParameterisation(note, param, setupSeconds, tixelSetup, comm.size());
  const ShardPlan plan = planShards(lf.scene, param, settings, comm.size());
  const RankShare share = rankShare(lf.scene, param, plan, comm.rank(), note);
  // How many bytes the field will take: the saved field's, when it is this bake's, else traced
  // ahead on a sample of the held tixels.
  VisibilityBytesPerTixel bytesPerTixel;
  if (reusable && reusable->hash == hash && reusable->tixelCount == param.tixelCount && reusable->heldBytes > 0) {
    const double tixels = double(reusable->tixelCount);
    bytesPerTixel.held = double(reusable->heldBytes) / tixels;
    bytesPerTixel.streamed = double(reusable->heldBytes - reusable->entryBytes - kEntryBytesPadding) / tixels - sizeof(uint64_t);
  } else {
    bytesPerTixel = estimateVisibilityBytesPerTixel(lf.scene, accel, param, settings, share.held);
  }
  const uint64_t subsurfaceBytes = subsurfaceOperatorBytesEstimate(lf.scene, param, settings.subsurfaceWalks, comm.size());
  const uint64_t heldEstimate =
      bakeMemoryEstimate(param.tixelCount, param.valueCount, settings, share.heldTixels, bytesPerTixel.held) + subsurfaceBytes;
  const uint64_t streamedEstimate = bakeMemoryEstimate(param.tixelCount, param.valueCount, settings, share.heldTixels,
                                                       bytesPerTixel.streamed, true) +
                                    subsurfaceBytes;
  const bool streamed = streamVisibility(options, shardVisibilityPath(options.visibilityPath, comm.rank(), comm.size()),
                                         heldEstimate, streamedEstimate, note);
  const uint64_t estimate = streamed ? streamedEstimate : heldEstimate;
  if (options.checkMemory) options.checkMemory(estimate);

  // 2. Visibility field and 3. propagation. One process saving its field keeps the first shot
  // by source for the .pls (below) when it fits the memory left beside the estimate: from the
  // budget the decoded field would otherwise get.
  uint64_t decodedBudget = decodedFieldBudget(estimate, options);
  const uint64_t bySourceBytes =
      (lf.scene.lights.size() * (settings.punctualHighlights ? 2 : 1) + 1) * param.valueCount * sizeof(Rgb);
  const bool keepBySource = comm.size() == 1 && !options.visibilityPath.empty() && bySourceBytes <= decodedBudget;
  if (keepBySource) decodedBudget -= bySourceBytes;
  else if (comm.size() == 1 && !options.visibilityPath.empty() && !lf.scene.lights.empty())
    note(fmt::format("first shot by source: not kept ({:.1f} MB would not fit beside the bake), so no {} is written",
                     bySourceBytes / 1e6, firstShotPathFor(options.visibilityPath)));
  Transport transport = traceAndPropagate(lf.scene, accel, param, settings, options, comm, plan, share.held, hash,
                                          decodedBudget, streamed, keepBySource, note);
  DistributedBakeStats distributed =
      gatherDistributedStats(comm, plan, share, setupSeconds, tixelSetup, transport, note);

  // The tixel setup beside the visibility field, so that relighting the saved light field
  // does not fill the tixels again (relight.h). One process only: a distributed bake's field is
  // saved in shards, which relighting does not read.
  if (comm.size() == 1 && !options.visibilityPath.empty() && !setupReused) {
    const auto writeStart = std::chrono::steady_clock::now();
    const std::string path = tixelSetupPathFor(options.visibilityPath);
    writeTixelSetup(path, lf.scene, param, hash);
    note(fmt::format("tixel setup: {} ({:.1f} MB) in {:.2f} s", path, double(std::filesystem::file_size(path)) / 1e6,
                     secondsSince(writeStart)));
  }
  // The first shot by source beside it (bake/first_shot.h), so that a warm-started re-bake
  // reads it instead of shooting again. A bake resumed from a propagation checkpoint has only
  // the summed first shot: without scene lights that is the whole D_e, else there is no file.
  std::optional<FirstShotBySource>& shot = transport.propagation.firstShotBySource;
  if (!shot && comm.size() == 1 && !options.visibilityPath.empty() && lf.scene.lights.empty() &&
      transport.propagation.direct.size() == param.valueCount) {
    shot.emplace();
    shot->emitterDirect = std::move(transport.propagation.direct);
  }
  if (shot) {
    const auto writeStart = std::chrono::steady_clock::now();
    const std::string path = firstShotPathFor(options.visibilityPath);
    writeFirstShot(path, hash, firstShotKey(lf.scene, param, settings, hash), *shot);
    note(fmt::format("first shot by source: {} ({:.1f} MB) in {:.2f} s", path,
                     double(std::filesystem::file_size(path)) / 1e6, secondsSince(writeStart)));
    shot.reset();
  } else if (comm.size() == 1 && !options.visibilityPath.empty()) {
    std::error_code ec;  // a stale one would be ignored by its key; removing it keeps the folder true
    std::filesystem::remove(firstShotPathFor(options.visibilityPath), ec);
  }
  storeLightField(lf, param, std::move(transport.propagation.values));
  lf.stats = bakeStats(param, transport, distributed);
  lf.stats.seconds = secondsSince(start);
  lf.stats.peakRssBytes = peakRssBytes();
  if (options.distributedStats) *options.distributedStats = std::move(distributed);
  if (options.keepParameterisation) *options.keepParameterisation = std::move(param);
  if (options.keepVisibility) *options.keepVisibility = std::move(transport.visibility);
  if (options.removeCheckpoint) removePropagationCheckpoint(options);
  return lf;
}

}  // namespace pl
