// The first shot by source beside the visibility field (see first_shot.h; the layout:
// docs/file-formats.md, "The .pls format").
#include "bake/first_shot.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <variant>

#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "env/env.h"

namespace pl {
namespace {

constexpr char kPlsMagic[8] = {'P', 'L', 'S', 'H', 'O', 'T', '\r', '\n'};
constexpr uint32_t kPlsVersion = 1;
constexpr uint64_t kPlsHeaderBytes = 56;
static_assert(sizeof(Rgb) == 12, "the .pls stores 3 f32 per value as the program holds them");

/// The arrays of a file in their stored order: per light D_l then (with punctual arrays) its
/// punctual part, then D_e.
uint64_t arrayCount(uint64_t lights, bool punctual) { return lights * (punctual ? 2 : 1) + 1; }

template <typename T>
void hashValue(Xxh64Stream& h, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  h.update(&v, sizeof(T));
}

}  // namespace

std::string firstShotPathFor(const std::string& visibilityPath) {
  return std::filesystem::path(visibilityPath).replace_extension(".pls").string();
}

uint64_t firstShotKey(const Scene& scene, const Parameterisation& param, const BakeSettings& settings,
                      uint64_t visibilityHash) {
  Xxh64Stream h;
  hashValue(h, kPlsVersion);
  hashValue(h, visibilityHash);
  hashValue(h, param.valueCount);
  const std::string json = toJson(settings).dump();
  h.update(json.data(), json.size());
  for (uint64_t key : tixelSetupKeys(scene, param)) hashValue(h, key);
  // Every light's type and serialised parameters (lights.h `parameters`: placement and emission).
  hashValue(h, uint64_t(scene.lights.size()));
  for (const Light& light : scene.lights) {
    hashValue(h, uint32_t(light.index()));
    std::visit(
        [&](const auto& l) {
          using T = std::decay_t<decltype(l)>;
          T::parameters(l, [&](const char*, LightParameterKind, const auto& field) { hashValue(h, field); });
        },
        light);
  }
  // What D_e reads beyond the tixel setup: the emissions (and, for an edit that only changed an
  // albedo, the albedo: a file is then for that scene alone) and the sky.
  for (const Material& m : scene.materials) {
    hashValue(h, m.emission);
    hashValue(h, uint8_t(m.twoSidedEmission));
    hashValue(h, m.emissionTexture);
    if (const auto* lambert = std::get_if<LambertBsdf>(&m.bsdf)) hashValue(h, lambert->albedo);
  }
  const Environment& env = scene.environment;
  hashValue(h, env.constant);
  hashValue(h, uint8_t(env.map != nullptr));
  if (env.map) {
    const Image& image = env.map->map().image;
    hashValue(h, env.map->scale());
    hashValue(h, env.map->rotationDegrees());
    hashValue(h, image.width);
    hashValue(h, image.height);
    hashValue(h, xxh64(image.pixels.data(), image.pixels.size() * sizeof(image.pixels[0])));
  }
  return h.digest();
}

void writeFirstShot(const std::string& path, uint64_t visibilityHash, uint64_t key, const FirstShotBySource& shot) {
  const uint64_t values = shot.emitterDirect.size();
  const bool punctual = !shot.lightPunctual.empty() && !shot.lightPunctual[0].empty();
  std::vector<const std::vector<Rgb>*> arrays;
  for (size_t l = 0; l < shot.lightDirect.size(); ++l) {
    arrays.push_back(&shot.lightDirect[l]);
    if (punctual) {
      if (l >= shot.lightPunctual.size()) fail("{}: the first shot has no punctual part for light {}", path, l);
      arrays.push_back(&shot.lightPunctual[l]);
    }
  }
  arrays.push_back(&shot.emitterDirect);
  for (const std::vector<Rgb>* a : arrays)
    if (a->size() != values) fail("{}: the first shot's arrays differ in size ({} and {} values)", path, a->size(), values);
  Xxh64Stream payload;
  for (const std::vector<Rgb>* a : arrays) payload.update(a->data(), a->size() * sizeof(Rgb));
  unsigned char header[kPlsHeaderBytes];
  auto put = [&](size_t at, const auto& v) { std::memcpy(header + at, &v, sizeof(v)); };
  std::memcpy(header, kPlsMagic, 8);
  put(8, kPlsVersion);
  put(12, uint32_t(shot.lightDirect.size()));
  put(16, visibilityHash);
  put(24, key);
  put(32, values);
  put(40, uint64_t(punctual ? 1 : 0));
  put(48, payload.digest());
  writeFileAtomically(path, [&](const std::string& temporary) {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(header), sizeof(header));
    for (const std::vector<Rgb>* a : arrays)
      out.write(reinterpret_cast<const char*>(a->data()), std::streamsize(a->size() * sizeof(Rgb)));
    out.close();
    if (!out) fail("writing failed (disk full?)");
  });
}

bool readFirstShot(const std::string& path, uint64_t visibilityHash, uint64_t key, uint32_t lightCount,
                   uint64_t valueCount, bool punctual, FirstShotBySource& shot, std::string* why) {
  auto no = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return no(fmt::format("there is no {}", path));
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return no(fmt::format("{} cannot be read ({})", path, ec.message()));
  std::ifstream in(path, std::ios::binary);
  unsigned char header[kPlsHeaderBytes];
  if (size < kPlsHeaderBytes || !in.read(reinterpret_cast<char*>(header), sizeof(header)))
    return no(fmt::format("{} is damaged (shorter than its {}-byte header)", path, kPlsHeaderBytes));
  auto get = [&](size_t at, auto v) {
    std::memcpy(&v, header + at, sizeof(v));
    return v;
  };
  if (std::memcmp(header, kPlsMagic, 8) != 0) return no(fmt::format("{} is damaged (not a .pls file)", path));
  if (get(8, uint32_t(0)) != kPlsVersion)
    return no(fmt::format("{} has version {}, this build reads {}", path, get(8, uint32_t(0)), kPlsVersion));
  const uint32_t lights = get(12, uint32_t(0));
  const uint64_t values = get(32, uint64_t(0)), flags = get(40, uint64_t(0)), checksum = get(48, uint64_t(0));
  if (get(16, uint64_t(0)) != visibilityHash || get(24, uint64_t(0)) != key)
    return no(fmt::format("{} was written for another light field or scene (a stale file)", path));
  if (lights != lightCount || values != valueCount || flags != (punctual ? 1u : 0u))
    return no(fmt::format("{} holds {} lights × {} values{}, the light field needs {} × {}{}", path, lights, values,
                          flags ? " with punctual parts" : "", lightCount, valueCount,
                          punctual ? " with punctual parts" : ""));
  const uint64_t arrays = arrayCount(lights, punctual);
  // The payload's size against the header's counts, divided rather than multiplied (no overflow).
  const uint64_t payloadBytes = size - kPlsHeaderBytes, arrayBytes = values * sizeof(Rgb);
  if (values > payloadBytes / sizeof(Rgb) || (arrayBytes > 0 && payloadBytes / arrayBytes != arrays) ||
      (arrayBytes > 0 && payloadBytes % arrayBytes != 0) || (arrayBytes == 0 && payloadBytes != 0))
    return no(fmt::format("{} is damaged ({} bytes after its header, which declares {} arrays of {} values)", path,
                          payloadBytes, arrays, values));
  FirstShotBySource read;
  read.lightDirect.resize(lights);
  if (punctual) read.lightPunctual.resize(lights);
  Xxh64Stream payload;
  auto fill = [&](std::vector<Rgb>& a) {
    a.resize(values);
    in.read(reinterpret_cast<char*>(a.data()), std::streamsize(values * sizeof(Rgb)));
    payload.update(a.data(), values * sizeof(Rgb));
    return bool(in);
  };
  for (uint32_t l = 0; l < lights; ++l)
    if (!fill(read.lightDirect[l]) || (punctual && !fill(read.lightPunctual[l])))
      return no(fmt::format("{} is damaged (cut short)", path));
  if (!fill(read.emitterDirect)) return no(fmt::format("{} is damaged (cut short)", path));
  if (payload.digest() != checksum) return no(fmt::format("{} is damaged (its checksum does not match)", path));
  shot = std::move(read);
  return true;
}

}  // namespace pl
