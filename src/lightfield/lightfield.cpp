// The JSON schema of BakeSettings and BakeStats (lightfield.h): each struct's keys are listed
// once, in its fields() hook, which both toJson and fromJson walk.
#include "lightfield/lightfield.h"

#include <nlohmann/json.hpp>

#include <type_traits>

namespace pl {
namespace {

/// visit(key, field) for every field of the settings, in the order of the struct.
template <typename Settings, typename Visit>
  requires std::is_same_v<std::remove_const_t<Settings>, BakeSettings>
void fields(Settings& s, Visit&& visit) {
  visit("preset", s.preset);
  visit("tixels_per_unit", s.tixelsPerUnit);
  visit("max_tixels_per_chart_side", s.maxTixelsPerChartSide);
  visit("tixels_across_scene", s.tixelsAcrossScene);
  visit("gather_directions", s.gatherDirections);
  visit("glossy_dir_res", s.glossyDirRes);
  visit("tolerance", s.tolerance);
  visit("max_iterations", s.maxIterations);
  visit("mirror_depth", s.mirrorDepth);
  visit("area_light_samples", s.areaLightSamples);
  visit("seed", s.seed);
  visit("sun_masks", s.sunMasks);
  visit("punctual_highlights", s.punctualHighlights);
  visit("caustic_photons", s.causticPhotons);
  visit("subsurface_walks", s.subsurfaceWalks);
  visit("exact_visibility", s.exactVisibility);
}

template <typename Stats, typename Visit>
  requires std::is_same_v<std::remove_const_t<Stats>, BakeStats>
void fields(Stats& s, Visit&& visit) {
  visit("seconds", s.seconds);
  visit("visibility_seconds", s.visibilitySeconds);
  visit("propagation_seconds", s.propagationSeconds);
  visit("iterations", s.iterations);
  visit("residual", s.residual);
  visit("tixels", s.tixels);
  visit("values", s.values);
  visit("visibility_rays", s.visibilityRays);
  visit("peak_rss_bytes", s.peakRssBytes);
  visit("reused_visibility", s.reusedVisibility);
  visit("caustic_photons", s.causticPhotons);
  visit("caustic_photons_landed", s.causticPhotonsLanded);
  visit("caustic_seconds", s.causticSeconds);
}

template <typename T>
nlohmann::json write(const T& value) {
  nlohmann::json json = nlohmann::json::object();
  fields(value, [&](const char* key, const auto& field) { json[key] = field; });
  return json;
}

template <typename T>
void read(const nlohmann::json& json, T& value) {
  fields(value, [&](const char* key, auto& field) {
    if (const auto it = json.find(key); it != json.end()) field = it->template get<std::decay_t<decltype(field)>>();
  });
}

}  // namespace

nlohmann::json toJson(const BakeSettings& settings) { return write(settings); }
nlohmann::json toJson(const BakeStats& stats) { return write(stats); }

void fromJson(const nlohmann::json& json, BakeSettings& settings) {
  settings.sunMasks = false;            // writers before sun masks (.plf version ≤ 2) baked without them
  settings.punctualHighlights = false;  // writers before punctual highlights kept them in the glossy maps
  settings.causticPhotons = 0;          // writers before the caustic pass left caustics to the gather
  settings.exactVisibility = true;      // writers before the compact fractions kept them whole
  read(json, settings);
}

void fromJson(const nlohmann::json& json, BakeStats& stats) { read(json, stats); }

}  // namespace pl
