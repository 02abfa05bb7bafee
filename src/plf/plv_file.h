#pragma once
// The visibility field's data and its .plv file, which keeps a traced field beside the light
// field so that a bake whose geometry, parameterisation and settings are unchanged reuses it
// (bake/visibility.h traces it and says what its directions are; bake/bake.h decides reuse).
//
// .plv layout (version 6; little-endian; written by writeVisibility, validated by readVisibility):
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
//   tixelsPerBlock u64    tixels per entry block (≈ 64 Ki entries; the last block may hold
//                         fewer): B = ⌈tixelCount / tixelsPerBlock⌉ blocks
//   frames       B entry blocks, in tixel order (below), then one zstd frame of extraOffset
//                (u64 × (tixelCount + 1)) followed by the extras (24 bytes each)
//   frameSizes   u64 × (B + 1): the stored bytes of each frame, in order
//   contentSizes u64 × (B + 1): per entry block, the bytes of its content as held in memory —
//                its tixels' encoded sizes (u32 each), then their compact encodings
//                ("Compact entries" below); for the last frame, the bytes it decompresses to
// A stored entry block keeps its entries in kPlvStreams byte streams, each its own zstd frame
// (docs/design.md, Visibility field, "The .plv's bytes"):
//   bits         u8       F, the bits per fraction of every tixel of the block
//   rawSizes     u32 × kPlvStreams: each stream's bytes
//   storedSizes  u32 × kPlvStreams: each stream's zstd frame's bytes (0: an empty stream, no frame)
//   frames       the streams' zstd frames, in stream order
// The streams hold the block's entries in tixel order, entry k of each tixel in turn; "previous"
// is the tixel index of the tixel's last earlier entry that saw a tixel (0 before the first):
//   ops          u8 per entry: 0 an escape (nothing seen, no extra record, fractions 0),
//                1 a hit without flags at previous + an i8 delta, 2 likewise with an i16
//                delta, 3 any other entry, its target (index and flags) whole
//   near         i8 per op 1: the delta
//   farLow       u8 per op 2: the delta's low byte
//   farHigh      u8 per op 2: the delta's high byte
//   targets      u32 per op 3: the target
//   fractions    per op 1–3: qu | qv << F in ⌈2F/8⌉ bytes (F ≤ 8), or fu, fv (u16 each; F = 16)
// Reading a block back and encoding its tixels gives the content the writer was handed, byte
// for byte (the compact encoding is a function of the entries). Version 5 stored each block's
// content as one zstd frame, version 4 had no fraction precision per tixel (always exact),
// version 3 held the raw 8-byte entries split into planes, version 2 the raw entries: an
// older field is traced again, like a stale one.
//
// Entries (8 bytes decoded; tixel-major: entry k of tixel g; held encoded, "Compact entries"):
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
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/math.h"

namespace pl {

/// The .plv format version this program reads and writes (visibilityHash includes it, so a
/// field of another version is traced again).
inline constexpr uint32_t kPlvVersion = 6;  // 2: multi-jittered gather directions; 3: compressed blocks; 4: compact entries; 5: quantised fractions; 6: entry blocks in streams
/// Byte streams of a stored entry block (layout above).
inline constexpr uint32_t kPlvStreams = 6;
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
static_assert(sizeof(VisibilityEntry) == 8 && offsetof(VisibilityEntry, fu) == 4 && offsetof(VisibilityEntry, fv) == 6);

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

// ---- Compact entries ----------------------------------------------------------------------
// In memory (and in the .plv, under zstd) a tixel's N entries are encoded one after another,
// so that the field takes a few bytes per entry instead of 8; the gather decodes each tixel's
// entries into a small buffer as it reaches it (docs/design.md, Visibility field, has the
// measurements behind this choice). The fractions are kept either whole (16 bits, "exact": the
// entries decode bit for bit as traced) or quantised to F ≤ 8 bits each ("compact", the
// default: `bake --visibility-precision`); the tixel index and the flags are always exact.
// A tixel's encoding:
//   bits     1 byte: F, the bits per fraction (16: exact; 1–8: quantised)
//   tags     ⌈N/4⌉ bytes: a 2-bit tag per entry, entry k in bits 2(k mod 4) of byte k/4
//   payload  per entry in order, by tag; exact (F = 16):
//     kTagEscape   (0) nothing: target = kEscape, fu = fv = 0 (nothing seen, no extra record)
//     kTagNear     (1) i8 delta, fu, fv (u16 each): no flags, tixel = previous + delta
//     kTagFar      (2) i16 delta, fu, fv: likewise
//     kTagGeneral  (3) LEB128 varint of zigzag(delta)·4 + (target >> 30), then fu, fv: any
//                      entry (flags set, escapes with an extra record, long jumps)
//   quantised (F ≤ 8), with levels qu = round(fu·(2^F − 1)/65535) and likewise qv:
//     kTagEscape   (0) nothing, as above (an escape whose levels are 0)
//     kTagNear     (1) nearHitBytes(F) bytes, a little-endian integer: qu in bits [0, F), qv in
//                      [F, 2F), the signed delta in the bits above (at least 4 of them)
//     kTagFar      (2) one byte more: the same with a delta 8 bits wider
//     kTagGeneral  (3) the varint as above, then ⌈2F/8⌉ bytes: qu | qv << F
//   and the fractions decode to fractionLevel(q, F) = round(q·65535/(2^F − 1)): 0 and 65535
//   (a fraction at a chart's last row or column, or at a tixel's far edge) stay exact.
// "previous" is the tixel index of the tixel's last earlier entry that saw a tixel (escapes
// leave it unchanged), 0 before the first. The delta is taken on the 30-bit index field.
// Neighbouring gather directions mostly see the same chart a few tixels apart, so most exact
// entries take 5 or 6 bytes and most quantised ones 2 or 3.
inline constexpr uint32_t kTagEscape = 0, kTagNear = 1, kTagFar = 2, kTagGeneral = 3;
/// Bits per fraction of the exact encoding, and of the compact one (docs/design.md, Visibility
/// field: the coarsest that keeps the light field within relMSE 1e-5 of the exact one, with margin).
inline constexpr uint32_t kExactFractionBits = 16, kCompactFractionBits = 2;
/// Whether a tixel's encoding may declare `bits` bits per fraction.
constexpr bool validFractionBits(uint32_t bits) { return (bits >= 1 && bits <= 8) || bits == kExactFractionBits; }
/// The level of a 16-bit fraction (× 65535) at `bits` ≤ 8 bits: round(f·(2^bits − 1)/65535).
constexpr uint32_t quantiseFraction(uint16_t f, uint32_t bits) {
  return (uint32_t(f) * ((1u << bits) - 1) + 32767u) / 65535u;
}
/// The 16-bit fraction that level q of `bits` ≤ 8 bits decodes to: round(q·65535/(2^bits − 1)).
constexpr uint16_t fractionLevel(uint32_t q, uint32_t bits) {
  const uint32_t top = (1u << bits) - 1;
  return uint16_t((2 * q * 65535u + top) / (2 * top));
}
/// fractionLevel tabulated: kFractionLevels[bits][q] for bits 1–8 (row 0 unused).
inline constexpr auto kFractionLevels = [] {
  std::array<std::array<uint16_t, 256>, 9> table{};
  for (uint32_t bits = 1; bits <= 8; ++bits)
    for (uint32_t q = 0; q < (1u << bits); ++q) table[bits][q] = fractionLevel(q, bits);
  return table;
}();
/// Bytes of a quantised near hit at `bits` per fraction (a far hit takes one more): the
/// fractions and at least 4 bits of delta.
constexpr uint32_t nearHitBytes(uint32_t bits) { return (2 * bits + 4 + 7) / 8; }
/// Bytes of a tixel's tag plane, and of everything before its payload (the bits byte and tags).
constexpr uint64_t kTagBytes(uint32_t n) { return (uint64_t(n) + 3) / 4; }
constexpr uint64_t kTixelHeaderBytes(uint32_t n) { return 1 + kTagBytes(n); }
/// Most bytes one entry's payload may take (kTagGeneral, exact: a 5-byte varint and the fractions).
inline constexpr uint64_t kMaxEntryPayloadBytes = 9;
/// Most bytes n entries may take encoded (the buffer encodeTixelEntries needs).
constexpr uint64_t maxEncodedTixelBytes(uint32_t n) { return kTixelHeaderBytes(n) + uint64_t(n) * kMaxEntryPayloadBytes; }

/// Encodes n entries (any values) into out (maxEncodedTixelBytes(n) bytes) with `fractionBits`
/// per fraction (validFractionBits); returns the bytes used.
size_t encodeTixelEntries(const VisibilityEntry* entries, uint32_t n, uint32_t fractionBits, unsigned char* out);

/// Zero bytes that follow a field's last encoded tixel, so that the unchecked decoder may read a
/// whole 8-byte word wherever an entry starts.
inline constexpr size_t kEntryBytesPadding = 8;

namespace detail {

/// The general form's varint at `at` (advanced past it): the entry's index, from `previous`,
/// and flags. Checked: false when the bytes run out before `end` or the varint is too long.
template <bool Checked>
inline bool readGeneralTarget(const unsigned char*& at, const unsigned char* end, int64_t previous, int64_t& index,
                              uint32_t& flags) {
  uint64_t v = 0;
  for (int shift = 0;; shift += 7) {
    if (Checked && (at == end || shift > 28)) return false;  // ≤ 33 bits: zigzag(delta)·4 + flags
    const uint8_t byte = *at++;
    v |= uint64_t(byte & 0x7f) << shift;
    if ((byte & 0x80) == 0) break;
  }
  flags = uint32_t(v & 3u) << 30;
  index = previous + (int64_t(v >> 3) ^ -int64_t((v >> 2) & 1));  // un-zigzag of v >> 2
  return true;
}

/// Whether a decoded index may stand with its tag (checked decoding): within [0, kEscape], and
/// kEscape only in the general form.
inline bool validIndex(int64_t index, uint32_t tag) {
  return index >= 0 && index <= int64_t(VisibilityEntry::kIndexMask) &&
         (tag == kTagGeneral || index != int64_t(VisibilityEntry::kEscape));
}

template <bool Checked>
inline size_t decodeExact(const unsigned char* in, size_t size, uint32_t n, VisibilityEntry* out) {
  const unsigned char* const tags = in + 1;
  const unsigned char* at = in + kTixelHeaderBytes(n);
  [[maybe_unused]] const unsigned char* const end = in + size;
  int64_t previous = 0;
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t tag = (tags[k / 4] >> (2 * (k % 4))) & 3u;
    if constexpr (!Checked) {
      if (tag != kTagGeneral) [[likely]] {
        // Without branches, as the mix of these three tags is unpredictable: the next 8 bytes
        // hold the delta (kTagNear: 1 byte, kTagFar: 2, kTagEscape: none — the tag is its
        // length) and then the fractions.
        uint64_t word;
        std::memcpy(&word, at, 8);
        // Masks, not conditionals, which compilers would turn back into branches.
        const uint64_t near = 0 - uint64_t(tag == kTagNear), far = 0 - uint64_t(tag == kTagFar);
        const uint64_t hit = near | far;
        previous += int64_t((uint64_t(int64_t(int8_t(word))) & near) | (uint64_t(int64_t(int16_t(word))) & far));
        // The entry as one 8-byte word (target, then fu and fv: little-endian, one store).
        const uint64_t packed = ((uint64_t(uint32_t(previous)) | ((word >> (8 * tag)) << 32)) & hit) |
                                (uint64_t(VisibilityEntry::kEscape) & ~hit);
        std::memcpy(static_cast<void*>(&out[k]), &packed, 8);
        at += (tag + 4) & hit;
        continue;
      }
    }
    if (tag == kTagEscape) {
      out[k] = VisibilityEntry{};
      continue;
    }
    int64_t index;
    uint32_t flags = 0;
    if (tag == kTagNear) {
      if (Checked && end - at < 1) return 0;
      index = previous + int8_t(at[0]);
      at += 1;
    } else if (tag == kTagFar) {
      if (Checked && end - at < 2) return 0;
      int16_t d;
      std::memcpy(&d, at, 2);
      index = previous + d;
      at += 2;
    } else if (!readGeneralTarget<Checked>(at, end, previous, index, flags)) {
      return 0;
    }
    if (Checked && (!validIndex(index, tag) || end - at < 4)) return 0;
    VisibilityEntry e;
    e.target = uint32_t(index) | flags;
    std::memcpy(&e.fu, at, 2);
    std::memcpy(&e.fv, at + 2, 2);
    at += 4;
    if (index != int64_t(VisibilityEntry::kEscape)) previous = index;
    out[k] = e;
  }
  return size_t(at - in);
}

/// Both fractions of a quantised entry's levels q = qu | qv << bits (bits ≤ 8), as 16-bit
/// values: fu | fv << 16.
constexpr uint32_t fractionPair(uint32_t bits, uint64_t q) {
  const uint64_t mask = (uint64_t(1) << bits) - 1;
  return uint32_t(kFractionLevels[bits][q & mask]) | uint32_t(kFractionLevels[bits][(q >> bits) & mask]) << 16;
}
/// fractionPair at F = kCompactFractionBits, tabulated over q, so that the default's decoder
/// looks the pair up in one load.
inline constexpr uint32_t kCompactFractionPairMask = (1u << (2 * kCompactFractionBits)) - 1;
inline constexpr auto kCompactFractionPairs = [] {
  static_assert(2 * kCompactFractionBits <= 8);
  std::array<uint32_t, kCompactFractionPairMask + 1> table{};
  for (uint32_t q = 0; q <= kCompactFractionPairMask; ++q) table[q] = fractionPair(kCompactFractionBits, q);
  return table;
}();

/// FixedBits: 0, or the bits per fraction known at compile time (the default's, which the
/// gather decodes with every length and mask a constant and the fractions looked up in pairs).
template <bool Checked, uint32_t FixedBits = 0>
inline size_t decodeQuantised(const unsigned char* in, size_t size, uint32_t n, uint32_t runtimeBits,
                              VisibilityEntry* out) {
  const uint32_t bits = FixedBits != 0 ? FixedBits : runtimeBits;
  const unsigned char* const tags = in + 1;
  const unsigned char* at = in + kTixelHeaderBytes(n);
  [[maybe_unused]] const unsigned char* const end = in + size;
  const uint16_t* const level = kFractionLevels[bits].data();
  const uint64_t mask = (uint64_t(1) << bits) - 1;
  const uint64_t nearBytes = nearHitBytes(bits), farBytes = nearBytes + 1, fractionBytes = (2 * bits + 7) / 8;
  int64_t previous = 0;
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t tag = (tags[k / 4] >> (2 * (k % 4))) & 3u;
    if constexpr (!Checked) {
      if (tag != kTagGeneral) [[likely]] {
        // Branch-free as in decodeExact: the entry's integer is the low `length` bytes of the
        // next 8 (none for an escape); shifting it to the top and back sign-extends the delta.
        uint64_t word;
        std::memcpy(&word, at, 8);
        const uint64_t near = 0 - uint64_t(tag == kTagNear), far = 0 - uint64_t(tag == kTagFar);
        const uint64_t hit = near | far;
        const uint64_t length = (nearBytes & near) | (farBytes & far);
        const uint32_t top = uint32_t(64 - 8 * length) & 63u;
        previous += int64_t(uint64_t(int64_t(word << top) >> (top + 2 * bits)) & hit);
        uint64_t fractions;
        if constexpr (FixedBits == kCompactFractionBits) fractions = kCompactFractionPairs[word & kCompactFractionPairMask];
        else fractions = uint64_t(level[word & mask]) | (uint64_t(level[(word >> bits) & mask]) << 16);
        const uint64_t packed = ((uint64_t(uint32_t(previous)) | (fractions << 32)) & hit) |
                                (uint64_t(VisibilityEntry::kEscape) & ~hit);
        std::memcpy(static_cast<void*>(&out[k]), &packed, 8);
        at += length;
        continue;
      }
    }
    if (tag == kTagEscape) {
      out[k] = VisibilityEntry{};
      continue;
    }
    int64_t index;
    uint32_t flags = 0;
    uint64_t word = 0;
    if (tag != kTagGeneral) {
      const uint64_t length = tag == kTagNear ? nearBytes : farBytes;
      if (Checked && uint64_t(end - at) < length) return 0;
      std::memcpy(&word, at, length);  // little-endian, as the whole format
      at += length;
      const uint32_t top = uint32_t(64 - 8 * length);
      index = previous + (int64_t(word << top) >> (top + 2 * bits));
    } else {
      if (!readGeneralTarget<Checked>(at, end, previous, index, flags)) return 0;
      if (Checked && uint64_t(end - at) < fractionBytes) return 0;
      std::memcpy(&word, at, fractionBytes);
      at += fractionBytes;
      if (Checked && (word >> (2 * bits)) != 0) return 0;  // bits the encoder leaves 0
    }
    if (Checked && !validIndex(index, tag)) return 0;
    VisibilityEntry e;
    e.target = uint32_t(index) | flags;
    e.fu = level[word & mask];
    e.fv = level[(word >> bits) & mask];
    if (index != int64_t(VisibilityEntry::kEscape)) previous = index;
    out[k] = e;
  }
  return size_t(at - in);
}

}  // namespace detail

/// Decodes n entries encoded by encodeTixelEntries from in[0, size) into out. Checked: returns
/// the bytes consumed, or 0 when the bytes run out, declare a fraction precision that is not
/// valid, decode to an index outside [0, kEscape] or take a form the encoder never writes (a
/// corrupt file). Unchecked (the gather's, on a field that the checked decoder accepted): size
/// is ignored, and kEntryBytesPadding bytes past the tixel's encoding must be readable; the
/// result is the same.
template <bool Checked>
inline size_t decodeTixelEntries(const unsigned char* in, size_t size, uint32_t n, VisibilityEntry* out) {
  if (Checked && size < kTixelHeaderBytes(n)) return 0;
  const uint32_t bits = in[0];
  if (bits == kExactFractionBits) return detail::decodeExact<Checked>(in, size, n, out);
  if (Checked && !validFractionBits(bits)) return 0;
  if (!Checked && bits == kCompactFractionBits)
    return detail::decodeQuantised<false, kCompactFractionBits>(in, size, n, bits, out);
  return detail::decodeQuantised<Checked>(in, size, n, bits, out);
}

/// A run of consecutive tixels' encoded entries: a bake encodes its field a run at a time, in
/// parallel, and assembleEntries joins the runs.
struct EncodedRun {
  std::vector<unsigned char> bytes;
  std::vector<uint32_t> tixelBytes;  ///< per tixel of the run, in order: its encoding's size

  /// Appends the encoding of one tixel's n entries, with `fractionBits` per fraction.
  void add(const VisibilityEntry* entries, uint32_t n, uint32_t fractionBits);
};

/// Tixels per entry block of a .plv whose tixels have `directionsPerTixel` entries each: as many
/// whole tixels as make about 512 KiB of decoded entries (64 Ki entries).
uint64_t visibilityBlockTixels(uint32_t directionsPerTixel);

/// Where a .plv's frames lie: B entry blocks of perBlock tixels (the last may hold fewer), then
/// the extra records' frame; per frame, its offset in the file, stored and content bytes.
struct VisibilityFrames {
  uint64_t perBlock = 0, blocks = 0;
  std::vector<uint64_t> frameOffset, frameSizes, contentSizes;  ///< B + 1 each
  uint64_t tixelCount = 0;
  uint32_t directionsPerTixel = 0;
};

/// A .plv's entry blocks, read from the file one at a time (the streamed field, docs/design.md
/// "Visibility field"): a block's frame is read (pread) into a caller's buffer and decoded
/// into another, so that memory holds a block per reader instead of the field. Thread-safe.
class VisibilityBlockFile {
 public:
  /// The .plv at `path`, whose frames lie as `frames` says (its writer's, or readVisibility's
  /// checked table). Throws pl::Error naming the file when it cannot be opened.
  VisibilityBlockFile(std::string path, VisibilityFrames frames);
  ~VisibilityBlockFile();
  VisibilityBlockFile(const VisibilityBlockFile&) = delete;
  VisibilityBlockFile& operator=(const VisibilityBlockFile&) = delete;

  const std::string& path() const { return path_; }
  uint64_t perBlock() const { return frames_.perBlock; }
  uint64_t blocks() const { return frames_.blocks; }
  uint64_t tixelCount() const { return frames_.tixelCount; }
  /// Reads block b's entries into `entries` (its tixels' N entries each, tixel-major); `frame`
  /// and `stream` are scratch for the stored frame and one decompressed stream. Throws
  /// pl::Error naming the file when the read fails or the block does not decode.
  void readEntries(uint64_t b, std::vector<unsigned char>& frame, std::vector<unsigned char>& stream,
                   std::vector<VisibilityEntry>& entries) const;

 private:
  std::string path_;
  int fd_ = -1;
  VisibilityFrames frames_;
};

struct VisibilityField {
  uint32_t gridSide = 0;          ///< m: N = m² gather directions per tixel
  uint64_t tixelCount = 0;
  uint64_t hash = 0;              ///< of geometry + parameterisation + settings (visibilityHash)
  FieldArray<unsigned char> entryBytes;   ///< the tixels' encoded entries, one after another
  FieldArray<uint64_t> entryOffset;       ///< tixelCount + 1: where tixel t's encoding starts
  FieldArray<uint64_t> extraOffset;       ///< tixelCount + 1
  FieldArray<VisibilityExtra> extras;
  /// Set when the field is streamed: its entries stay in this .plv, read a block at a time by
  /// the gathers (entryBytes and entryOffset are then empty, and decode() may not be called).
  std::shared_ptr<const VisibilityBlockFile> stream;
  uint64_t rays = 0;              ///< rays traced to build it (gather + mirror continuations)
  double seconds = 0.0;

  uint32_t directionsPerTixel() const { return gridSide * gridSide; }
  uint64_t entryCount() const { return tixelCount * directionsPerTixel(); }
  /// Decodes tixel t's (field index, not global) N entries into out[0, N).
  void decode(uint64_t t, VisibilityEntry* out) const {
    decodeTixelEntries<false>(entryBytes.data() + entryOffset[t], 0, directionsPerTixel(), out);
  }
  /// Every entry, tixel-major (tests and tools; the bake decodes a tixel at a time).
  std::vector<VisibilityEntry> decodeAll() const;
  /// Encodes tixelCount · N entries (tixel-major) as the field's entries (gridSide and
  /// tixelCount set before), with `fractionBits` per fraction ("Compact entries").
  void setEntries(const VisibilityEntry* entries, uint32_t fractionBits = kExactFractionBits);
  /// Sets the field's entries to `runs` in order (their tixels must total tixelCount), freeing
  /// each run as it is copied, so that the runs and the field are not held twice.
  void assembleEntries(std::vector<EncodedRun>& runs);
  /// Bytes the field holds in memory.
  uint64_t bytes() const {
    return entryBytes.size() + entryOffset.size() * sizeof(uint64_t) + extraOffset.size() * sizeof(uint64_t) +
           extras.size() * sizeof(VisibilityExtra);
  }
};

/// Writes the field atomically (temp + rename): zstd frames of blocks of tixels' encoded
/// entries (format: above), with a progress bar. A held field only.
void writeVisibility(const std::string& path, const VisibilityField& field);

/// Writes a .plv a block at a time while its field is traced (a streamed field is never held
/// whole): each entry block's frame is made by frameBlock on any thread and handed to put() in
/// any order; put() writes the frames in block order as they become contiguous. finish()
/// writes the extra records' frame and the frame table and moves the file over `path` (temp +
/// rename: an unfinished writer leaves no .plv). The bytes are writeVisibility's.
class VisibilityWriter {
 public:
  /// Throws pl::Error naming the file when it cannot be created.
  VisibilityWriter(const std::string& path, uint32_t gridSide, uint64_t hash, uint64_t tixelCount);
  ~VisibilityWriter();
  VisibilityWriter(const VisibilityWriter&) = delete;
  VisibilityWriter& operator=(const VisibilityWriter&) = delete;

  uint64_t perBlock() const { return frames_.perBlock; }
  uint64_t blocks() const { return frames_.blocks; }
  uint32_t directionsPerTixel() const { return frames_.directionsPerTixel; }
  /// The stored frame of an entry block of `tixelBytes.size()` tixels of `directionsPerTixel`
  /// entries whose encodings, of those sizes, are `encoded` one after another (thread-safe; every
  /// tixel of the block must have one fraction precision); *contentBytes receives its content's size.
  static std::vector<unsigned char> frameBlock(std::span<const uint32_t> tixelBytes, std::span<const unsigned char> encoded,
                                               uint32_t directionsPerTixel, uint64_t* contentBytes);
  /// Hands over block b's frame (thread-safe, each block once, any order). Throws pl::Error
  /// naming the file when a write fails.
  void put(uint64_t b, std::vector<unsigned char> frame, uint64_t contentBytes);
  /// Bytes of frames handed over but waiting for an earlier block.
  uint64_t waitingBytes() const;
  /// After every block was put: writes the extra records (extraOffset: tixelCount + 1), the
  /// table and the checksum, and commits the file. Returns where its frames lie.
  VisibilityFrames finish(std::span<const uint64_t> extraOffset, std::span<const VisibilityExtra> extras);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  VisibilityFrames frames_;
};

/// Bytes writeVisibility holds besides the field itself (one batch of blocks and frames).
uint64_t visibilityWriteBufferBytes(uint32_t gridSide);

/// What a .plv holds, from its header and frame table (`plenoptic info FILE.plv`).
struct VisibilityFileInfo {
  uint32_t version = 0, gridSide = 0;
  uint64_t hash = 0, tixelCount = 0, entryCount = 0, extraCount = 0;
  uint64_t fileBytes = 0;
  uint64_t entryBytes = 0;  ///< the encoded entries (0 for an older version, which is not read further)
  uint64_t heldBytes = 0;   ///< what the field takes in memory once read (VisibilityField::bytes; 0: older version)
  uint32_t fractionBits = 0;  ///< bits per fraction of its first tixel ("Compact entries"; 0: older version or no tixels)
};
/// Reads a .plv's header and, for the current version, checks its payload checksum and frame
/// table (without decoding the entries). Throws pl::Error naming the file when it is not a .plv
/// or is corrupt.
VisibilityFileInfo readVisibilityInfo(const std::string& path);

/// Reads a field into memory, encoded as the bake holds it ("Compact entries"; its size,
/// VisibilityField::bytes, is checked with requireMemory before allocating). Returns false and
/// sets *why when the file is absent, of an older format version, or its hash differs from
/// expectedHash (a stale field is not an error); throws pl::Error naming the file when it is
/// present but corrupt or truncated (header, payload checksum, every frame and every index are
/// checked, every tixel's encoding decoded once, before it returns).
/// targetTixels: how many tixels the entries may point at (0: the file's own tixel count; a
/// shard's entries point at any tixel of the scene). decoded: when given, receives every
/// tixel's entries decoded (directionsPerTixel each, in field order) as they are checked — what
/// the bake's VisibilityShard::decoded holds — instead of a second decoding.
/// streamed: the entries are checked but not kept; the field reads them from the file instead
/// (VisibilityField::stream), and only its extra records are held.
bool readVisibility(const std::string& path, uint64_t expectedHash, VisibilityField& field, std::string* why,
                    uint64_t targetTixels = 0, std::vector<VisibilityEntry>* decoded = nullptr, bool streamed = false);

}  // namespace pl
