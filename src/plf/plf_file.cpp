// The .plf light-field file: layout in plf_file.h.
#include "plf/plf_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <limits>
#include <optional>
#include <nlohmann/json.hpp>
#include <span>
#include <type_traits>

#include "core/byte_reader.h"
#include "core/byte_writer.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "plf/codec_backends.h"
#include "plf/compression.h"

namespace pl {

// The file is little-endian and arrays are copied to and from memory as they are, so the
// host must be little-endian too (every platform plenoptic targets is).
static_assert(std::endian::native == std::endian::little, ".plf I/O assumes a little-endian host");
static_assert(sizeof(Vec2) == 8 && sizeof(Vec3) == 12 && sizeof(UVec3) == 12, "packed GLM vectors expected");
static_assert(std::is_trivially_copyable_v<Vec3> && std::is_trivially_copyable_v<UVec3>);

// ---------------------------------------------------------------------------------------
namespace {

constexpr size_t kSectionAlignment = 64;
/// No file of this version has more sections than this; a larger count is corruption.
constexpr uint32_t kMaxSections = 64;

// Kinds in the order the writer stores them (the reader accepts any order).
enum SectionIndex { kScene = 0, kCharts, kTriangleCharts, kValues, kSunMasks, kMeta, kSectionKinds };
constexpr const char* kSectionIds[kSectionKinds] = {"SCNE", "CHRT", "TRCH", "VALS", "SMSK", "META"};
constexpr const char* kSectionNames[kSectionKinds] = {"scene",     "charts",    "triangle charts", "values",
                                                      "sun masks", "metadata"};
/// Whether a file must hold the section (the others are optional: at most once).
constexpr bool isRequiredSection(int kind) { return kind != kSunMasks; }
/// The first version that may hold the section (an older file with it is refused as holding
/// an unknown section, which is what it was when that version was current).
constexpr uint32_t firstVersionWith(int kind) { return kind == kSunMasks ? 3 : 1; }

/// SMSK (plf_file.h): u32 light count, u32 reserved (0), u64 tixel count, then the masks.
struct SunMaskHeader {
  uint32_t lightCount;
  uint32_t reserved;
  uint64_t tixelCount;
};
static_assert(sizeof(SunMaskHeader) == 16 && std::is_trivially_copyable_v<SunMaskHeader>);
static_assert(sizeof(SunMask) == 2, "SMSK stores 16-bit masks");

static_assert(kPlfSectionZstd > uint32_t(ValuesCodec::Hdr), "a section's zstd encoding is no values codec");
/// zstd's largest expansion: an RLE block, 3 header bytes and 1 byte, decodes to at most 128 KiB.
/// A zstd section's decoded size beyond this many times its stored size is corruption, refused
/// before anything is allocated for it.
constexpr uint64_t kZstdMaxExpansion = 32768;

uint64_t alignUp(uint64_t x) { return (x + kSectionAlignment - 1) / kSectionAlignment * kSectionAlignment; }

// --- Scene -------------------------------------------------------------------------------

// A model is its variant index (uint32) followed by its parameters in the order of the
// model's parameters() hook (bsdf.h): Rgb as three floats, float, bool as one byte. The
// model numbers 0–4 (Lambert, mirror, Blinn-Phong, GGX, dielectric) are the file format;
// the dielectric (4) was added without a version bump: older files never contain it, and an
// older build reading a newer file refuses it as "unknown BSDF model 4".
void putBsdf(ByteWriter& w, const Bsdf& bsdf) {
  w.put(uint32_t(bsdf.index()));
  std::visit(
      [&](const auto& b) {
        std::decay_t<decltype(b)>::parameters(b, [&](const auto& field) {
          if constexpr (std::is_same_v<std::decay_t<decltype(field)>, bool>) w.put(uint8_t(field));
          else w.put(field);
        });
      },
      bsdf);
}

// Version 6 appended the glTF model's (5) dielectric Fresnel, dielectricF0 and dielectricF90:
// an older file's model ends before them and means the diffuse coupled to the whole lobe,
// dielectricF0 = f0 and dielectricF90 = f90 (bsdf.h GltfPbrBsdf).
constexpr size_t kGltfPbrFieldsBeforeVersion6 = 8;

Bsdf getBsdf(ByteReader& r, uint32_t version) {
  const uint32_t model = r.get<uint32_t>();
  std::optional<Bsdf> bsdf = bsdfOfIndex(model);
  if (!bsdf) r.corrupt(fmt::format("unknown BSDF model {}", model));
  auto* gltf = std::get_if<GltfPbrBsdf>(&*bsdf);
  const bool older = gltf && version < 6;
  size_t fieldsLeft = older ? kGltfPbrFieldsBeforeVersion6 : SIZE_MAX;
  std::visit(
      [&](auto& b) {
        std::decay_t<decltype(b)>::parameters(b, [&](auto& field) {
          if (fieldsLeft == 0) return;
          --fieldsLeft;
          using Field = std::decay_t<decltype(field)>;
          if constexpr (std::is_same_v<Field, bool>) field = r.get<uint8_t>() != 0;
          else field = r.get<Field>();
        });
      },
      *bsdf);
  if (older) {
    gltf->dielectricF0 = gltf->f0;
    gltf->dielectricF90 = gltf->f90;
  }
  return *bsdf;
}

// A light likewise: its variant index (uint32; 0 point, 1 spot, 2 directional, … in the order
// of light/lights.h's Light, the file's light numbers) followed by its parameters in the order
// of the type's parameters() hook, each a Vec3 (three floats) or a float. A new type at the end
// of the variant needs no new version: older files never contain it, and an older build
// reading a newer file refuses it as "unknown light type N".
void putLight(ByteWriter& w, const Light& light) {
  w.put(uint32_t(light.index()));
  visitLightParameters(light, [&](const char*, LightParameterKind, const auto& field) { w.put(field); });
}

Light getLight(ByteReader& r) {
  const uint32_t type = r.get<uint32_t>();
  std::optional<Light> light = lightOfIndex(type);
  if (!light) r.corrupt(fmt::format("unknown light type {}", type));
  visitLightParameters(*light,
                       [&](const char*, LightParameterKind, auto& field) { field = r.get<std::decay_t<decltype(field)>>(); });
  // Its values are checked with the rest of the scene (checkScene, after the section is read).
  prepareLight(*light);
  return *light;
}

/// How a texture record stores its image (the byte after its path).
constexpr uint8_t kTexturePixels = 0;       ///< i32 width, i32 height, u64 count, float32 RGB texels
constexpr uint8_t kTextureEncodedFile = 1;  ///< u64 count, the image file's bytes (PNG/JPEG/TGA/BMP)
/// Opens SCNE's optional surface-detail block ("SDTL" read as a little-endian u32).
constexpr uint32_t kSurfaceDetailTag = 0x4c544453u;
/// Opens SCNE's optional texturing block ("TXMP", version ≥ 5; plf_file.h).
constexpr uint32_t kTexturingTag = 0x504d5854u;
/// Opens SCNE's optional emission-texture block ("EMTX", version ≥ 5; plf_file.h).
constexpr uint32_t kEmissionTextureTag = 0x58544d45u;
/// Opens SCNE's optional vertex-alpha block ("VALP", version ≥ 6; plf_file.h).
constexpr uint32_t kVertexAlphaTag = 0x504c4156u;

/// Whether a scene needs the texturing block: a second uv set, vertex colours, a texture
/// mapping other than TEXCOORD_0 as it is, a metallic-roughness texture or a sampling other
/// than repeat/bilinear/mip-mapped. Scenes without any keep the version-4 layout of SCNE.
bool needsTexturingBlock(const Scene& scene) {
  for (const Mesh& m : scene.meshes)
    if (!m.uvs1.empty() || !m.colors.empty()) return true;
  for (const Material& m : scene.materials)
    if (!m.albedoMapping.isDefault() || !m.alphaMapping.isDefault() || !m.normalMapping.isDefault() ||
        m.metallicRoughness.texture >= 0)
      return true;
  for (const Texture& t : scene.textures)
    if (!t.sampling.isDefault()) return true;
  return false;
}

void putMapping(ByteWriter& w, const TextureMapping& mapping) {
  w.put(mapping.uvSet);
  w.put(mapping.linear[0]);
  w.put(mapping.linear[1]);
  w.put(mapping.offset);
}

TextureMapping getMapping(ByteReader& r) {
  TextureMapping mapping;
  mapping.uvSet = r.get<uint8_t>();
  mapping.linear[0] = r.get<Vec2>();
  mapping.linear[1] = r.get<Vec2>();
  mapping.offset = r.get<Vec2>();
  return mapping;
}

std::vector<unsigned char> encodeScene(const Scene& scene) {
  ByteWriter w;
  w.putString(scene.sourcePath);
  w.put(uint64_t(scene.meshes.size()));
  for (const Mesh& m : scene.meshes) {
    w.putString(m.name);
    w.putArray(m.positions);
    w.putArray(m.normals);
    w.putArray(m.uvs);
    w.putArray(m.triangles);
    w.putArray(m.materials);
  }
  w.put(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    w.putString(m.name);
    putBsdf(w, m.bsdf);
    w.put(int32_t(m.albedoTexture));
    w.put(m.emission);
    w.put(uint8_t(m.twoSidedEmission));
  }
  w.put(uint64_t(scene.textures.size()));
  for (const Texture& t : scene.textures) {
    w.putString(t.path);
    // The image file's bytes when the texture has them (decoded on load), else the pixels.
    const bool encoded = t.encoded && !t.encoded->empty();
    w.put(uint8_t(encoded ? kTextureEncodedFile : kTexturePixels));
    if (encoded) {
      w.putArray(*t.encoded);
    } else {
      w.put(int32_t(t.image.width));
      w.put(int32_t(t.image.height));
      w.putArray(t.image.pixels);
    }
  }
  w.put(uint64_t(scene.lights.size()));
  for (const Light& l : scene.lights) putLight(w, l);
  w.put(uint64_t(scene.cameras.size()));
  for (const CameraDesc& c : scene.cameras) {
    w.putString(c.name);
    w.put(c.eye);
    w.put(c.target);
    w.put(c.up);
    w.put(c.fovYDegrees);
    w.put(c.fNumber);
    w.put(c.focusDistance);
    w.put(c.focalLengthMm);
    w.put(uint8_t(c.aspectRatio.has_value()));
    w.put(c.aspectRatio.value_or(0.0f));
  }
  w.put(scene.environment.constant);
  // The environment map (optional): its scale and rotation, then the lat-long radiance.
  const EnvironmentMap* map = scene.environment.map.get();
  w.put(uint8_t(map != nullptr));
  if (map) {
    w.put(map->scale());
    w.put(map->rotationDegrees());
    w.put(int32_t(map->map().width()));
    w.put(int32_t(map->map().height()));
    w.putArray(map->map().image.pixels);
  }
  // The scene file's suggested render settings: each a presence byte and a value.
  for (const std::optional<int>& value : {scene.settings.width, scene.settings.height, scene.settings.spp}) {
    w.put(uint8_t(value.has_value()));
    w.put(int32_t(value.value_or(0)));
  }
  w.put(uint8_t(scene.settings.camera.has_value()));
  w.putString(scene.settings.camera.value_or(""));
  // Surface detail (plf_file.h): only when some material has an alpha mask or a normal map, or
  // a texture is not colour (a metallic-roughness texture: data), so files without them keep
  // the original layout byte for byte.
  const bool detail = std::any_of(scene.materials.begin(), scene.materials.end(),
                                  [](const Material& m) { return m.isMasked() || m.normalTexture >= 0; }) ||
                      std::any_of(scene.textures.begin(), scene.textures.end(),
                                  [](const Texture& t) { return t.decode != ImageDecode::Colour; });
  if (detail) {
    w.put(kSurfaceDetailTag);
    for (const Material& m : scene.materials) {
      w.put(int32_t(m.alphaTexture));
      w.put(m.alphaFactor);
      w.put(m.alphaCutoff);
      w.put(int32_t(m.normalTexture));
      w.put(m.normalScale);
    }
    for (const Texture& t : scene.textures) w.put(uint8_t(t.decode));
  }
  if (needsTexturingBlock(scene)) {
    w.put(kTexturingTag);
    for (const Mesh& m : scene.meshes) {
      w.putArray(m.uvs1);
      w.putArray(m.colors);
    }
    for (const Material& m : scene.materials) {
      for (const TextureMapping* mapping : {&m.albedoMapping, &m.alphaMapping, &m.normalMapping}) putMapping(w, *mapping);
      const MetallicRoughnessMap& mr = m.metallicRoughness;
      w.put(int32_t(mr.texture));
      putMapping(w, mr.mapping);
      w.put(mr.baseColor);
      w.put(mr.metallic);
      w.put(mr.roughness);
    }
    for (const Texture& t : scene.textures) {
      w.put(uint8_t(t.sampling.wrapU));
      w.put(uint8_t(t.sampling.wrapV));
      w.put(uint8_t(t.sampling.nearest));
      w.put(uint8_t(t.sampling.mipmaps));
    }
  }
  // Emission textures: only when some material has one, so other files keep their layout.
  if (std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.emissionTexture >= 0; })) {
    w.put(kEmissionTextureTag);
    for (const Material& m : scene.materials) {
      w.put(int32_t(m.emissionTexture));
      putMapping(w, m.emissionMapping);
    }
  }
  // Vertex alphas: only when some mesh has them, so other files keep their layout.
  if (std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) { return !m.alphas.empty(); })) {
    w.put(kVertexAlphaTag);
    for (const Mesh& m : scene.meshes) w.putArray(m.alphas);
  }
  return std::move(w.bytes());
}

// Smallest encoded size of one element, used to bound counts before allocating.
constexpr uint64_t kMinMeshBytes = 4 + 5 * 8;
constexpr uint64_t kMinMaterialBytes = 4 + 4 + 12 + 4 + 12 + 1;
constexpr uint64_t kMinTextureBytes = 4 + 1 + 8;
constexpr uint64_t kMinLightBytes = 4 + 24;
constexpr uint64_t kMinCameraBytes = 4 + 36 + 16 + 1 + 4;

/// Whether decodeScene decodes embedded image files (`info` only counts textures).
enum class TextureDecoding { Decode, Skip };

/// Decodes SCNE and checks every index and size; the scene is ready for an Accel (with
/// TextureDecoding::Skip, encoded textures have no pixels: for summaries only).
Scene decodeScene(std::span<const unsigned char> bytes, const std::string& path, uint32_t version,
                  TextureDecoding textures = TextureDecoding::Decode) {
  ByteReader r(bytes, path, std::string(kSectionNames[kScene]) + " section");
  Scene scene;
  scene.sourcePath = r.getString();
  scene.meshes.resize(r.getCount(kMinMeshBytes, "meshes"));
  for (Mesh& m : scene.meshes) {
    m.name = r.getString();
    m.positions = r.getArray<Vec3>("positions");
    m.normals = r.getArray<Vec3>("normals");
    m.uvs = r.getArray<Vec2>("uvs");
    m.triangles = r.getArray<UVec3>("triangles");
    m.materials = r.getArray<uint32_t>("triangle materials");
  }
  scene.materials.resize(r.getCount(kMinMaterialBytes, "materials"));
  for (Material& m : scene.materials) {
    m.name = r.getString();
    m.bsdf = getBsdf(r, version);
    m.albedoTexture = r.get<int32_t>();
    m.emission = r.get<Rgb>();
    m.twoSidedEmission = r.get<uint8_t>() != 0;
  }
  scene.textures.resize(r.getCount(kMinTextureBytes, "textures"));
  for (Texture& t : scene.textures) {
    t.path = r.getString();
    // Version 1 had no storage byte: always pixels, followed by their (recomputed) average.
    const uint8_t storage = version >= 2 ? r.get<uint8_t>() : kTexturePixels;
    if (storage == kTextureEncodedFile) {
      std::vector<unsigned char> file = r.getArray<unsigned char>("encoded image bytes");
      if (file.empty()) r.corrupt(fmt::format("texture '{}' has an empty image file", t.path));
      // Decoded below, once the surface-detail block has said how (colour, data or coverage).
      t.encoded = std::make_shared<const std::vector<unsigned char>>(std::move(file));
    } else if (storage == kTexturePixels) {
      t.image.width = r.get<int32_t>();
      t.image.height = r.get<int32_t>();
      t.image.pixels = r.getArray<Rgb>("texels");
      if (version < 2) r.get<Rgb>();  // the version-1 average
      if (t.image.width <= 0 || t.image.height <= 0 ||
          uint64_t(t.image.width) * uint64_t(t.image.height) != t.image.pixels.size())
        r.corrupt(fmt::format("texture '{}' is {}×{} but holds {} texels", t.path, t.image.width, t.image.height,
                              t.image.pixels.size()));
      t.finish(path);
    } else {
      r.corrupt(fmt::format("texture '{}' has unknown storage {}", t.path, storage));
    }
  }
  scene.lights.resize(r.getCount(kMinLightBytes, "lights"));
  for (Light& l : scene.lights) l = getLight(r);
  scene.cameras.resize(r.getCount(kMinCameraBytes, "cameras"));
  for (CameraDesc& c : scene.cameras) {
    c.name = r.getString();
    c.eye = r.get<Vec3>();
    c.target = r.get<Vec3>();
    c.up = r.get<Vec3>();
    c.fovYDegrees = r.get<float>();
    c.fNumber = r.get<float>();
    c.focusDistance = r.get<float>();
    c.focalLengthMm = r.get<float>();
    const bool hasAspect = r.get<uint8_t>() != 0;
    const float aspect = r.get<float>();
    if (hasAspect) c.aspectRatio = aspect;
  }
  scene.environment.constant = r.get<Rgb>();
  if (r.get<uint8_t>() != 0) {
    const float scale = r.get<float>(), rotationDegrees = r.get<float>();
    LatLongMap map;
    map.image.width = r.get<int32_t>();
    map.image.height = r.get<int32_t>();
    map.image.pixels = r.getArray<Rgb>("environment texels");
    if (map.image.height <= 0 || map.image.width != 2 * map.image.height ||
        uint64_t(map.image.width) * uint64_t(map.image.height) != map.image.pixels.size())
      r.corrupt(fmt::format("environment map is {}×{} (must be 2H×H) with {} texels", map.image.width,
                            map.image.height, map.image.pixels.size()));
    if (!std::isfinite(scale) || !std::isfinite(rotationDegrees))
      r.corrupt("non-finite environment scale or rotation");
    scene.environment.map = std::make_shared<const EnvironmentMap>(std::move(map), scale, rotationDegrees);
  }
  for (std::optional<int>* value : {&scene.settings.width, &scene.settings.height, &scene.settings.spp}) {
    const bool present = r.get<uint8_t>() != 0;
    const int32_t v = r.get<int32_t>();
    if (present) *value = v;
  }
  const bool hasCamera = r.get<uint8_t>() != 0;
  std::string camera = r.getString();
  if (hasCamera) scene.settings.camera = std::move(camera);
  // The optional blocks, each at most once, in this order and from the version given:
  // SDTL, TXMP (5), EMTX (5), VALP (6). nextTag reads the next one's tag (0 at the end).
  constexpr std::pair<uint32_t, uint32_t> kBlocks[] = {
      {kSurfaceDetailTag, 1}, {kTexturingTag, 5}, {kEmissionTextureTag, 5}, {kVertexAlphaTag, 6}};
  size_t blocksPast = 0;
  auto nextTag = [&](const char* after) -> uint32_t {
    if (r.remaining() == 0) return 0;
    const uint32_t tag = r.get<uint32_t>();
    for (size_t b = blocksPast; b < std::size(kBlocks); ++b)
      if (tag == kBlocks[b].first && version >= kBlocks[b].second) {
        blocksPast = b + 1;
        return tag;
      }
    r.corrupt(fmt::format("unexpected bytes after {}", after));
  };
  uint32_t tag = nextTag("the scene's settings");
  if (tag == kSurfaceDetailTag) {
    for (Material& m : scene.materials) {
      m.alphaTexture = r.get<int32_t>();
      m.alphaFactor = r.get<float>();
      m.alphaCutoff = r.get<float>();
      m.normalTexture = r.get<int32_t>();
      m.normalScale = r.get<float>();
    }
    for (Texture& t : scene.textures) {
      const uint8_t decode = r.get<uint8_t>();
      if (decode > uint8_t(ImageDecode::Coverage))
        r.corrupt(fmt::format("texture '{}' has unknown decoding {}", t.path, decode));
      t.decode = ImageDecode(decode);
    }
    tag = nextTag("the surface-detail block");
  }
  if (tag == kTexturingTag) {
    for (Mesh& m : scene.meshes) {
      m.uvs1 = r.getArray<Vec2>("second uvs");
      m.colors = r.getArray<Rgb>("vertex colours");
    }
    for (Material& m : scene.materials) {
      for (TextureMapping* mapping : {&m.albedoMapping, &m.alphaMapping, &m.normalMapping}) *mapping = getMapping(r);
      MetallicRoughnessMap& mr = m.metallicRoughness;
      mr.texture = r.get<int32_t>();
      mr.mapping = getMapping(r);
      mr.baseColor = r.get<Rgb>();
      mr.metallic = r.get<float>();
      mr.roughness = r.get<float>();
      if (const std::string problem = mappingProblem(m); !problem.empty())
        r.corrupt(fmt::format("material '{}': {}", m.name, problem));
    }
    for (Texture& t : scene.textures) {
      const uint8_t wrapU = r.get<uint8_t>(), wrapV = r.get<uint8_t>(), nearest = r.get<uint8_t>(), mipmaps = r.get<uint8_t>();
      if (wrapU > uint8_t(TextureWrap::MirroredRepeat) || wrapV > uint8_t(TextureWrap::MirroredRepeat) || nearest > 1 ||
          mipmaps > 1)
        r.corrupt(fmt::format("texture '{}' has unknown sampling {} {} {} {}", t.path, wrapU, wrapV, nearest, mipmaps));
      t.sampling = TextureSampling{TextureWrap(wrapU), TextureWrap(wrapV), nearest != 0, mipmaps != 0};
    }
    tag = nextTag("the texturing block");
  }
  if (tag == kEmissionTextureTag) {
    for (Material& m : scene.materials) {
      m.emissionTexture = r.get<int32_t>();
      m.emissionMapping = getMapping(r);
      if (const std::string problem = mappingProblem(m); !problem.empty())
        r.corrupt(fmt::format("material '{}': {}", m.name, problem));
    }
    tag = nextTag("the emission-texture block");
  }
  if (tag == kVertexAlphaTag)
    for (Mesh& m : scene.meshes) m.alphas = r.getArray<float>("vertex alphas");
  r.expectEnd();
  if (textures == TextureDecoding::Decode)
    for (Texture& t : scene.textures) {
      if (!t.encoded) continue;  // stored as pixels: checked above
      const std::string label = fmt::format("{}: texture '{}' embedded in the scene section", path, t.path);
      t.image = decodeLdrImage(*t.encoded, label, t.decode);  // size checked before decoding
      t.finish(path);
    }

  // The writer only ever stores a finalized scene, so a scene that fails the scene checker
  // (every index, number, material model and light) was produced by something else or damaged
  // in a way the checksum missed.
  try {
    checkScene(scene);
  } catch (const Error& e) {
    fail("{}: the {} section holds an invalid scene: {}", path, kSectionNames[kScene], e.what());
  }
  // Embree reads 16 bytes at the last vertex: keep one element of padding (see scene.h).
  for (Mesh& m : scene.meshes) m.positions.reserve(m.positions.size() + 1);
  markVertexColoredMaterials(scene);
  return scene;
}

// --- Charts ------------------------------------------------------------------------------

constexpr uint64_t kChartRecordBytes = 4 + 1 + 4 * 12 + 4 + 3 * 4 + 2 * 8;
// The kind byte: ChartKind in bits 0–2, and the sides (lightfield.h "Sides"): bit 7 = two-sided
// (on both records), bit 6 = the back record. Files written before two-sided charts have both
// bits clear, so they read as one-sided charts, which is what they hold. Bit 5 marks a curved
// chart (lightfield.h: diffuse, or glossy but not rough glass); files written before curved
// charts have it clear, and files written before curved glossy charts have it on diffuse
// charts only, so both read unchanged.
// Bit 4 (version 4 on) marks a glossy chart with a diffuse value after each tixel's map
// (Chart::diffuseValue); older files have it clear, and their glossy maps hold the whole
// exitant radiance, which is what a chart without the bit means.
// Bit 3 (version 5 on) marks a diffuse chart with tilted irradiances after each tixel's
// irradiance (Chart::directionalIrradiance); older files have it clear, and their normal-mapped
// diffuse charts keep one irradiance, shown flat, which is what a chart without the bit means.
// A glossy chart with a diffuse value may have bit 3 too (its Ẽ followed by tilted
// irradiances), without a version bump: older files never have it there (their normal-mapped
// glossy charts' Ẽ is shown flat), and an older build reading a newer file refuses the chart
// as marked with tilted irradiances.
constexpr uint8_t kChartTwoSidedBit = 0x80, kChartBackBit = 0x40, kChartCurvedBit = 0x20, kChartDiffuseValueBit = 0x10,
                  kChartDirectionalBit = 0x08, kChartKindMask = 0x07;

std::vector<unsigned char> encodeCharts(const std::vector<Chart>& charts) {
  ByteWriter w;
  w.put(uint64_t(charts.size()));
  for (const Chart& c : charts) {
    w.put(c.material);
    w.put(uint8_t(uint8_t(c.kind) | (c.sides == 2 ? kChartTwoSidedBit : 0) | (c.isBack ? kChartBackBit : 0) |
                  (c.curved ? kChartCurvedBit : 0) | (c.diffuseValue ? kChartDiffuseValueBit : 0) |
                  (c.directionalIrradiance ? kChartDirectionalBit : 0)));
    w.put(c.origin);
    w.put(c.axisU);
    w.put(c.axisV);
    w.put(c.normal);
    w.put(c.tixelSize);
    w.put(c.resU);
    w.put(c.resV);
    w.put(c.dirRes);
    w.put(c.firstTixel);
    w.put(c.firstValue);
  }
  return std::move(w.bytes());
}

/// Decodes CHRT; checks each chart's own fields and its material index (and, for a curved
/// chart, that its material may be curved: not rough glass).
std::vector<Chart> decodeCharts(std::span<const unsigned char> bytes, const std::string& path,
                                const std::vector<Material>& sceneMaterials) {
  const size_t materials = sceneMaterials.size();
  ByteReader r(bytes, path, std::string(kSectionNames[kCharts]) + " section");
  std::vector<Chart> charts(r.getCount(kChartRecordBytes, "charts"));
  for (size_t i = 0; i < charts.size(); ++i) {
    Chart& c = charts[i];
    c.material = r.get<uint32_t>();
    const uint8_t kindByte = r.get<uint8_t>();
    const uint8_t kind = kindByte & kChartKindMask;
    if (kind > uint8_t(ChartKind::Specular)) r.corrupt(fmt::format("chart {} has unknown kind {}", i, kind));
    c.kind = ChartKind(kind);
    c.sides = (kindByte & kChartTwoSidedBit) ? 2 : 1;
    c.isBack = (kindByte & kChartBackBit) != 0;
    c.curved = (kindByte & kChartCurvedBit) != 0;
    c.diffuseValue = (kindByte & kChartDiffuseValueBit) != 0;
    c.directionalIrradiance = (kindByte & kChartDirectionalBit) != 0;
    if (c.curved && c.kind == ChartKind::Specular) r.corrupt(fmt::format("chart {} of kind {} is marked curved", i, kind));
    if (c.diffuseValue && c.kind != ChartKind::Glossy)
      r.corrupt(fmt::format("chart {} of kind {} is marked as having a diffuse value", i, kind));
    if (c.directionalIrradiance && c.kind != ChartKind::Diffuse && !c.diffuseValue)
      r.corrupt(fmt::format("chart {} of kind {} without a diffuse value is marked as having tilted irradiances", i, kind));
    c.origin = r.get<Vec3>();
    c.axisU = r.get<Vec3>();
    c.axisV = r.get<Vec3>();
    c.normal = r.get<Vec3>();
    c.tixelSize = r.get<float>();
    c.resU = r.get<uint32_t>();
    c.resV = r.get<uint32_t>();
    c.dirRes = r.get<uint32_t>();
    c.firstTixel = r.get<uint64_t>();
    c.firstValue = r.get<uint64_t>();
    if (c.material >= materials) r.corrupt(fmt::format("chart {} has material {} of {}", i, c.material, materials));
    if (c.curved && isRoughGlassChart(c, sceneMaterials[c.material].bsdf))
      r.corrupt(fmt::format("rough-glass chart {} is marked curved", i));
    if (!isFinite(c.origin) || !isFinite(c.axisU) || !isFinite(c.axisV) || !isFinite(c.normal) ||
        !(c.tixelSize > 0.0f) || !std::isfinite(c.tixelSize))
      r.corrupt(fmt::format("chart {} has a non-finite frame or tixel size", i));
    if (c.resU == 0 || c.resV == 0) r.corrupt(fmt::format("chart {} has an empty {}×{} grid", i, c.resU, c.resV));
    const bool dirResFits = c.kind == ChartKind::Diffuse    ? c.dirRes == 1
                            : c.kind == ChartKind::Specular ? c.dirRes == 0
                                                            : c.dirRes >= 1;
    if (!dirResFits) r.corrupt(fmt::format("chart {} of kind {} has direction resolution {}", i, kind, c.dirRes));
    // A back record follows its two-sided front record and repeats its material, kind and grid.
    if (c.isBack) {
      const Chart* front = i > 0 ? &charts[i - 1] : nullptr;
      if (c.sides != 2 || !front || front->sides != 2 || front->isBack || front->material != c.material ||
          front->kind != c.kind || front->resU != c.resU || front->resV != c.resV || front->dirRes != c.dirRes ||
          front->curved != c.curved || front->diffuseValue != c.diffuseValue ||
          front->directionalIrradiance != c.directionalIrradiance)
        r.corrupt(fmt::format("chart {} is a back side without a matching two-sided front chart before it", i));
    } else if (i > 0 && charts[i - 1].sides == 2 && !charts[i - 1].isBack) {
      r.corrupt(fmt::format("two-sided chart {} is not followed by its back side", i - 1));
    }
  }
  if (!charts.empty() && charts.back().sides == 2 && !charts.back().isBack)
    r.corrupt(fmt::format("two-sided chart {} is not followed by its back side", charts.size() - 1));
  r.expectEnd();
  return charts;
}

/// Checks that every chart's tixels and values lie inside the light field's arrays.
void checkChartRanges(const std::vector<Chart>& charts, uint64_t valueCount, const std::string& path) {
  for (size_t i = 0; i < charts.size(); ++i) {
    const Chart& c = charts[i];
    const uint64_t tixels = c.tixelCount();  // < 2^64: both factors are < 2^32
    const uint64_t perTixel = c.valuesPerTixel();
    if (perTixel == 0) continue;
    if (tixels > valueCount / perTixel || c.firstValue > valueCount - tixels * perTixel)
      fail("{}: corrupt charts section: chart {} needs values [{}, {} + {}·{}) but the file holds {} values", path, i,
           c.firstValue, c.firstValue, tixels, perTixel, valueCount);
  }
}

std::vector<unsigned char> encodeTriangleCharts(const std::vector<std::vector<uint32_t>>& triangleChart) {
  ByteWriter w;
  w.put(uint64_t(triangleChart.size()));
  for (const auto& mesh : triangleChart) w.putArray(mesh);
  return std::move(w.bytes());
}

std::vector<std::vector<uint32_t>> decodeTriangleCharts(std::span<const unsigned char> bytes, const std::string& path,
                                                        const Scene& scene, const std::vector<Chart>& charts) {
  ByteReader r(bytes, path, std::string(kSectionNames[kTriangleCharts]) + " section");
  std::vector<std::vector<uint32_t>> triangleChart(r.getCount(8, "meshes"));
  if (triangleChart.size() != scene.meshes.size())
    r.corrupt(fmt::format("{} meshes, but the scene has {}", triangleChart.size(), scene.meshes.size()));
  for (size_t m = 0; m < triangleChart.size(); ++m) {
    triangleChart[m] = r.getArray<uint32_t>("triangle charts");
    if (triangleChart[m].size() != scene.meshes[m].triangles.size())
      r.corrupt(fmt::format("mesh {} maps {} triangles, but it has {}", m, triangleChart[m].size(),
                            scene.meshes[m].triangles.size()));
    for (size_t t = 0; t < triangleChart[m].size(); ++t)
      if (triangleChart[m][t] >= charts.size() || charts[triangleChart[m][t]].isBack)
        r.corrupt(fmt::format("mesh {} triangle {} maps to chart {} of {}{}", m, t, triangleChart[m][t], charts.size(),
                              triangleChart[m][t] < charts.size() ? " (a back side, not a front chart)" : ""));
  }
  r.expectEnd();
  return triangleChart;
}

// --- Metadata ----------------------------------------------------------------------------

std::vector<unsigned char> encodeMeta(const LightField& lf) {
  const nlohmann::json meta = {{"writer", "plenoptic"},
                               {"settings", toJson(lf.settings)},
                               {"stats", toJson(lf.stats)}};
  const std::string text = meta.dump(2);
  return {text.begin(), text.end()};
}

void decodeMeta(std::span<const unsigned char> bytes, const std::string& path, BakeSettings& settings,
                BakeStats& stats) {
  try {
    const auto meta = nlohmann::json::parse(bytes.begin(), bytes.end());
    fromJson(meta.at("settings"), settings);
    fromJson(meta.at("stats"), stats);
  } catch (const nlohmann::json::exception& e) {
    fail("{}: corrupt metadata section: {}", path, e.what());
  }
}

// --- Files -------------------------------------------------------------------------------

std::string errnoText() { return std::strerror(errno); }

/// An open file descriptor, closed on scope exit.
struct FileHandle {
  int fd = -1;
  ~FileHandle() {
    if (fd >= 0) ::close(fd);
  }
};

void writeAll(int fd, const void* data, size_t size, const std::string& tempPath) {
  auto* p = static_cast<const unsigned char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, std::min<size_t>(size, size_t(1) << 30));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("{}: write failed: {}", tempPath, errnoText());
    }
    p += n;
    size -= size_t(n);
  }
}

/// Reads exactly `size` bytes at `offset` (the caller has checked they exist).
void readAt(int fd, uint64_t offset, void* data, uint64_t size, const std::string& path) {
  auto* p = static_cast<unsigned char*>(data);
  while (size > 0) {
    const ssize_t n = ::pread(fd, p, std::min<uint64_t>(size, uint64_t(1) << 30), off_t(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("{}: read failed: {}", path, errnoText());
    }
    if (n == 0) fail("{}: unexpected end of file at byte {} (the file shrank while being read?)", path, offset);
    p += n;
    offset += uint64_t(n);
    size -= uint64_t(n);
  }
}

struct SectionEntry {
  char id[4];
  uint32_t encoding;
  uint64_t offset, storedSize, decodedSize, checksum, reserved;
};
static_assert(sizeof(SectionEntry) == kPlfSectionEntrySize);

struct Header {
  char magic[8];
  uint32_t version;
  uint32_t sectionCount;
  uint64_t fileSize;
  uint64_t headerHash;
};
static_assert(sizeof(Header) == kPlfHeaderSize);

uint64_t headerHash(const Header& header, const std::vector<SectionEntry>& table) {
  Xxh64Stream stream;
  stream.update(&header, offsetof(Header, headerHash));
  stream.update(table.data(), table.size() * sizeof(SectionEntry));
  return stream.digest();
}

/// An opened, structurally validated .plf file: header and section table checked, every
/// section known (for the file's version), at most once, raw (VALS: a known codec), inside
/// the file, in order and without overlap, and every required section present (all but
/// SMSK). Section contents are read (and checksummed) on demand.
class PlfReader {
 public:
  explicit PlfReader(const std::string& path) : path_(path) {
    requireRegularFile(path);  // before open(2), which would block on a FIFO
    file_.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (file_.fd < 0) failFile(path, "{}: cannot open light field: {}", path, errnoText());
    struct stat st {};
    if (::fstat(file_.fd, &st) != 0) fail("{}: cannot stat: {}", path, errnoText());
    if (!S_ISREG(st.st_mode)) fail("{}: not a regular file", path);
    actualSize_ = uint64_t(st.st_size);

    if (actualSize_ == 0) fail("{}: empty file, not a plenoptic light field", path);
    Header header{};
    readAt(file_.fd, 0, &header, std::min<uint64_t>(actualSize_, sizeof(Header)), path);
    const size_t magicBytes = std::min<size_t>(actualSize_, kPlfMagic.size());
    if (std::memcmp(header.magic, kPlfMagic.data(), magicBytes) != 0)
      fail("{}: not a plenoptic light field (wrong magic number)", path);
    if (actualSize_ < kPlfMagic.size())
      fail("{}: truncated: the file ends at byte {} inside the {}-byte header", path, actualSize_, kPlfHeaderSize);
    if (actualSize_ < offsetof(Header, sectionCount))
      fail("{}: truncated: the file ends at byte {} inside the {}-byte header", path, actualSize_, kPlfHeaderSize);
    if (header.version < kPlfOldestReadableVersion || header.version > kPlfVersion)
      fail("{}: unsupported .plf format version {} (this build of plenoptic reads versions {} to {}); "
           "re-bake the scene with this build",
           path, header.version, kPlfOldestReadableVersion, kPlfVersion);
    if (actualSize_ < sizeof(Header))
      fail("{}: truncated: the file ends at byte {} inside the {}-byte header", path, actualSize_, kPlfHeaderSize);
    version_ = header.version;
    if (header.sectionCount > kMaxSections)
      fail("{}: corrupt header: {} sections (at most {} exist)", path, header.sectionCount, kMaxSections);
    const uint64_t tableEnd = sizeof(Header) + uint64_t(header.sectionCount) * sizeof(SectionEntry);
    if (tableEnd > actualSize_)
      fail("{}: truncated: the section table needs bytes [{}, {}) but the file has {} bytes", path, sizeof(Header),
           tableEnd, actualSize_);
    table_.resize(header.sectionCount);
    readAt(file_.fd, sizeof(Header), table_.data(), table_.size() * sizeof(SectionEntry), path);
    if (headerHash(header, table_) != header.headerHash)
      fail("{}: corrupt header or section table (checksum mismatch)", path);
    fileSize_ = header.fileSize;

    // From here on the header is trusted: a size mismatch is a truncation or an append.
    int found[kSectionKinds];
    std::fill(std::begin(found), std::end(found), -1);
    uint64_t previousEnd = tableEnd;
    for (size_t i = 0; i < table_.size(); ++i) {
      const SectionEntry& e = table_[i];
      const std::string id(e.id, 4);
      const auto kind = std::find(std::begin(kSectionIds), std::end(kSectionIds), id) - std::begin(kSectionIds);
      if (kind == kSectionKinds || version_ < firstVersionWith(int(kind)))
        fail("{}: unknown section '{}' in a version {} file", path, id, version_);
      if (found[kind] >= 0) fail("{}: section {} appears twice", path, id);
      found[kind] = int(i);
      const bool compressedValues = kind == kValues && e.encoding != uint32_t(ValuesCodec::Raw);
      const bool zstd = kind != kValues && e.encoding == kPlfSectionZstd;
      if (e.encoding != uint32_t(ValuesCodec::Raw) && !(kind == kValues && isKnownValuesCodec(e.encoding)) && !zstd)
        fail("{}: section {} uses encoding {}, which this build does not know", path, id, e.encoding);
      if (zstd && e.decodedSize / kZstdMaxExpansion > e.storedSize)
        fail("{}: corrupt section table: zstd section {} of {} bytes cannot decode to {} bytes", path, id,
             e.storedSize, e.decodedSize);
      if (compressedValues && e.decodedSize % sizeof(Rgb) != 0)
        fail("{}: corrupt section table: compressed section {} decodes to {} bytes, not a whole number of RGB "
             "float triplets",
             path, id, e.decodedSize);
      if (!compressedValues && !zstd && e.decodedSize != e.storedSize)
        fail("{}: section {} is raw but its decoded size {} differs from its stored size {}", path, id,
             e.decodedSize, e.storedSize);
      if (e.offset < previousEnd || e.storedSize > fileSize_ || e.offset > fileSize_ - e.storedSize)
        fail("{}: corrupt section table: section {} at [{}, +{}) overlaps another or lies outside the {}-byte file",
             path, id, e.offset, e.storedSize, fileSize_);
      previousEnd = e.offset + e.storedSize;
    }
    for (int kind = 0; kind < kSectionKinds; ++kind)
      if (found[kind] < 0 && isRequiredSection(kind))
        fail("{}: the {} section ({}) is missing", path, kSectionNames[kind], kSectionIds[kind]);
    std::copy(std::begin(found), std::end(found), std::begin(entryOf_));

    if (actualSize_ < fileSize_) {
      for (const SectionEntry& e : table_)
        if (e.offset + e.storedSize > actualSize_)
          fail("{}: truncated: section {} needs bytes [{}, {}) ({} bytes) but the file ends at byte {} "
               "({} of {} bytes present)",
               path, std::string(e.id, 4), e.offset, e.offset + e.storedSize, e.storedSize, actualSize_,
               actualSize_ > e.offset ? actualSize_ - e.offset : 0, e.storedSize);
      fail("{}: truncated: {} bytes expected, {} present", path, fileSize_, actualSize_);
    }
    if (actualSize_ > fileSize_)
      fail("{}: {} unexpected bytes after the end of the light field ({} bytes expected)", path,
           actualSize_ - fileSize_, fileSize_);
    checkPadding(tableEnd);
  }

  /// Whether the file holds the section (always, for a required one).
  bool has(int kind) const { return entryOf_[kind] >= 0; }
  /// The section's table entry; the section must be present (has).
  const SectionEntry& entry(int kind) const { return table_[size_t(entryOf_[kind])]; }
  uint32_t version() const { return version_; }
  uint64_t fileSize() const { return fileSize_; }
  const std::vector<SectionEntry>& table() const { return table_; }

  /// The section's bytes, checksum verified.
  std::vector<unsigned char> read(int kind) const {
    const SectionEntry& e = entry(kind);
    std::vector<unsigned char> bytes(e.storedSize);
    readInto(kind, bytes.data());
    return bytes;
  }
  /// The section's decoded bytes (read(kind) unless it is zstd: decompressed, checked against
  /// its decoded size and its frame's content checksum).
  std::vector<unsigned char> decoded(int kind) const {
    std::vector<unsigned char> stored = read(kind);
    const SectionEntry& e = entry(kind);
    if (e.encoding != kPlfSectionZstd) return stored;
    return detail::zstdDecompress(stored, e.decodedSize,
                                  fmt::format("{}: {} section ({})", path_, kSectionNames[kind], kSectionIds[kind]));
  }
  /// Reads the section into memory the caller sized to storedSize, checksum verified.
  void readInto(int kind, void* destination) const {
    const SectionEntry& e = entry(kind);
    readAt(file_.fd, e.offset, destination, e.storedSize, path_);
    checkHash(kind, xxh64(destination, e.storedSize));
  }
  /// Reads the section's bytes into `head` (headBytes) and then `rest` (storedSize − headBytes;
  /// headBytes ≤ storedSize), checksum verified: one pass over a section whose header and
  /// payload live in different places in memory.
  void readInto(int kind, void* head, uint64_t headBytes, void* rest) const {
    const SectionEntry& e = entry(kind);
    readAt(file_.fd, e.offset, head, headBytes, path_);
    readAt(file_.fd, e.offset + headBytes, rest, e.storedSize - headBytes, path_);
    Xxh64Stream stream;
    stream.update(head, headBytes);
    if (e.storedSize > headBytes) stream.update(rest, e.storedSize - headBytes);  // (rest may be null when empty)
    checkHash(kind, stream.digest());
  }
  /// The section's first `bytes` bytes (≤ storedSize) *without* verifying its checksum: for
  /// checking a header's sizes before allocating; the caller reads the whole section (or
  /// verifies it) before trusting anything else.
  void peek(int kind, void* destination, uint64_t bytes) const {
    readAt(file_.fd, entry(kind).offset, destination, bytes, path_);
  }
  /// Verifies a section's checksum reading it in bounded chunks; a zstd section is decoded
  /// (it is small, and its frame's own checks see damage the checksum was re-signed over).
  void verify(int kind) const {
    const SectionEntry& e = entry(kind);
    if (e.encoding == kPlfSectionZstd) {
      (void)decoded(kind);
      return;
    }
    std::vector<unsigned char> chunk(std::min<uint64_t>(e.storedSize, 1u << 20));
    Xxh64Stream stream;
    for (uint64_t done = 0; done < e.storedSize;) {
      const uint64_t n = std::min<uint64_t>(chunk.size(), e.storedSize - done);
      readAt(file_.fd, e.offset + done, chunk.data(), n, path_);
      stream.update(chunk.data(), n);
      done += n;
    }
    checkHash(kind, stream.digest());
  }

 private:
  void checkHash(int kind, uint64_t hash) const {
    if (hash != entry(kind).checksum)
      fail("{}: checksum mismatch in the {} section ({}): the file is corrupt", path_, kSectionNames[kind],
           kSectionIds[kind]);
  }
  /// The bytes between sections carry no data and no checksum; they must be zero, so that
  /// every byte of a .plf file is covered by some check.
  void checkPadding(uint64_t tableEnd) const {
    uint64_t previousEnd = tableEnd;
    unsigned char gap[kSectionAlignment];
    auto checkGap = [&](uint64_t begin, uint64_t end) {
      for (uint64_t at = begin; at < end; at += sizeof(gap)) {
        const uint64_t n = std::min<uint64_t>(sizeof(gap), end - at);
        readAt(file_.fd, at, gap, n, path_);
        if (std::any_of(gap, gap + n, [](unsigned char b) { return b != 0; }))
          fail("{}: corrupt file: non-zero padding bytes in [{}, {})", path_, begin, end);
      }
    };
    for (const SectionEntry& e : table_) {
      checkGap(previousEnd, e.offset);
      previousEnd = e.offset + e.storedSize;
    }
    checkGap(previousEnd, fileSize_);
  }

  std::string path_;
  FileHandle file_;
  uint64_t actualSize_ = 0, fileSize_ = 0;
  uint32_t version_ = 0;
  std::vector<SectionEntry> table_;
  int entryOf_[kSectionKinds] = {};
};

std::vector<PlfSectionInfo> sectionInfos(const PlfReader& reader) {
  std::vector<PlfSectionInfo> infos;
  for (const SectionEntry& e : reader.table())
    infos.push_back({std::string(e.id, 4), e.encoding, e.offset, e.storedSize, e.decodedSize, e.checksum});
  return infos;
}

/// The light field's tixel count: the sum of its charts' (saturating at 2^64 − 1, which only
/// a corrupt file reaches).
uint64_t chartTixelCount(const std::vector<Chart>& charts) {
  constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();
  uint64_t total = 0;
  for (const Chart& c : charts) total = c.tixelCount() > kMax - total ? kMax : total + c.tixelCount();
  return total;
}

/// Reads SMSK's header (of a raw section without its checksum; of a zstd one from `decoded`,
/// the whole decoded section) and checks it against the section's decoded size, the scene's
/// masked lights (sunMaskLights) and the charts' tixels, so that nothing is allocated from an
/// unchecked count. On a problem the section's checksum is verified first, so damaged bytes
/// are reported as a checksum mismatch rather than as a bad field.
SunMaskHeader checkSunMaskHeader(const PlfReader& reader, const std::string& path, const Scene& scene,
                                 const std::vector<Chart>& charts, std::span<const unsigned char> decoded) {
  const SectionEntry& e = reader.entry(kSunMasks);
  auto corrupt = [&](const std::string& problem) {
    reader.verify(kSunMasks);
    fail("{}: corrupt sun masks section (SMSK): {}", path, problem);
  };
  auto lights = [](uint64_t n) { return fmt::format("{} light{}", n, n == 1 ? "" : "s"); };
  const uint64_t size = e.decodedSize;  // = storedSize when raw (PlfReader)
  if (size < sizeof(SunMaskHeader))
    corrupt(fmt::format("{} bytes, fewer than its {}-byte header", size, sizeof(SunMaskHeader)));
  SunMaskHeader h{};
  if (e.encoding == kPlfSectionZstd) std::memcpy(&h, decoded.data(), sizeof(h));
  else reader.peek(kSunMasks, &h, sizeof(h));
  if (h.reserved != 0) corrupt(fmt::format("reserved field is {}, not 0", h.reserved));
  if (h.lightCount < 1 || h.lightCount > kMaxSunMaskLights)
    corrupt(fmt::format("light count {} (must be 1 to {})", h.lightCount, kMaxSunMaskLights));
  const size_t maskedLights = sunMaskLights(scene).size();
  if (h.lightCount != maskedLights)
    corrupt(fmt::format("masks of {} per tixel, but the scene has {} masked light{} (its first {} directional "
                        "lights, none when a material is thin glass)",
                        lights(h.lightCount), maskedLights, maskedLights == 1 ? "" : "s", kMaxSunMaskLights));
  const uint64_t payload = size - sizeof(SunMaskHeader);
  const uint64_t perTixel = uint64_t(h.lightCount) * sizeof(SunMask);
  if (payload % perTixel != 0 || h.tixelCount != payload / perTixel) {
    const bool fits = h.tixelCount <= (std::numeric_limits<uint64_t>::max() - sizeof(SunMaskHeader)) / perTixel;
    corrupt(fmt::format("the section has {} bytes, but its {}-byte header and the masks of {} tixels × {} × {} bytes "
                        "need {}",
                        size, sizeof(SunMaskHeader), h.tixelCount, lights(h.lightCount), sizeof(SunMask),
                        fits ? std::to_string(sizeof(SunMaskHeader) + h.tixelCount * perTixel)
                             : std::string("more than 2^64")));
  }
  const uint64_t tixels = chartTixelCount(charts);
  if (h.tixelCount != tixels)
    corrupt(fmt::format("masks for {} tixels, but the charts have {} tixels", h.tixelCount, tixels));
  return h;
}

/// SMSK decoded whole when it is zstd (for checkSunMaskHeader and the masks), else empty: a raw
/// one is read straight into the light field.
std::vector<unsigned char> decodedSunMasks(const PlfReader& reader) {
  return reader.entry(kSunMasks).encoding == kPlfSectionZstd ? reader.decoded(kSunMasks)
                                                             : std::vector<unsigned char>{};
}

}  // namespace

void writeLightField(const std::string& path, const LightField& lf, ValuesCodec valuesEncoding) {
  writeLightField(path, lf, valuesEncoding, ValuesCodecOptions{});
}

void writeLightField(const std::string& path, const LightField& lf, ValuesCodec valuesEncoding,
                     const ValuesCodecOptions& codecOptions) {
  // Sun masks that a reader would refuse are a programming error: refused before anything is
  // written (lightfield.h: count 0 and no masks, or sunMaskLights(scene) masks per tixel).
  const uint64_t tixels = chartTixelCount(lf.charts);
  const size_t maskedLights = sunMaskLights(lf.scene).size();
  if (lf.sunMaskLightCount != 0 && lf.sunMaskLightCount != maskedLights)
    fail("{}: cannot write the light field: it has sun masks of {} light{} per tixel, but its scene has {} masked "
         "light{} (sunMaskLights)",
         path, lf.sunMaskLightCount, lf.sunMaskLightCount == 1 ? "" : "s", maskedLights, maskedLights == 1 ? "" : "s");
  if (lf.sunMaskLightCount == 0 ? !lf.sunMasks.empty()
                                : lf.sunMasks.size() % lf.sunMaskLightCount != 0 ||
                                      lf.sunMasks.size() / lf.sunMaskLightCount != tixels)
    fail("{}: cannot write the light field: it holds {} sun masks, but {} masked light{} × {} tixels need {}", path,
         lf.sunMasks.size(), lf.sunMaskLightCount, lf.sunMaskLightCount == 1 ? "" : "s", tixels,
         uint64_t(lf.sunMaskLightCount) * tixels);

  // Encode the small sections; raw values and sun masks are written straight from the
  // LightField, compressed values from their encoded stream (compression.h).
  static_assert(sizeof(Rgb) == 12, "VALS stores float32 RGB triplets");
  const std::vector<unsigned char> scene = encodeScene(lf.scene);
  const std::vector<unsigned char> charts = encodeCharts(lf.charts);
  const std::vector<unsigned char> triangleCharts = encodeTriangleCharts(lf.triangleChart);
  const std::vector<unsigned char> meta = encodeMeta(lf);
  std::vector<unsigned char> compressedValues;
  if (valuesEncoding != ValuesCodec::Raw) {
    if (!isKnownValuesCodec(uint32_t(valuesEncoding)))
      fail("{}: unknown values encoding {}", path, uint32_t(valuesEncoding));
    compressedValues = encodeValues(ValuesCodec(valuesEncoding), lf.charts, lf.values, codecOptions);
  }
  const std::span<const unsigned char> rawValues{reinterpret_cast<const unsigned char*>(lf.values.data()),
                                                 lf.values.size() * sizeof(Rgb)};
  const SunMaskHeader sunMaskHeader{lf.sunMaskLightCount, 0, tixels};
  const std::span<const unsigned char> sunMasks{reinterpret_cast<const unsigned char*>(lf.sunMasks.data()),
                                                lf.sunMasks.size() * sizeof(SunMask)};

  // Each section's stored bytes: one or two parts (SMSK's header and its masks), in kind order;
  // SMSK only when the light field has sun masks. With compressed values every section but VALS
  // and META (small, and readable as text) is stored as one zstd frame instead (kPlfSectionZstd).
  struct OutSection {
    int kind;
    std::span<const unsigned char> parts[2];
    bool zstd = false;         ///< parts[0] is the zstd frame of decodedSize raw bytes
    uint64_t decodedSize = 0;
    uint64_t size() const { return parts[0].size() + parts[1].size(); }
  };
  std::vector<OutSection> sections = {
      {kScene, {scene, {}}},
      {kCharts, {charts, {}}},
      {kTriangleCharts, {triangleCharts, {}}},
      {kValues,
       {valuesEncoding == ValuesCodec::Raw ? rawValues : std::span<const unsigned char>(compressedValues), {}}}};
  if (lf.sunMaskLightCount > 0)
    sections.push_back(
        {kSunMasks,
         {{reinterpret_cast<const unsigned char*>(&sunMaskHeader), sizeof(sunMaskHeader)}, sunMasks}});
  sections.push_back({kMeta, {meta, {}}});
  std::vector<std::vector<unsigned char>> zstdFrames;
  zstdFrames.reserve(sections.size());
  if (valuesEncoding != ValuesCodec::Raw)
    for (OutSection& section : sections) {
      if (section.kind == kValues || section.kind == kMeta) continue;
      std::vector<unsigned char> raw(section.parts[0].begin(), section.parts[0].end());
      raw.insert(raw.end(), section.parts[1].begin(), section.parts[1].end());
      zstdFrames.push_back(detail::zstdCompress(raw, codecOptions.zstdLevel));
      section.zstd = true;
      section.decodedSize = raw.size();
      section.parts[0] = zstdFrames.back();
      section.parts[1] = {};
    }

  Header header{};
  std::memcpy(header.magic, kPlfMagic.data(), kPlfMagic.size());
  header.version = kPlfVersion;
  header.sectionCount = uint32_t(sections.size());
  std::vector<SectionEntry> table(sections.size());
  uint64_t offset = alignUp(sizeof(Header) + table.size() * sizeof(SectionEntry));
  for (size_t i = 0; i < sections.size(); ++i) {
    const OutSection& section = sections[i];
    SectionEntry& e = table[i];
    std::memcpy(e.id, kSectionIds[section.kind], 4);
    e.encoding = section.kind == kValues ? uint32_t(valuesEncoding)
                 : section.zstd ? kPlfSectionZstd
                                : uint32_t(ValuesCodec::Raw);
    e.offset = offset;
    e.storedSize = e.decodedSize = section.size();
    if (section.kind == kValues) e.decodedSize = rawValues.size();
    if (section.zstd) e.decodedSize = section.decodedSize;
    Xxh64Stream stream;
    for (const auto& part : section.parts)
      if (!part.empty()) stream.update(part.data(), part.size());
    e.checksum = stream.digest();
    e.reserved = 0;
    offset = alignUp(offset + e.storedSize);
  }
  // The last section is not padded: the file ends where its data ends.
  header.fileSize = table.back().offset + table.back().storedSize;
  header.headerHash = headerHash(header, table);

  // Atomic and durable (core/file_io.h): a temporary file in the same directory (same file
  // system), fsynced, renamed over `path`, then the directory fsynced; removed on any failure.
  writeFileAtomically(
      path,
      [&](const std::string& tempPath) {
        FileHandle file;
        // Mode 0666 before the umask, like any newly created file.
        file.fd = ::open(tempPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
        if (file.fd < 0) fail("cannot create the temporary file {}: {}", tempPath, errnoText());
        writeAll(file.fd, &header, sizeof(header), tempPath);
        writeAll(file.fd, table.data(), table.size() * sizeof(SectionEntry), tempPath);
        uint64_t written = sizeof(header) + table.size() * sizeof(SectionEntry);
        const unsigned char zeros[kSectionAlignment] = {};
        for (size_t i = 0; i < sections.size(); ++i) {
          writeAll(file.fd, zeros, table[i].offset - written, tempPath);
          for (const auto& part : sections[i].parts) writeAll(file.fd, part.data(), part.size(), tempPath);
          written = table[i].offset + sections[i].size();
        }
        const int fd = file.fd;
        file.fd = -1;
        if (::close(fd) != 0) fail("{}: close failed: {}", tempPath, errnoText());
      },
      FileSync::durable);
}

LightField readLightField(const std::string& path) {
  const PlfReader reader(path);
  LightField lf;
  lf.scene = decodeScene(reader.decoded(kScene), path, reader.version());
  lf.charts = decodeCharts(reader.decoded(kCharts), path, lf.scene.materials);
  lf.triangleChart = decodeTriangleCharts(reader.decoded(kTriangleCharts), path, lf.scene, lf.charts);
  const SectionEntry& values = reader.entry(kValues);
  const uint64_t valueBytes = values.decodedSize;
  if (valueBytes % sizeof(Rgb) != 0)
    fail("{}: corrupt values section: {} bytes is not a whole number of RGB float triplets", path, valueBytes);
  if (values.encoding == uint32_t(ValuesCodec::Raw)) {
    lf.values.resize(valueBytes / sizeof(Rgb));  // bounded by the file's size, checked above
    reader.readInto(kValues, lf.values.data());
  } else {
    // The charts are checked against the declared count before anything is decoded.
    checkChartRanges(lf.charts, valueBytes / sizeof(Rgb), path);
    lf.values = decodeValues(ValuesCodec(values.encoding), lf.charts, valueBytes / sizeof(Rgb), reader.read(kValues),
                             fmt::format("{}: {} values in the values section (VALS)", path,
                                         valuesCodecName(ValuesCodec(values.encoding))));
  }
  checkChartRanges(lf.charts, lf.values.size(), path);
  if (reader.has(kSunMasks)) {
    // Sizes checked against the section's (file-bounded) size before the masks are allocated.
    const std::vector<unsigned char> decoded = decodedSunMasks(reader);
    const SunMaskHeader header = checkSunMaskHeader(reader, path, lf.scene, lf.charts, decoded);
    lf.sunMasks.resize(header.tixelCount * header.lightCount);  // = (decodedSize − 16) / 2
    if (reader.entry(kSunMasks).encoding == kPlfSectionZstd) {
      std::memcpy(lf.sunMasks.data(), decoded.data() + sizeof(header), lf.sunMasks.size() * sizeof(SunMask));
    } else {
      SunMaskHeader again{};
      reader.readInto(kSunMasks, &again, sizeof(again), lf.sunMasks.data());
      if (std::memcmp(&again, &header, sizeof(header)) != 0)
        fail("{}: the sun masks section (SMSK) changed while being read", path);
    }
    lf.sunMaskLightCount = header.lightCount;
  }  // else none: sunMaskLightCount 0, sunMasks empty (a file baked without them, or of version 1 or 2)
  decodeMeta(reader.decoded(kMeta), path, lf.settings, lf.stats);
  return lf;
}

PlfInfo readLightFieldInfo(const std::string& path, bool verifyChecksums) {
  const PlfReader reader(path);
  PlfInfo info;
  info.path = path;
  info.version = reader.version();
  info.fileBytes = reader.fileSize();
  info.sections = sectionInfos(reader);

  const Scene scene = decodeScene(reader.decoded(kScene), path, reader.version(), TextureDecoding::Skip);
  info.sceneSource = scene.sourcePath;
  info.meshes = scene.meshes.size();
  for (const Mesh& m : scene.meshes) {
    info.triangles += m.triangles.size();
    info.vertices += m.positions.size();
  }
  info.materials = scene.materials.size();
  for (const Material& m : scene.materials) info.materialModels.push_back(modelName(m.bsdf));
  info.textures = scene.textures.size();
  info.lights = scene.lights.size();
  for (const CameraDesc& c : scene.cameras) info.cameraNames.push_back(c.name);
  info.environment = scene.environment.constant;
  if (const EnvironmentMap* map = scene.environment.map.get()) {
    info.environmentMapWidth = uint32_t(map->map().width());
    info.environmentMapHeight = uint32_t(map->map().height());
    info.environmentMapScale = map->scale();
    info.environmentMapRotationDegrees = map->rotationDegrees();
  }

  const std::vector<Chart> charts = decodeCharts(reader.decoded(kCharts), path, scene.materials);
  info.charts = charts.size();
  for (const Chart& c : charts) {
    info.diffuseCharts += c.kind == ChartKind::Diffuse;
    info.glossyCharts += c.kind == ChartKind::Glossy;
    info.specularCharts += c.kind == ChartKind::Specular;
    info.twoSidedCharts += c.isBack;
    info.curvedCharts += c.curved;
    info.tixels += c.tixelCount();
  }
  info.values = reader.entry(kValues).decodedSize / sizeof(Rgb);
  if (reader.has(kSunMasks))
    info.sunMaskLights = checkSunMaskHeader(reader, path, scene, charts, decodedSunMasks(reader)).lightCount;
  decodeMeta(reader.decoded(kMeta), path, info.settings, info.stats);
  if (verifyChecksums) {
    reader.verify(kTriangleCharts);
    reader.verify(kValues);
    if (reader.has(kSunMasks)) reader.verify(kSunMasks);
    info.checksumsVerified = true;
  }
  return info;
}

std::vector<unsigned char> encodeSceneSection(const Scene& scene) { return encodeScene(scene); }

}  // namespace pl
