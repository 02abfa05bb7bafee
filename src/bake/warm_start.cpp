// A re-bake warm-started from the previous light field (see warm_start.h).
#include "bake/warm_start.h"

#include <filesystem>
#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "bake/first_shot.h"
#include "bake/parameterisation.h"
#include "bake/visibility.h"
#include "core/cancel.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/timing.h"
#include "distributed/communicator.h"
#include "plf/plf_file.h"

namespace pl {
namespace {

/// Materials whose tixel setup the relit parameterisation holds other than fillTixels would
/// fill it for `after`: a changed Lambertian albedo (relight.h scales a textured one's
/// footprint means), or emission switched on or off (the setup's keys record it).
std::vector<uint32_t> staleMaterials(const Scene& before, const Scene& after) {
  std::vector<uint32_t> stale;
  for (uint32_t m = 0; m < before.materials.size() && m < after.materials.size(); ++m) {
    const Material &a = before.materials[m], &b = after.materials[m];
    const auto* la = std::get_if<LambertBsdf>(&a.bsdf);
    const auto* lb = std::get_if<LambertBsdf>(&b.bsdf);
    const bool albedo = la && lb && la->albedo != lb->albedo;
    if (albedo || a.isEmissive() != b.isEmissive()) stale.push_back(m);
  }
  return stale;
}

/// The relit light field, or throws pl::Error saying why the previous one cannot serve.
LightField relightPrevious(Scene& scene, const BakeSettings& settings, const std::string& previousPath,
                           const BakeOptions& options, WarmStartOutcome& outcome) {
  const auto start = SteadyClock::now();
  std::error_code ec;
  if (!std::filesystem::exists(previousPath, ec)) fail("there is no previous light field at {}", previousPath);
  const LightField previous = readLightField(previousPath);
  const nlohmann::json before = toJson(previous.settings), now = toJson(settings);
  if (before != now) {
    std::string differ;
    for (const auto& [key, value] : now.items())
      if (!before.contains(key) || before[key] != value)
        differ += fmt::format("{}{} {} (was {})", differ.empty() ? "" : ", ", key, value.dump(),
                              before.contains(key) ? before[key].dump() : "unset");
    fail("{} was baked with other settings: {}", previousPath, differ);
  }
  // The Relighter holds what the bake holds (the visibility field counted at 8 bytes per
  // entry: no sample measured here) and the first shot of every source (relight.h).
  const uint64_t perSource = 2 * previous.values.size() * sizeof(Rgb);
  const uint64_t estimate = bakeMemoryEstimate(previous.stats.tixels, previous.values.size(), settings) +
                            (previous.scene.lights.size() + 1) * perSource;
  if (options.checkMemory) options.checkMemory(estimate);
  Relighter relighter(previous, options.visibilityPath, options.log, decodedFieldBudget(estimate, options));
  // What setScene does not compare: the meshes' attributes and the textures' texels (key 0 of
  // the tixel setup), which the relit charts were filled from.
  const Parameterisation& param = relighter.parameterisation();
  if (tixelSetupKeys(scene, param).at(0) != tixelSetupKeys(relighter.scene(), param).at(0))
    fail("the meshes' normals, uvs or vertex colours or the textures differ from {}'s", previousPath);
  relighter.setScene(scene);  // refuses, with the reason, what the field does not serve
  outcome.setupSeconds = secondsSince(start);
  const bool sourcesChange = relighter.pending();
  outcome.relight = relighter.relight();
  // The first shot by source of the new scene beside the .plv, for the next re-bake (first_shot.h):
  // unless it is the one just read (nothing changed). A cache: a failure to write is a note.
  if (!outcome.relight.cancelled && (sourcesChange || !relighter.firstShotRead())) {
    try {
      relighter.saveFirstShot(firstShotPathFor(options.visibilityPath));
    } catch (const Error& e) {
      if (options.log) options.log(fmt::format("warm start: the first shot by source was not saved: {}", e.what()));
    }
  }
  LightField lf = relighter.lightField();
  // The .plt beside the .plv now describes the relit parameterisation (what a Relighter of
  // the new light field reads); the charts it holds other than fillTixels would are marked.
  writeTixelSetup(tixelSetupPathFor(options.visibilityPath), scene, param, visibilityHash(scene, param, settings),
                  staleMaterials(previous.scene, scene));
  lf.scene = std::move(scene);
  BakeStats& stats = lf.stats;
  stats = BakeStats{};
  stats.tixels = param.tixelCount;
  stats.values = lf.values.size();
  stats.reusedVisibility = true;
  stats.iterations = outcome.relight.iterations;
  stats.residual = outcome.relight.residual;
  stats.causticPhotons = previous.stats.causticPhotons;
  stats.causticPhotonsLanded = previous.stats.causticPhotonsLanded;
  stats.seconds = secondsSince(start);
  stats.propagationSeconds = stats.seconds;
  stats.peakRssBytes = peakRssBytes();
  return lf;
}

}  // namespace

std::optional<LightField> warmStartBake(Scene& scene, const BakeSettings& settings, const std::string& previousPath,
                                        const BakeOptions& options, WarmStartOutcome& outcome) {
  outcome = WarmStartOutcome{};
  auto decline = [&](std::string why) {
    outcome.reason = std::move(why);
    if (options.log) options.log(fmt::format("warm start: not used, because {}; propagating from zero", outcome.reason));
    return std::nullopt;
  };
  if (options.visibilityPath.empty()) return decline("the bake saves no visibility field");
  if (options.communicator && options.communicator->size() > 1) return decline("the bake is distributed");
  if (options.keepParameterisation || options.keepVisibility)
    return decline("the caller keeps the bake's parameterisation and visibility field");
  try {
    LightField lf = relightPrevious(scene, settings, previousPath, options, outcome);
    outcome.used = true;
    if (options.log)
      options.log(fmt::format("warm start: relit {} for the changed scene instead of propagating from zero: {} "
                              "iterations, residual {:.2e}, {:.2f} s (setup and first shot by source {:.2f} s; {} "
                              "lights and {} sun masks traced again{})",
                              previousPath, outcome.relight.iterations, outcome.relight.residual, lf.stats.seconds,
                              outcome.setupSeconds, outcome.relight.lightsShot, outcome.relight.sunMasksTraced,
                              outcome.relight.emittersShot ? ", emitters shot again" : ""));
    return lf;
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& e) {
    return decline(e.what());
  }
}

}  // namespace pl
