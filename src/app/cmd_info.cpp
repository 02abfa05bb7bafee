// `plenoptic info IN.plf [--json] [--no-verify]`: what a light-field file holds — format
// version, the embedded scene, charts by kind, tixels, values, sun masks, section sizes, and
// the bake's settings and statistics — read without decoding the values (plf/plf_file.h).
// `plenoptic info IN.plv [--json]`: a visibility field's counts and bytes per entry
// (plf/plv_file.h), read without decoding the entries.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "app/commands.h"
#include "core/error.h"
#include "plf/compression.h"
#include "plf/plf_file.h"
#include "plf/plv_file.h"

namespace pl {
namespace {

struct InfoOptions {
  std::string input;
  bool json = false;      ///< --json: one JSON object on stdout
  bool noVerify = false;  ///< --no-verify: skip recomputing the big sections' checksums
};

std::string humanBytes(uint64_t bytes) {
  if (bytes < 1024) return fmt::format("{} B", bytes);
  if (bytes < (uint64_t(1) << 20)) return fmt::format("{:.1f} KiB", double(bytes) / 1024.0);
  if (bytes < (uint64_t(1) << 30)) return fmt::format("{:.1f} MiB", double(bytes) / double(1 << 20));
  return fmt::format("{:.2f} GiB", double(bytes) / double(1 << 30));
}

std::string_view encodingName(uint32_t encoding) {
  if (encoding == uint32_t(ValuesCodec::Raw)) return "raw";
  if (encoding == kPlfSectionZstd) return "zstd";
  return isKnownValuesCodec(encoding) ? valuesCodecName(ValuesCodec(encoding)) : "unknown";
}

/// The values section's storage: mode, stored and decoded bytes, their ratio.
struct ValuesStorage {
  std::string_view mode = "none";
  uint64_t storedBytes = 0, decodedBytes = 0;
  double ratio = 1.0;  ///< decoded / stored
};
ValuesStorage valuesStorage(const PlfInfo& info) {
  ValuesStorage v;
  for (const PlfSectionInfo& s : info.sections)
    if (s.id == "VALS") {
      v.mode = s.encoding == uint32_t(ValuesCodec::Raw) ? "none" : encodingName(s.encoding);
      v.storedBytes = s.storedSize;
      v.decodedBytes = s.decodedSize;
      v.ratio = s.storedSize > 0 ? double(s.decodedSize) / double(s.storedSize) : 1.0;
    }
  return v;
}

/// "lambert ×4, mirror ×1" in first-seen order.
std::string modelCounts(const std::vector<std::string>& models) {
  std::vector<std::pair<std::string, int>> counts;
  for (const std::string& m : models) {
    auto it = std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == m; });
    if (it == counts.end())
      counts.emplace_back(m, 1);
    else
      ++it->second;
  }
  std::string text;
  for (const auto& [model, count] : counts) text += fmt::format("{}{} ×{}", text.empty() ? "" : ", ", model, count);
  return text;
}

nlohmann::json toJson(const PlfInfo& info) {
  nlohmann::json sections = nlohmann::json::array();
  for (const PlfSectionInfo& s : info.sections)
    sections.push_back({{"id", s.id},
                        {"encoding", std::string(encodingName(s.encoding))},
                        {"offset", s.offset},
                        {"stored_bytes", s.storedSize},
                        {"decoded_bytes", s.decodedSize},
                        {"checksum_xxh64", fmt::format("{:016x}", s.checksum)}});
  const ValuesStorage storage = valuesStorage(info);
  return {{"file", info.path},
          {"format_version", info.version},
          {"file_bytes", info.fileBytes},
          {"checksums_verified", info.checksumsVerified},
          {"scene",
           {{"source", info.sceneSource},
            {"meshes", info.meshes},
            {"triangles", info.triangles},
            {"vertices", info.vertices},
            {"materials", info.materials},
            {"material_models", info.materialModels},
            {"textures", info.textures},
            {"lights", info.lights},
            {"cameras", info.cameraNames},
            {"environment", {info.environment.r, info.environment.g, info.environment.b}},
            {"environment_map",
             info.environmentMapWidth == 0
                 ? nlohmann::json(nullptr)
                 : nlohmann::json({{"width", info.environmentMapWidth},
                                   {"height", info.environmentMapHeight},
                                   {"scale", info.environmentMapScale},
                                   {"rotation_degrees", info.environmentMapRotationDegrees}})}}},
          {"charts",
           {{"total", info.charts},
            {"diffuse", info.diffuseCharts},
            {"glossy", info.glossyCharts},
            {"specular", info.specularCharts},
            {"two_sided", info.twoSidedCharts},
            {"curved", info.curvedCharts}}},
          {"tixels", info.tixels},
          {"values", info.values},
          {"sun_mask_lights", info.sunMaskLights},
          {"sections", sections},
          {"compression",
           {{"mode", std::string(storage.mode)},
            {"values_stored_bytes", storage.storedBytes},
            {"values_decoded_bytes", storage.decodedBytes},
            {"ratio", storage.ratio}}},
          {"settings", toJson(info.settings)},
          {"stats", toJson(info.stats)}};
}

void printHuman(const PlfInfo& info) {
  fmt::print("{}: plenoptic light field, format version {}, {} ({} bytes)\n", info.path, info.version,
             humanBytes(info.fileBytes), info.fileBytes);
  fmt::print("checksums    {}\n", info.checksumsVerified ? "all sections verified" : "header and small sections verified "
                                                                                     "(values not checked: --no-verify)");
  fmt::print("scene        {}\n", info.sceneSource.empty() ? "(unnamed)" : info.sceneSource);
  fmt::print("  geometry   {} triangles, {} vertices in {} meshes\n", info.triangles, info.vertices, info.meshes);
  fmt::print("  materials  {} ({})\n", info.materials, modelCounts(info.materialModels));
  fmt::print("  textures   {}\n", info.textures);
  fmt::print("  lights     {} (plus emissive surfaces)\n", info.lights);
  std::string cameras;
  for (const std::string& c : info.cameraNames) cameras += (cameras.empty() ? "" : ", ") + (c.empty() ? "(unnamed)" : c);
  fmt::print("  cameras    {}{}\n", info.cameraNames.size(), cameras.empty() ? "" : ": " + cameras);
  fmt::print("  environment  constant {:.4g} {:.4g} {:.4g} W·sr⁻¹·m⁻²", info.environment.r, info.environment.g,
             info.environment.b);
  if (info.environmentMapWidth > 0)
    fmt::print(" + lat-long map {}×{} (scale {:.4g}, rotated {:.4g}° about +y)", info.environmentMapWidth,
               info.environmentMapHeight, info.environmentMapScale, info.environmentMapRotationDegrees);
  fmt::print("\n");
  fmt::print("charts       {} ({} diffuse, {} glossy, {} specular; {} two-sided, counted twice; {} curved)\n", info.charts,
             info.diffuseCharts, info.glossyCharts, info.specularCharts, info.twoSidedCharts, info.curvedCharts);
  fmt::print("tixels       {}\n", info.tixels);
  fmt::print("values       {} RGB (float32, {})\n", info.values, humanBytes(info.values * 12));
  if (info.sunMaskLights == 0)
    fmt::print("sun masks    none\n");
  else
    fmt::print("sun masks    {} light{} ({} tixels × {} bytes, {})\n", info.sunMaskLights,
               info.sunMaskLights == 1 ? "" : "s", info.tixels, 2 * info.sunMaskLights,
               humanBytes(info.tixels * 2 * info.sunMaskLights));
  const ValuesStorage storage = valuesStorage(info);
  fmt::print("compression  {}: values {} stored as {} ({:.2f}:1)\n", storage.mode, humanBytes(storage.decodedBytes),
             humanBytes(storage.storedBytes), storage.ratio);
  fmt::print("sections     id    encoding        offset        bytes  xxh64\n");
  for (const PlfSectionInfo& s : info.sections)
    fmt::print("             {}  {:8} {:>13} {:>12}  {:016x}  ({}{})\n", s.id, encodingName(s.encoding), s.offset,
               s.storedSize, s.checksum, humanBytes(s.storedSize),
               s.decodedSize == s.storedSize ? "" : " of " + humanBytes(s.decodedSize));
  const BakeSettings& bs = info.settings;
  fmt::print("bake settings  preset {}, ", bs.preset);
  if (bs.tixelsPerUnit > 0.0f)
    fmt::print("{} tixels per scene unit", bs.tixelsPerUnit);
  else
    fmt::print("{} tixels across the scene's room scale", bs.tixelsAcrossScene);
  fmt::print(" (≤ {} per chart side), {} gather directions, glossy maps ≤ {}², tolerance {}, ≤ {} iterations, "
             "mirror depth {}, {} area-light samples, seed {}\n",
             bs.maxTixelsPerChartSide, bs.gatherDirections, bs.glossyDirRes, bs.tolerance, bs.maxIterations,
             bs.mirrorDepth, bs.areaLightSamples, bs.seed);
  const BakeStats& st = info.stats;
  fmt::print("bake stats     {:.3f} s (visibility {:.3f} s{}, propagation {:.3f} s), {} iterations, residual {:.3g}, "
             "{} visibility rays, peak RSS {}\n",
             st.seconds, st.visibilitySeconds, st.reusedVisibility ? ", reused" : "", st.propagationSeconds,
             st.iterations, st.residual, st.visibilityRays, humanBytes(st.peakRssBytes));
}

/// A .plv (visibility field): its counts and its bytes per entry on disk and in memory.
void printVisibility(const std::string& path, bool json) {
  const VisibilityFileInfo v = readVisibilityInfo(path);
  const bool current = v.version == kPlvVersion;
  const double entries = double(std::max<uint64_t>(v.entryCount, 1));
  if (json) {
    nlohmann::json j = {{"path", path},
                        {"kind", "visibility field"},
                        {"version", v.version},
                        {"current_version", current},
                        {"gather_directions", uint64_t(v.gridSide) * v.gridSide},
                        {"tixels", v.tixelCount},
                        {"entries", v.entryCount},
                        {"extra_records", v.extraCount},
                        {"hash", fmt::format("{:016x}", v.hash)},
                        {"file_bytes", v.fileBytes},
                        {"file_bytes_per_entry", double(v.fileBytes) / entries}};
    if (current) {
      j["entry_bytes"] = v.entryBytes;
      j["entry_bytes_per_entry"] = double(v.entryBytes) / entries;
      j["memory_bytes"] = v.heldBytes;
      j["memory_bytes_per_entry"] = double(v.heldBytes) / entries;
      j["fraction_bits"] = v.fractionBits;
    }
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("{}: plenoptic visibility field, format version {} ({} bytes)\n", path, v.version, v.fileBytes);
  if (!current) {
    fmt::print("format       older than this program's version {}: a bake traces the field again\n", kPlvVersion);
    return;
  }
  fmt::print("checksums    payload and frame table verified\n");
  fmt::print("field        {} tixels × {} gather directions = {} entries, {} extra records, hash {:016x}\n", v.tixelCount,
             uint64_t(v.gridSide) * v.gridSide, v.entryCount, v.extraCount, v.hash);
  fmt::print("on disk      {} ({:.2f} bytes per entry)\n", humanBytes(v.fileBytes), double(v.fileBytes) / entries);
  if (v.fractionBits > 0)
    fmt::print("fractions    {} bits each ({})\n", v.fractionBits,
               v.fractionBits == kExactFractionBits ? "exact, as traced" : "compact, quantised");
  fmt::print("in memory    {} ({:.2f} bytes per entry; the encoded entries alone {:.2f})\n", humanBytes(v.heldBytes),
             double(v.heldBytes) / entries, double(v.entryBytes) / entries);
}

bool isVisibilityFile(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".plv";
}

}  // namespace

void addInfoCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand("info", "Show what a light-field file (.plf) contains: format, scene, "
                                                 "charts, sizes, bake settings and statistics; or a visibility "
                                                 "field (.plv): counts and bytes per entry on disk and in memory");
  command->add_option("input", options->input, "Light-field file (.plf) or visibility field (.plv)")->required();
  command->add_flag("--json", options->json, "Print one JSON object instead of text");
  command->add_flag("--no-verify", options->noVerify,
                    "Do not recompute the checksums of the triangle-chart and value sections (faster on huge files)");
  command->callback([options, &global] {
    Runtime runtime(global);
    if (isVisibilityFile(options->input)) {
      printVisibility(options->input, options->json);
      return;
    }
    const PlfInfo info = readLightFieldInfo(options->input, !options->noVerify);
    if (options->json)
      fmt::print("{}\n", toJson(info).dump(2));
    else
      printHuman(info);
  });
}

}  // namespace pl
