#pragma once
// The tixel-setup file (.plt): the per-tixel arrays of a bake's parameterisation that the
// light field does not store (gather points and normals, footprint coverage and albedo, …:
// bake/parameterisation.h forEachTixelSetupArray names them), written beside the visibility
// field (X.plv → X.plt) so that relighting a loaded light field (bake/relight.h) takes them
// instead of filling the tixels again — the buried-point probes and footprint sub-samples that
// take minutes on a large scene. The file holds tagged arrays of fixed-size elements and knows
// nothing of their meaning; bake/parameterisation.cpp maps them to and from a Parameterisation.
//
// .plt layout (version 2; little-endian; written by writeTixelSetupFile, validated by
// readTixelSetupFile):
//   header, 48 bytes:
//   magic        8 bytes  "PLTIX\0\r\n"
//   version      u32      kPltVersion
//   arrayCount   u32      A (at most kMaxTixelSetupArrays)
//   hash         u64      visibilityHash of the bake (the hash of the .plv written with it)
//   tixelCount   u64      T
//   payloadHash  u64      XXH64 (seed 0) of every byte after the header
//   keyCount     u64      K (at most kMaxTixelSetupKeys; 0 in a version 1 file, whose field
//                         was reserved, and which is read as version 2 without keys)
//   table, A × 32 bytes, one entry per array:
//     tag          4 chars
//     elementBytes u32      1 to kMaxTixelSetupElementBytes
//     count        u64      0 (the bake does not use the array) or T
//     storedBytes  u64      the bytes of its zstd frame (0 when count is 0)
//     reserved     u64      0
//   keys, K × u64: what the writer computed the arrays from (bake/parameterisation.cpp
//     tixelSetupKeys: a hash per input, so that a reader can tell which arrays are stale)
//   frames: one zstd frame (with content checksum) per array of non-zero count, in table
//   order, holding its count × elementBytes bytes as the program holds them in memory.
// Nothing follows the last frame.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pl {

/// The .plt format version this program writes (it reads kPltOldestVersion to this); a file of
/// another version is not an error: relighting fills the tixels again, as without the file.
inline constexpr uint32_t kPltVersion = 2;
/// The oldest version read (version 1: no keys).
inline constexpr uint32_t kPltOldestVersion = 1;
/// Most arrays a .plt may hold; a file declaring more is corrupt.
inline constexpr uint32_t kMaxTixelSetupArrays = 64;
/// Largest element a .plt array may have (bytes); larger is corrupt.
inline constexpr uint32_t kMaxTixelSetupElementBytes = 256;
/// Most keys a .plt may hold; more is corrupt.
inline constexpr uint64_t kMaxTixelSetupKeys = uint64_t(1) << 20;

/// One array of a .plt: count elements of elementBytes each (count · elementBytes bytes).
struct TixelSetupArray {
  std::array<char, 4> tag{};
  uint32_t elementBytes = 1;
  uint64_t count = 0;                 ///< 0 or the file's tixel count
  std::vector<unsigned char> bytes;   ///< read: the elements; written: see TixelSetupView
};

/// An array to write, without copying it.
struct TixelSetupView {
  std::array<char, 4> tag{};
  uint32_t elementBytes = 1;
  uint64_t count = 0;                 ///< 0 or tixelCount
  const void* data = nullptr;         ///< count · elementBytes bytes
};

struct TixelSetupFile {
  uint64_t hash = 0;
  uint64_t tixelCount = 0;
  std::vector<TixelSetupArray> arrays;
  std::vector<uint64_t> keys;  ///< empty in a version 1 file
};

/// Writes the arrays atomically (temp + rename; format above), each compressed on its own
/// thread. pl::Error naming the file when an array's count is neither 0 nor tixelCount.
void writeTixelSetupFile(const std::string& path, uint64_t hash, uint64_t tixelCount,
                         std::span<const TixelSetupView> arrays, std::span<const uint64_t> keys = {});

/// Reads a .plt whose hash is expectedHash. Returns false and sets *why when the file is
/// absent, of another format version, or of another hash (not an error: the caller fills the
/// tixels itself); throws pl::Error naming the file when it is present but not a .plt, corrupt
/// or truncated (header, payload checksum, table, every frame and its size are checked; the
/// memory is checked with requireMemory before it is allocated).
bool readTixelSetupFile(const std::string& path, uint64_t expectedHash, TixelSetupFile& out, std::string* why);

}  // namespace pl
