// BakeJob (jobs.h): `plenoptic bake` as a library call.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <utility>

#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "jobs/jobs.h"
#include "bake/bake.h"
#include "bake/shard.h"
#include "bake/relight.h"
#include "bake/warm_start.h"
#include "distributed/communicator.h"
#include "plf/compression.h"
#include "plf/plf_file.h"

namespace pl {

std::string BakeJobStats::toJson() const {
  // The bake's own statistics under the keys of the .plf's META (lightfield.h toJson), but
  // `seconds` is the whole job's here and the bake's is `bake_seconds`.
  nlohmann::json json = pl::toJson(bake);
  json["bake_seconds"] = bake.seconds;
  json["visibility_memory"] = bake.visibilityMemory;  // a run's fact, not the light field's: not in META
  json["seconds"] = seconds;
  json["command"] = "bake";
  json["scene"] = scene;
  json["output"] = output;
  json["preset"] = preset;
  json["threads"] = threads;
  json["load_seconds"] = loadSeconds;
  json["charts"] = charts;  // chart records: a two-sided chart counts twice (front and back)
  json["two_sided_charts"] = twoSidedCharts;
  json["back_side_tixels"] = backSideTixels;
  json["sun_mask_lights"] = sunMaskLights;
  json["warm_start"] = warmStart;
  json["warm_start_reason"] = warmStartReason;
  json["curved_charts"] = curvedCharts;  // chart records (a two-sided curved chart counts twice)
  json["curved_tixels"] = curvedTixels;
  json["visibility_rays_per_second"] =
      bake.visibilitySeconds > 0 ? double(bake.visibilityRays) / bake.visibilitySeconds : 0.0;
  json["visibility_file"] = visibilityFile;
  json["file_bytes"] = fileBytes;
  json["compression"] = compression;
  // Distributed bake (docs/user-guide.md, bake --stats): per-rank figures in rank order; the
  // exchange is rank 0's (every rank receives about the same).
  json["ranks"] = distributed.ranks;
  json["batches"] = distributed.batches;
  json["rank_estimated_cost_share"] = distributed.estimatedCost;
  json["setup_seconds"] = distributed.setupSeconds;
  json["rank_tixel_setup_seconds"] = distributed.tixelSetupSeconds;
  json["tixel_setup_exchange_seconds"] = distributed.tixelSetupExchangeSeconds;
  json["rank_visibility_rays"] = distributed.visibilityRays;
  json["rank_visibility_seconds"] = distributed.visibilitySeconds;
  json["rank_propagation_seconds"] = distributed.propagationSeconds;
  json["rank_first_shot_seconds"] = distributed.firstShotSeconds;
  json["rank_gather_seconds"] = distributed.gatherSeconds;
  json["rank_repeated_seconds"] = distributed.repeatedSeconds;
  json["exchange_bytes"] = distributed.exchangeBytes;
  json["exchanges"] = distributed.exchanges;
  json["exchange_seconds"] = distributed.exchangeSeconds;
  return json.dump(2) + "\n";
}

BakeJob::BakeJob(BakeJobOptions options) : options_(std::move(options)) {
  // Every output is checked before the scene is loaded (core/file_io.h): a bake that could
  // not save its results is refused before it traces anything.
  if (!options_.output.empty()) checkOutputPath(options_.output, {".plf"}, "-o");
  visibilityPath_ = options_.visibilityPath;
  if (visibilityPath_.empty() && !options_.output.empty())
    visibilityPath_ = visibilityPathFor(options_.output);
  if (!visibilityPath_.empty()) checkOutputPath(visibilityPath_, {".plv"}, "--visibility");
  if (!options_.statsPath.empty()) checkOutputPath(options_.statsPath, {}, "--stats");
  if (!options_.warmStart.empty()) {
    if (options_.noWarmStart) failUsage("bake: --warm-start and --no-warm-start contradict each other");
    options_.reuseVisibility = true;
  }
  checkDistinctOutputs({{"-o", options_.output}, {"--visibility", visibilityPath_}, {"--stats", options_.statsPath}});
  (void)bakePreset(options_.preset);          // an unknown preset names the known ones
  (void)parseValuesCodec(options_.compress);  // an unknown codec names the known ones
  (void)parseVisibilityMemory(options_.visibilityMemory, "--visibility-memory");
}

BakeSettings BakeJob::settings() const {
  BakeSettings settings = bakePreset(options_.preset);
  if (options_.tixelsAcross > 0.0f) settings.tixelsAcrossScene = options_.tixelsAcross;
  if (options_.gatherDirections > 0) settings.gatherDirections = options_.gatherDirections;
  if (options_.glossyDirRes > 0) settings.glossyDirRes = options_.glossyDirRes;
  if (options_.lightSamples > 0) settings.areaLightSamples = options_.lightSamples;
  settings.sunMasks = options_.sunMasks;
  settings.punctualHighlights = options_.punctualHighlights;
  settings.exactVisibility = options_.exactVisibility;
  if (options_.causticPhotons >= 0) settings.causticPhotons = uint64_t(options_.causticPhotons);
  if (options_.subsurfaceWalks > 0) settings.subsurfaceWalks = options_.subsurfaceWalks;
  if (options_.tolerance > 0.0f) settings.tolerance = options_.tolerance;
  settings.seed = options_.seed;
  return settings;
}

BakeJobResult BakeJob::run(Scene scene) const { return runFrom(std::move(scene), 0.0); }

BakeJobResult BakeJob::run(const std::string& scenePath) const {
  const auto start = SteadyClock::now();
  checkSameJobOnEveryRank(scenePath);
  Scene scene = loadScene(scenePath);
  return runFrom(std::move(scene), secondsSince(start));
}

void BakeJob::checkSameJobOnEveryRank(const std::string& scenePath) const {
  Communicator* comm = options_.communicator;
  if (!comm || comm->size() <= 1) return;
  // The scene file's bytes (the built-in scene's name) and everything that shapes the bake;
  // files the scene refers to are covered later by bake()'s check of the geometry and
  // parameterisation.
  const BakeSettings s = settings();
  uint64_t hash = xxh64(scenePath.data(), scenePath.size());
  if (scenePath != "cornell") {
    const MappedFile file(scenePath);  // (refuses a FIFO or directory: requireRegularFile)
    hash = xxh64(file.bytes().data(), file.bytes().size());
  }
  const std::string shape = fmt::format("{}|{}|{}|{}|{}|{}|{}|{}|{}|{}", options_.preset, s.tixelsAcrossScene,
                                        s.gatherDirections, s.glossyDirRes, s.areaLightSamples, s.tolerance, s.seed,
                                        options_.compress, options_.reuseVisibility, s.causticPhotons);
  hash = xxh64(shape.data(), shape.size(), hash);
  uint64_t rank0Hash = 0;
  const std::string differ = comm->ranksDiffering(hash, rank0Hash);
  if (!differ.empty())
    fail("{}: refused: rank(s) {} of {} have a different scene file or bake settings than rank 0 (hash {:016x} here, "
         "{:016x} on rank 0); every rank must bake the same scene with the same flags",
         scenePath, differ, comm->size(), hash, rank0Hash);
}

BakeJobResult BakeJob::runFrom(Scene scene, double loadSeconds) const {
  const auto start = SteadyClock::now();
  const ThreadPool pool(options_.threads);
  BakeOptions bakeOptions;
  bakeOptions.visibilityPath = visibilityPath_;
  bakeOptions.reuseVisibility = options_.reuseVisibility;
  bakeOptions.resume = !options_.fresh;
  // The propagation checkpoint goes once the .plf is written (below): a bake killed while
  // writing it resumes with nothing left to propagate.
  bakeOptions.removeCheckpoint = false;
  bakeOptions.log = options_.log;
  bakeOptions.maxMemory = options_.maxMemory;
  bakeOptions.visibilityMemory = parseVisibilityMemory(options_.visibilityMemory, "--visibility-memory");
  // A field forced to be held may still fit streamed: say so beside the other ways down.
  const char* lower = bakeOptions.visibilityMemory == VisibilityMemory::held
                          ? "lower --preset, --tixels-across or --directions, or let the visibility field stream from "
                            "its .plv (--visibility-memory auto)"
                          : "lower --preset, --tixels-across or --directions";
  bakeOptions.checkMemory = [limit = options_.maxMemory, lower](uint64_t bytes) {
    requireMemory(bytes, "bake (visibility field and light-field values)", lower, limit);
  };
  bakeOptions.communicator = options_.communicator;
  DistributedBakeStats distributed;
  bakeOptions.distributedStats = &distributed;
  bakeOptions.keepParameterisation = options_.keepParameterisation;
  bakeOptions.keepVisibility = options_.keepVisibility;
  WarmStartOutcome warm;
  std::optional<LightField> warmed;
  if (!options_.reuseVisibility) {
    warm.reason = "the bake does not reuse its visibility field (--reuse-visibility)";
  } else if (options_.noWarmStart) {
    warm.reason = "--no-warm-start";
  } else {
    const std::string& previous = options_.warmStart.empty() ? options_.output : options_.warmStart;
    if (previous.empty()) warm.reason = "there is no previous light field to start from (no output path)";
    else warmed = warmStartBake(scene, settings(), previous, bakeOptions, warm);
  }
  BakeJobResult result{warmed ? std::move(*warmed) : bake(std::move(scene), settings(), bakeOptions), {}};
  const LightField& lf = result.lightField;
  BakeJobStats& stats = result.stats;
  stats.warmStart = warm.used;
  stats.warmStartReason = warm.reason;
  stats.distributed = distributed;
  // Every rank holds the whole light field; rank 0 alone writes it (atomically) and the stats.
  const bool writer = !options_.communicator || options_.communicator->rank() == 0;
  if (writer && !options_.output.empty()) {
    writeLightField(options_.output, lf, parseValuesCodec(options_.compress));
    stats.fileBytes = std::filesystem::file_size(options_.output);
  }
  removePropagationCheckpoint(bakeOptions);
  stats.seconds = loadSeconds + secondsSince(start);
  stats.loadSeconds = loadSeconds;
  stats.scene = options_.sceneName;
  stats.output = options_.output;
  stats.preset = options_.preset;
  stats.visibilityFile = options_.communicator ? shardVisibilityPath(visibilityPath_, options_.communicator->rank(), options_.communicator->size()) : visibilityPath_;
  stats.compression = options_.compress;
  stats.threads = pool.threads();
  stats.bake = lf.stats;
  stats.charts = lf.charts.size();
  for (const Chart& c : lf.charts) {
    stats.twoSidedCharts += c.isBack ? 1 : 0;
    stats.backSideTixels += c.isBack ? c.tixelCount() : 0;
    stats.curvedCharts += c.curved ? 1 : 0;
    stats.curvedTixels += c.curved ? c.tixelCount() : 0;
  }
  stats.sunMaskLights = lf.sunMaskLightCount;
  if (writer && !options_.statsPath.empty()) writeFileAtomically(options_.statsPath, stats.toJson());
  return result;
}

}  // namespace pl
