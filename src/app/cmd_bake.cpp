// `plenoptic bake SCENE -o OUT.plf`: the light-field bake (src/bake/bake.h) through BakeJob
// (src/jobs/jobs.h): flags → job → printed summary.
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <string>
#include <utility>

#include "app/commands.h"
#include "bake/bake.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/progress.h"
#include "distributed/communicator.h"
#include "jobs/jobs.h"

namespace pl {
namespace {

void runBake(const BakeJobOptions& options, const GlobalOptions& global, Communicator& comm) {
  // Ranks other than 0 stay quiet (no bars, no notes): rank 0 speaks for the job.
  const bool speaker = comm.rank() == 0;
  applyGlobalOptions(global);
  if (!speaker) Progress::setEnabled(false);
  if (options.output.empty()) failUsage("bake: an output file is required (-o OUT.plf)");
  BakeJobOptions jobOptions = options;
  jobOptions.seed = global.seed;
  jobOptions.threads = global.threads;
  jobOptions.log = [&](const std::string& line) {
    if (!global.quiet && speaker) fmt::print(stderr, "{}\n", line);
  };
  jobOptions.communicator = &comm;
  const BakeJob job(std::move(jobOptions));  // checks every output before the scene is loaded
  const BakeJobResult result = job.run(options.sceneName);
  const BakeJobStats& stats = result.stats;
  const BakeStats& s = stats.bake;
  if (!speaker) return;
  fmt::print("wrote {} ({} charts, {} tixels, {} values, {:.1f} MB; {} iterations, residual {:.2e}; {:.2f} s)\n",
             options.output, stats.charts, s.tixels, s.values, stats.fileBytes / 1e6, s.iterations, s.residual,
             stats.seconds);
}

/// `plenoptic bake` in one process, or as one rank of `mpirun -np N plenoptic bake ...`
/// (distributed/communicator.h). A rank that fails ends the whole job: it reports its error
/// and aborts every rank (mpirun then exits non-zero), so nothing is left waiting in an
/// exchange and rank 0 writes no .plf.
void runBakeCommand(const BakeJobOptions& options, const GlobalOptions& global) {
  std::unique_ptr<Communicator> comm = makeCommunicator();
  if (comm->size() == 1) return runBake(options, global, *comm);
  try {
    runBake(options, global, *comm);
  } catch (const std::exception& e) {
    fmt::print(stderr, "plenoptic: error: rank {} of {}: {}\n", comm->rank(), comm->size(),
               dynamic_cast<const Error*>(&e) ? e.what() : fmt::format("internal error: {}", e.what()));
    std::fflush(stderr);
    comm->abort(kExitFailure);
  }
}

}  // namespace

void addBakeCommand(CLI::App& app, const GlobalOptions& global) {
  // The flags are bound to the job's options; sceneName is the scene loaded.
  auto options = std::make_shared<BakeJobOptions>();
  CLI::App* command = app.add_subcommand(
      "bake", "Precompute the scene's light field (charts, visibility field, propagation) into a .plf file");
  command->add_option("scene", options->sceneName, "cornell, or a scene file (.obj, .gltf, .glb, .json)")->required();
  command->add_option("-o,--output", options->output, "Output light field (.plf)")->required();
  command->add_option("--preset", options->preset, "Quality preset")
      ->check(CLI::IsMember(bakePresetNames()))
      ->capture_default_str();
  command->add_flag("--reuse-visibility", options->reuseVisibility,
                    "Reuse the saved visibility field if geometry, parameterisation and settings are unchanged "
                    "(checked by hash); otherwise recompute it and say why");
  command->add_option("--warm-start", options->warmStart,
                      "With --reuse-visibility: the previous light field (.plf, baked with the reused .plv) to relight "
                      "instead of propagating from zero, when the scene changed only in lights, emission, environment "
                      "or Lambertian albedo (default: the one at -o, if any; implies --reuse-visibility)");
  command->add_flag("--no-warm-start", options->noWarmStart,
                    "With --reuse-visibility: always propagate from zero (the light field a full bake gives, bit for "
                    "bit; a warm start is within the bake's tolerance of it)");
  command->add_flag("--fresh", options->fresh,
                    "Start afresh: ignore the partial visibility field and propagation checkpoint that an interrupted "
                    "bake left beside the .plv (by default a matching one is resumed)");
  command->add_option("--visibility", options->visibilityPath,
                      "Where the visibility field is saved/looked for (default: OUT with extension .plv)");
  command
      ->add_option_function<std::string>(
          "--max-memory", [options](const std::string& s) { options->maxMemory = parseMemorySize(s, "--max-memory"); },
          "The most memory the bake may plan to use, e.g. 12G or 800M: a bake whose estimate exceeds it (or the "
          "available memory) is refused before it starts")
      ->type_name("SIZE");
  command->add_option("--visibility-memory", options->visibilityMemory,
                      "Where the propagation reads the visibility field: held (in memory), streamed (from the .plv, a "
                      "block at a time: far less memory) or auto (streamed only when holding it does not fit the "
                      "available memory or --max-memory; see docs/user-guide.md)")
      ->check(CLI::IsMember({"auto", "held", "streamed"}))
      ->capture_default_str();
  command->add_option("--stats", options->statsPath, "Write timings and counts as JSON");
  command->add_option("--compress", options->compress,
                      "How the values are stored: none (float32, bit for bit; every section raw), lossless (bit-exact), "
                      "bc1 (S3TC), hdr (log codes, ≤ 0.54% per value); all but none also zstd the other sections")
      ->check(CLI::IsMember({"none", "lossless", "bc1", "hdr"}))
      ->capture_default_str();
  command->add_option("--tixels-across", options->tixelsAcross,
                      "Override the preset: tixels across the scene's room scale (see docs/user-guide.md)")
      ->check(CLI::Range(1.0f, 4096.0f));
  command->add_option("--directions", options->gatherDirections,
                      "Override the preset: gather directions per tixel (rounded to a square)")
      ->check(CLI::Range(1u, 65536u));
  command->add_option("--glossy-res", options->glossyDirRes,
                      "Override the preset: the largest paraboloid map (texels across) of a glossy chart (twice that for a strong narrow lobe)")
      ->check(CLI::Range(2u, 256u));
  command->add_option("--light-samples", options->lightSamples,
                      "Override the preset: shadow rays per tixel towards emissive surfaces")
      ->check(CLI::Range(1u, 65536u));
  command->add_option("--caustic-photons", options->causticPhotons,
                      "Override the preset: photons shot from emissive surfaces through mirrors and glass onto diffuse "
                      "surfaces (caustics; 0 = none, the gather finds that light; see docs/user-guide.md)")
      ->check(CLI::Range(int64_t(0), int64_t(1) << 32));
  command->add_option("--subsurface-walks", options->subsurfaceWalks,
                      "Override the preset: random walks per tixel area that carry light through subsurface objects")
      ->check(CLI::Range(1u, 65536u));
  command->add_option("--tolerance", options->tolerance,
                      "Override the preset: relative change of total power at which iteration stops")
      ->check(CLI::Range(1e-9f, 1.0f));
  command
      ->add_option_function<std::string>(
          "--sun-masks", [options](const std::string& s) { options->sunMasks = s == "on"; },
          "Sub-tixel visibility masks for directional lights (sharp sun shadows; see docs/user-guide.md): on|off")
      ->check(CLI::IsMember({"on", "off"}))
      ->default_str("on");
  command
      ->add_option_function<std::string>(
          "--punctual-highlights", [options](const std::string& s) { options->punctualHighlights = s == "on"; },
          "Point, spot and directional lights' highlights on glossy surfaces evaluated per pixel by the renderers "
          "(off: kept in the glossy maps; see docs/user-guide.md): on|off")
      ->check(CLI::IsMember({"on", "off"}))
      ->default_str("on");
  command
      ->add_option_function<std::string>(
          "--visibility-precision", [options](const std::string& s) { options->exactVisibility = s == "exact"; },
          "The visibility field's bilinear fractions: compact (2 bits each: under half the memory, light field "
          "within relMSE 1e-6) or exact (16 bits, as traced; see docs/user-guide.md): compact|exact")
      ->check(CLI::IsMember({"compact", "exact"}))
      ->default_str("compact");
  command->callback([options, &global] { runBakeCommand(*options, global); });
}

}  // namespace pl
