#pragma once
// The visibility field's data and its .plv file, which keeps a traced field beside the light
// field so that a bake whose geometry, parameterisation and settings are unchanged reuses it
// (bake/visibility.h traces it and says what its directions are; bake/bake.h decides reuse).
//
// .plv layout (version 3; little-endian; written by writeVisibility, validated by readVisibility):
//   header, 56 bytes:
//   magic        8 bytes  "PLVIS\0\r\n"
//   version      u32      kPlvVersion
//   gridSide     u32      m (N = m² gather directions per tixel)
//   hash         u64      visibilityHash of the bake that traced it
//   tixelCount   u64
//   entryCount   u64      = tixelCount · N
//   extraCount   u64
//   payloadHash  u64      XXH64 (seed 0, as the .plf checksums) of every byte after the header
//   payload:
//   tixelsPerBlock u64    tixels per entry block (≈ 512 KiB of entries; the last block may
//                         hold fewer): B = ⌈tixelCount / tixelsPerBlock⌉ blocks
//   frames       B zstd frames of entry blocks, in tixel order, then one zstd frame of
//                extraOffset (u64 × (tixelCount + 1)) followed by the extras (24 bytes each)
//   frameSizes   u64 × (B + 1): the stored bytes of each frame, in order
// An entry block of k entries, before zstd (encodeEntryBlock): the k targets (u32), then the
// k fu (u16), then the k fv (u16). Decoding restores the 8-byte entries below exactly,
// so a reused field gives the same light field bit for bit. Version 2 was the raw entries
// (8 bytes each, memory-mapped): a version-2 file is traced again, like a stale one.
//
// Entries (8 bytes in memory, tixel-major: entry k of tixel g at g·N + k; compressed on disk):
//   target  bits 0–29: global index of the tixel at the lower-left of the 2×2 bilinear
//                      footprint of the seen point (kEscape: nothing was hit)
//           bit 30:    the seen chart was hit from behind (its back side)
//           bit 31:    the entry has an extra record (see below)
//   fu, fv  bilinear fractions towards tixel (i+1, j) and (i, j+1), × 65535
// Extra records (rare: glossy targets and paths through mirrors), in entry order per tixel,
// starting at extraOffset[g]:
//   throughput  product of the mirror reflectances along the chain (1 without mirrors)
//   st          paraboloid coordinates, in the seen chart's frame, of the direction in which
//               the seen point sends light back along the path (glossy targets); for a path
//               that leaves the scene after mirrors, the octahedral encoding of its final
//               world direction (to look the environment up)
//   viaMirror   whether the path went through at least one mirror
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"

namespace pl {

/// The .plv format version this program reads and writes (visibilityHash includes it, so a
/// field of another version is traced again).
inline constexpr uint32_t kPlvVersion = 3;  // 2: multi-jittered gather directions; 3: compressed blocks
/// Largest gather grid side m a field may have (gatherDirections ≤ 65 536); a .plv declaring
/// more is corrupt.
inline constexpr uint32_t kMaxGatherGridSide = 256;

struct VisibilityEntry {
  static constexpr uint32_t kIndexMask = 0x3fffffffu;
  static constexpr uint32_t kEscape = kIndexMask;
  static constexpr uint32_t kBackSide = 1u << 30;
  static constexpr uint32_t kHasExtra = 1u << 31;
  uint32_t target = kEscape;
  uint16_t fu = 0, fv = 0;

  uint32_t tixel() const { return target & kIndexMask; }
  bool escaped() const { return tixel() == kEscape; }
  bool backSide() const { return (target & kBackSide) != 0; }
  bool hasExtra() const { return (target & kHasExtra) != 0; }
};
static_assert(sizeof(VisibilityEntry) == 8);

struct VisibilityExtra {
  Rgb throughput{1.0f};
  Vec2 st{0.0f};
  uint32_t viaMirror = 0;
};
static_assert(sizeof(VisibilityExtra) == 24);

/// Read-only elements of a visibility field (a field just traced, or decoded from its .plv).
/// Copies share the storage.
template <typename T>
class FieldArray {
 public:
  FieldArray() = default;
  explicit FieldArray(std::vector<T> owned) {
    auto storage = std::make_shared<const std::vector<T>>(std::move(owned));
    data_ = storage->data();
    size_ = storage->size();
    keepAlive_ = std::move(storage);
  }

  const T* data() const { return data_; }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& operator[](size_t i) const { return data_[i]; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }

 private:
  std::shared_ptr<const void> keepAlive_;
  const T* data_ = nullptr;
  size_t size_ = 0;
};

struct VisibilityField {
  uint32_t gridSide = 0;          ///< m: N = m² gather directions per tixel
  uint64_t tixelCount = 0;
  uint64_t hash = 0;              ///< of geometry + parameterisation + settings (visibilityHash)
  FieldArray<VisibilityEntry> entries;    ///< tixelCount × N
  FieldArray<uint64_t> extraOffset;       ///< tixelCount + 1
  FieldArray<VisibilityExtra> extras;
  uint64_t rays = 0;              ///< rays traced to build it (gather + mirror continuations)
  double seconds = 0.0;

  uint32_t directionsPerTixel() const { return gridSide * gridSide; }
  uint64_t bytes() const {
    return entries.size() * sizeof(VisibilityEntry) + extraOffset.size() * sizeof(uint64_t) +
           extras.size() * sizeof(VisibilityExtra);
  }
};

/// Writes the field atomically (temp + rename), compressed: zstd frames of blocks of
/// entries split into index and fraction planes (format: above), with a progress bar.
void writeVisibility(const std::string& path, const VisibilityField& field);

/// Bytes writeVisibility holds besides the field itself (one batch of blocks and frames).
uint64_t visibilityWriteBufferBytes(uint32_t gridSide);

/// Reads and decodes a field into memory (the in-memory layout above: the bytes the bake's
/// memory estimate counts, checked with requireMemory before allocating). Returns false and
/// sets *why when the file is absent, of an older format version, or its hash differs from
/// expectedHash (a stale field is not an error); throws pl::Error naming the file when it is
/// present but corrupt or truncated (header, payload checksum, every frame and every index are
/// checked before it returns).
/// targetTixels: how many tixels the entries may point at (0: the file's own tixel count; a
/// shard's entries point at any tixel of the scene).
bool readVisibility(const std::string& path, uint64_t expectedHash, VisibilityField& field, std::string* why,
                    uint64_t targetTixels = 0);

}  // namespace pl
