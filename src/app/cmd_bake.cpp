// `plenoptic bake SCENE -o OUT.plf`: the light-field bake (src/lightfield/bake.h).
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/memory.h"
#include "core/timing.h"
#include "lightfield/bake.h"
#include "lightfield/compression.h"
#include "lightfield/plf_file.h"
#include "scene/scene.h"

namespace pl {
namespace {

struct BakeCommandOptions {
  std::string scene;            ///< `cornell`, .obj, .gltf/.glb, .json
  std::string output;           ///< .plf
  std::string preset = "default";
  bool reuseVisibility = false;
  std::string visibilityPath;   ///< default: OUT with extension .plv
  std::string statsPath;
  // Overrides of single preset values (0 / negative = keep the preset's).
  float tixelsAcross = 0.0f;
  uint32_t gatherDirections = 0;
  uint32_t lightSamples = 0;
  float tolerance = 0.0f;
  std::string compress = "none";  ///< how the values are stored: none|lossless|bc1|hdr (compression.h)
};

void runBake(const BakeCommandOptions& options, const GlobalOptions& global) {
  Runtime runtime(global);
  const auto start = std::chrono::steady_clock::now();
  // Every output is checked before the scene is loaded (core/file_io.h): a bake that could
  // not save its results is refused before it traces anything.
  if (options.output.empty()) failUsage("bake: an output file is required (-o OUT.plf)");
  checkOutputPath(options.output, {".plf"}, "-o");
  const std::string visibilityPath =
      options.visibilityPath.empty() ? std::filesystem::path(options.output).replace_extension(".plv").string()
                                     : options.visibilityPath;
  checkOutputPath(visibilityPath, {".plv"}, "--visibility");
  if (!options.statsPath.empty()) checkOutputPath(options.statsPath, {}, "--stats");
  checkDistinctOutputs({{"-o", options.output}, {"--visibility", visibilityPath}, {"--stats", options.statsPath}});

  BakeSettings settings = bakePreset(options.preset);
  if (options.tixelsAcross > 0.0f) settings.tixelsAcrossScene = options.tixelsAcross;
  if (options.gatherDirections > 0) settings.gatherDirections = options.gatherDirections;
  if (options.lightSamples > 0) settings.areaLightSamples = options.lightSamples;
  if (options.tolerance > 0.0f) settings.tolerance = options.tolerance;
  settings.seed = global.seed;

  Scene scene = loadScene(options.scene);
  BakeOptions bakeOptions;
  bakeOptions.visibilityPath = visibilityPath;
  bakeOptions.reuseVisibility = options.reuseVisibility;
  bakeOptions.log = [&](const std::string& line) {
    if (!global.quiet) fmt::print(stderr, "{}\n", line);
  };
  bakeOptions.checkMemory = [](uint64_t bytes) {
    requireMemory(bytes, "bake (visibility field and light-field values)",
                  "lower --preset, --tixels-across or --directions");
  };
  LightField lf = bake(std::move(scene), settings, bakeOptions);
  writeLightField(options.output, lf, PlfEncoding(uint32_t(parseValuesCodec(options.compress))));
  const uint64_t fileBytes = std::filesystem::file_size(options.output);
  const double seconds = secondsSince(start);
  const BakeStats& s = lf.stats;

  if (!options.statsPath.empty()) {
    nlohmann::json json;
    json["command"] = "bake";
    json["scene"] = options.scene;
    json["output"] = options.output;
    json["preset"] = settings.preset;
    json["threads"] = runtime.threads();
    json["seconds"] = seconds;
    json["bake_seconds"] = s.seconds;
    json["visibility_seconds"] = s.visibilitySeconds;
    json["propagation_seconds"] = s.propagationSeconds;
    json["iterations"] = s.iterations;
    json["residual"] = s.residual;
    json["tixels"] = s.tixels;
    json["values"] = s.values;
    json["charts"] = lf.charts.size();  // chart records: a two-sided chart counts twice (front and back)
    uint64_t twoSided = 0, backTixels = 0;
    for (const Chart& c : lf.charts) {
      twoSided += c.isBack ? 1 : 0;
      backTixels += c.isBack ? c.tixelCount() : 0;
    }
    json["two_sided_charts"] = twoSided;
    json["back_side_tixels"] = backTixels;
    json["visibility_rays"] = s.visibilityRays;
    json["visibility_rays_per_second"] = s.visibilitySeconds > 0 ? double(s.visibilityRays) / s.visibilitySeconds : 0.0;
    json["reused_visibility"] = s.reusedVisibility;
    json["visibility_file"] = visibilityPath;
    json["peak_rss_bytes"] = s.peakRssBytes;
    json["file_bytes"] = fileBytes;
    json["compression"] = options.compress;
    writeFileAtomically(options.statsPath, json.dump(2) + "\n");
  }
  fmt::print("wrote {} ({} charts, {} tixels, {} values, {:.1f} MB; {} iterations, residual {:.2e}; {:.2f} s)\n",
             options.output, lf.charts.size(), s.tixels, s.values, fileBytes / 1e6, s.iterations, s.residual, seconds);
}

}  // namespace

void addBakeCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<BakeCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "bake", "Precompute the scene's light field (charts, visibility field, propagation) into a .plf file");
  command->add_option("scene", options->scene, "cornell, or a scene file (.obj, .gltf, .glb, .json)")->required();
  command->add_option("-o,--output", options->output, "Output light field (.plf)")->required();
  command->add_option("--preset", options->preset, "Quality preset")
      ->check(CLI::IsMember({"draft", "default", "high"}))
      ->capture_default_str();
  command->add_flag("--reuse-visibility", options->reuseVisibility,
                    "Reuse the saved visibility field if geometry, parameterisation and settings are unchanged "
                    "(checked by hash); otherwise recompute it and say why");
  command->add_option("--visibility", options->visibilityPath,
                      "Where the visibility field is saved/looked for (default: OUT with extension .plv)");
  command->add_option("--stats", options->statsPath, "Write timings and counts as JSON");
  command->add_option("--compress", options->compress,
                      "How the values are stored: none (float32), lossless (bit-exact), bc1 (S3TC), hdr (log codes)")
      ->check(CLI::IsMember({"none", "lossless", "bc1", "hdr"}))
      ->capture_default_str();
  command->add_option("--tixels-across", options->tixelsAcross,
                      "Override the preset: tixels across the scene's room scale (see the README)")
      ->check(CLI::Range(1.0f, 4096.0f));
  command->add_option("--directions", options->gatherDirections,
                      "Override the preset: gather directions per tixel (rounded to a square)")
      ->check(CLI::Range(1u, 65536u));
  command->add_option("--light-samples", options->lightSamples,
                      "Override the preset: shadow rays per tixel towards emissive surfaces")
      ->check(CLI::Range(1u, 65536u));
  command->add_option("--tolerance", options->tolerance,
                      "Override the preset: relative change of total power at which iteration stops")
      ->check(CLI::Range(1e-9f, 1.0f));
  command->callback([options, &global] { runBake(*options, global); });
}

}  // namespace pl
