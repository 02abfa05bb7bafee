#pragma once
// The light-field file (.plf): a LightField — its embedded Scene, charts, triangle → chart
// map, HDR values, sun masks, bake settings and statistics — in one self-contained binary file.
//
// Layout (all integers and floats little-endian; offsets and sizes in bytes):
//
//   offset 0   header (kPlfHeaderSize = 32 bytes)
//              magic        8 bytes  "PLF\0\r\n\x1a\n"  (the PNG trick: a text-mode transfer
//                                     or a truncation to 7 bits corrupts it visibly)
//              version      u32      kPlfVersion
//              sectionCount u32
//              fileSize     u64      total bytes; a shorter file is truncated
//              headerHash   u64      XXH64 (seed 0) of header bytes [0, 24) followed by the
//                                     section table: covers every field except itself
//   offset 32  section table: sectionCount entries of 48 bytes
//              id           4 bytes  four-character code, see Sections below
//              encoding     u32      0 = raw; VALS may also be 1 = lossless, 2 = bc1, 3 = hdr
//                                     (ValuesCodec numbers, plf/compression.h); every other
//                                     section may be 4 = zstd (kPlfSectionZstd)
//              offset       u64      from the start of the file, 64-byte aligned
//              storedSize   u64      bytes in the file
//              decodedSize  u64      bytes after decoding (= storedSize when raw; for a
//                                     compressed VALS, 12 × the value count; for zstd, the
//                                     raw section's size)
//              checksum     u64      XXH64 of the stored bytes (seed 0)
//              reserved     u64      0
//   sections, each at its offset, in table order, zero padding between them (checked).
//
// Sections (SMSK optional, every other one present exactly once; the writer stores them in
// this order, a reader accepts them in any order in the table; a section id the file's version does not have,
// such as SMSK in a version 1 or 2 file, is refused as unknown):
//   SCNE  the Scene: meshes, materials (every BSDF variant's parameters), textures, lights,
//         cameras, the environment (constant and lat-long map with its scale and rotation)
//         and the scene file's suggested settings. Everything a renderer needs. A texture
//         is its path, a storage byte and either (1) the bytes of its image file as the
//         scene had it (PNG/JPEG/TGA/BMP, decoded on load with decodeLdrImage as the texture's
//         ImageDecode says: the pixels the scene loader had) or (0) float32 RGB pixels
//         (textures from HDR files); see encodeScene in plf_file.cpp. Optionally followed by
//         a surface-detail block, written only when a material has an alpha mask or a normal
//         map or a texture is not colour (version ≥ 5: a metallic-roughness texture): u32 tag "SDTL", then per material i32 alphaTexture, f32 alphaFactor,
//         f32 alphaCutoff, i32 normalTexture, f32 normalScale, then per texture u8 ImageDecode
//         (image.h: 0 colour, 1 data, 2 coverage). Without the block materials have no mask
//         or normal map and textures are colour. Then (version ≥ 5), only when the scene has a
//         second uv set, vertex colours, a texture mapping other than TEXCOORD_0 as it is, a
//         metallic-roughness texture or a texture sampling other than repeat/bilinear/mip-mapped
//         (encodeScene's needsTexturingBlock), a texturing block: u32 tag "TXMP"; per mesh
//         u64 count + Vec2 second uvs, u64 count + Rgb vertex colours; per material the albedo,
//         alpha and normal mappings (TextureMapping: u8 uv set, 4 f32 linear part column by
//         column, 2 f32 offset), i32 metallic-roughness texture, its mapping, Rgb base colour,
//         f32 metallic, f32 roughness; per texture u8 wrapU, u8 wrapV (TextureWrap), u8 nearest,
//         u8 mipmaps. Without it every mapping, map and sampling is the default. Then
//         (version ≥ 5), only when a material has an emission texture, an emission-texture
//         block: u32 tag "EMTX"; per material i32 emissionTexture (−1: none) and its
//         TextureMapping. Without it no material has one (files written before emission
//         textures read unchanged; a reader from before them refuses a file with the block).
//         Then (version ≥ 6), only when a mesh has vertex alphas (Mesh::alphas), a
//         vertex-alpha block: u32 tag "VALP"; per mesh u64 count + f32 alphas. Without it no
//         mesh has them (likewise: older files read unchanged, older readers refuse it).
//   CHRT  the charts: u64 count, then fixed 85-byte records (see encodeCharts in plf_file.cpp).
//         The kind byte's bit 4 (version ≥ 4) marks a glossy chart whose tixels keep their
//         diffuse irradiance after their map (Chart::diffuseValue, lightfield.h); bit 3
//         (version ≥ 5) a diffuse chart whose tixels keep tilted irradiances after their
//         irradiance, or a glossy chart with bit 4 whose tixels keep them after their diffuse
//         irradiance (Chart::directionalIrradiance).
//   TRCH  triangle → chart: u64 mesh count, then per mesh u64 triangle count + u32 indices.
//   VALS  the values: float32 RGB triplets (12 bytes each), in LightField::values order.
//         Compressed (encoding ≠ 0): a stream of plf/compression.h.
//   SMSK  (version ≥ 3, optional) the sun masks (lightfield.h "Sun masks"), written only when
//         LightField::sunMaskLightCount > 0; absent = no masks (count 0). Always raw:
//           lightCount   u32   L, 1 to kMaxSunMaskLights; must equal sunMaskLights(scene).size()
//           reserved     u32   0
//           tixelCount   u64   T, must equal the charts' tixel count (Σ resU·resV)
//           masks        T × L u16, in LightField::sunMasks order (tixel-major: light l of
//                        tixel g at g·L + l; bit b·4 + a = sub-sample (a, b) lit)
//         so the section is exactly 16 + 2·T·L bytes.
//   META  UTF-8 JSON: {"settings": BakeSettings, "stats": BakeStats}.
//
// Versions: 1 textures as float pixels; 2 textures as their image file's bytes; 3 an optional
// SMSK section (sun masks); 4 glossy charts with a diffuse value per tixel (CHRT bit 4); 5 the
// SCNE texturing block and normal-mapped diffuse charts with tilted irradiances (CHRT bit 3); 6
// the glTF model's (BSDF 5) dielectric Fresnel after its other parameters. A
// file without sun masks differs from version 2 only in the version field (and so the header
// hash); a version 3 file from version 4 only there when no chart has the bit; a version 4 file
// from version 5 only there when the scene has no texturing block and no chart has bit 3; a
// version 5 file from version 6 only there when no material has the glTF model.
//
// The version is checked right after the magic, before anything else is interpreted, so a
// future layout can change everything after it (versions 1 to kPlfVersion are read). Reading never trusts the file: the magic,
// version, header hash, every section's bounds and
// checksum, and every count inside a section (against the bytes that remain) are checked
// before anything is allocated, and all indices are range-checked. Any problem throws
// pl::Error naming the file and the section.
#include "lightfield/lightfield.h"
#include "plf/compression.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pl {

/// The version written. 2: textures store their image file's bytes (PNG/JPEG/…) instead of
/// float pixels. 3: an optional SMSK section (sun masks). 4: glossy charts may keep a diffuse
/// value per tixel (the textured-glossy fix; older files' glossy maps hold all of Lo, which
/// is what a chart without it means). 5: SCNE may end with a texturing block (glTF texture
/// mappings, second uv sets, vertex colours, metallic-roughness textures, samplers), and
/// normal-mapped diffuse charts may keep tilted irradiances per tixel (older files show such
/// charts flat, which is what a chart without them means). 6: the glTF model (BSDF 5) ends
/// with its dielectric Fresnel (bsdf.h GltfPbrBsdf: fractional metalness as glTF mixes it).
/// Readers also read versions 1 (the same as 2 but for the texture records), 2 (as 3, never
/// with SMSK), 3 (as 4, never with the chart bit), 4 (as 5, never with the texturing block or
/// CHRT bit 3) and 5 (as 6, the glTF model without its dielectric Fresnel, which is then the
/// lobe's: the diffuse coupled to the whole lobe, what version 5 meant).
inline constexpr uint32_t kPlfVersion = 6;
inline constexpr uint32_t kPlfOldestReadableVersion = 1;
inline constexpr size_t kPlfHeaderSize = 32;
inline constexpr size_t kPlfSectionEntrySize = 48;
inline constexpr std::array<char, 8> kPlfMagic = {'P', 'L', 'F', '\0', '\r', '\n', '\x1a', '\n'};

// How a section's bytes are stored is a ValuesCodec number (plf/compression.h; a reader
// refuses modes it does not know, naming the section). Every section may be Raw; only VALS
// may use the value codecs, and every section but VALS may be kPlfSectionZstd. The checksum
// covers the stored (compressed) bytes; decoding happens in readLightField, so every reader
// gets it.

/// Section encoding 4 (any section but VALS): the raw section's bytes as exactly one zstd
/// frame with its content size and content checksum; decodedSize is the raw size. Written
/// for SCNE, CHRT, TRCH and SMSK whenever the values are compressed (writeLightField), never
/// by `--compress none`, whose files stay readable by builds older than this encoding (which
/// refuse a zstd section naming it and its encoding). Not a ValuesCodec: those are 0–3.
inline constexpr uint32_t kPlfSectionZstd = 4;

/// One entry of the section table, as stored.
struct PlfSectionInfo {
  std::string id;  ///< "SCNE", "CHRT", "TRCH", "VALS", "SMSK" (optional), "META"
  uint32_t encoding = 0;
  uint64_t offset = 0, storedSize = 0, decodedSize = 0, checksum = 0;
};

/// What `plenoptic info` shows, read without decoding the big sections (VALS, TRCH and SMSK
/// are only checksummed, in chunks; SMSK's 16-byte header is read and checked).
struct PlfInfo {
  std::string path;
  uint32_t version = 0;
  uint64_t fileBytes = 0;
  std::vector<PlfSectionInfo> sections;
  bool checksumsVerified = false;  ///< every section's checksum was recomputed and matched
  // Scene summary (decoded from SCNE).
  std::string sceneSource;
  uint64_t meshes = 0, triangles = 0, vertices = 0, materials = 0, textures = 0, lights = 0;
  std::vector<std::string> cameraNames;
  std::vector<std::string> materialModels;  ///< modelName() of every material, in order
  Rgb environment{0.0f};  ///< the constant part
  uint32_t environmentMapWidth = 0, environmentMapHeight = 0;  ///< lat-long map; 0 = none
  float environmentMapScale = 1.0f, environmentMapRotationDegrees = 0.0f;
  // Charts (decoded from CHRT).
  uint64_t charts = 0, diffuseCharts = 0, glossyCharts = 0, specularCharts = 0;  ///< chart records
  uint64_t twoSidedCharts = 0;  ///< back records (each two-sided chart has one; lightfield.h "Sides")
  uint64_t curvedCharts = 0;    ///< curved chart records (lightfield.h; diffuse or glossy, counted there too)
  uint64_t tixels = 0, values = 0;
  uint32_t sunMaskLights = 0;  ///< masks per tixel (SMSK's light count); 0 = no SMSK section
  // Bake settings and statistics (from META).
  BakeSettings settings;
  BakeStats stats;
};

/// Writes the light field atomically: a temporary file beside `path` is written, fsynced
/// and renamed over it; on any failure the temporary file is removed and pl::Error thrown.
/// `valuesEncoding` selects how the VALS section is stored (compression.h); any codec but Raw
/// also stores SCNE, CHRT, TRCH and SMSK as zstd frames (kPlfSectionZstd), Raw every section raw.
void writeLightField(const std::string& path, const LightField& lightField,
                     ValuesCodec valuesEncoding = ValuesCodec::Raw);

/// The same with the value codec's tuning (zstd level, also the other sections', hdr steps per stop).
void writeLightField(const std::string& path, const LightField& lightField, ValuesCodec valuesEncoding,
                     const ValuesCodecOptions& codecOptions);

/// Reads and fully validates a .plf file (see the header comment). The embedded scene is
/// finalized (vertex buffers padded for Embree) and ready for an Accel.
LightField readLightField(const std::string& path);

/// Reads the header, the section table, the scene, charts and metadata; the checksums of
/// the other sections are recomputed in bounded chunks when verifyChecksums is set.
PlfInfo readLightFieldInfo(const std::string& path, bool verifyChecksums = true);

/// The scene section's bytes (SCNE) for `scene`: everything a light field keeps of it —
/// geometry, materials, textures, lights, environment. A bake hashes them to tell whether a
/// saved propagation state is this scene's (bake/resume.h).
std::vector<unsigned char> encodeSceneSection(const Scene& scene);

}  // namespace pl
