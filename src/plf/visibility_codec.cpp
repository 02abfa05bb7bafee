// The compact encoding of a tixel's visibility entries (layout and rationale in plv_file.h,
// "Compact entries"; measurements in docs/design.md, Visibility field).
#include <algorithm>
#include <cstring>

#include "core/error.h"
#include "core/memory.h"
#include "core/parallel.h"

#include "plf/plv_file.h"

namespace pl {
namespace {

constexpr uint32_t kFlagBits = VisibilityEntry::kBackSide | VisibilityEntry::kHasExtra;

inline uint64_t zigzag(int64_t d) { return (uint64_t(d) << 1) ^ uint64_t(d >> 63); }

/// The n low bytes of v, little-endian.
inline unsigned char* putBytes(unsigned char* out, uint64_t v, uint64_t n) {
  std::memcpy(out, &v, n);
  return out + n;
}

/// Whether delta fits a signed integer of `bits` bits.
inline bool fits(int64_t delta, uint64_t bits) {
  const int64_t half = int64_t(1) << (bits - 1);
  return delta >= -half && delta < half;
}

}  // namespace

size_t encodeTixelEntries(const VisibilityEntry* entries, uint32_t n, uint32_t fractionBits, unsigned char* out) {
  if (!validFractionBits(fractionBits)) fail("visibility field: {} bits per fraction (1 to 8, or 16)", fractionBits);
  const bool exact = fractionBits == kExactFractionBits;
  // The fractions' bits as stored, and the widths of a near and a far hit's delta (layout in
  // plv_file.h).
  const uint64_t fractionWidth = exact ? 32 : 2 * fractionBits;
  const uint64_t nearBits = exact ? 8 : 8 * nearHitBytes(fractionBits) - fractionWidth, farBits = nearBits + 8;
  out[0] = uint8_t(fractionBits);
  unsigned char* tags = out + 1;
  std::memset(tags, 0, kTagBytes(n));
  unsigned char* at = out + kTixelHeaderBytes(n);
  int64_t previous = 0;  // index of the last entry that saw a tixel
  for (uint32_t k = 0; k < n; ++k) {
    const VisibilityEntry& e = entries[k];
    // The fractions as stored: whole (exact), or their levels, packed qu | qv << F.
    const uint64_t fractions = exact ? uint64_t(e.fu) | uint64_t(e.fv) << 16
                                     : quantiseFraction(e.fu, fractionBits) |
                                           uint64_t(quantiseFraction(e.fv, fractionBits)) << fractionBits;
    uint32_t tag;
    if (e.target == VisibilityEntry::kEscape && fractions == 0) {
      tag = kTagEscape;
    } else {
      const int64_t index = e.tixel();
      const int64_t delta = index - previous;
      const bool plain = (e.target & kFlagBits) == 0 && !e.escaped();
      if (plain && fits(delta, farBits)) {
        tag = fits(delta, nearBits) ? kTagNear : kTagFar;
        const uint64_t deltaBits = tag == kTagNear ? nearBits : farBits;
        const uint64_t d = uint64_t(delta) & ((uint64_t(1) << deltaBits) - 1);
        if (exact) at = putBytes(putBytes(at, d, deltaBits / 8), fractions, 4);
        else at = putBytes(at, fractions | d << fractionWidth, (fractionWidth + deltaBits) / 8);
      } else {
        tag = kTagGeneral;
        uint64_t v = (zigzag(delta) << 2) | (e.target >> 30);
        while (v >= 0x80) {
          *at++ = uint8_t(v | 0x80);
          v >>= 7;
        }
        *at++ = uint8_t(v);
        at = putBytes(at, fractions, (fractionWidth + 7) / 8);
      }
      if (!e.escaped()) previous = index;
    }
    tags[k / 4] |= uint8_t(tag << (2 * (k % 4)));
  }
  return size_t(at - out);
}

void EncodedRun::add(const VisibilityEntry* entries, uint32_t n, uint32_t fractionBits) {
  const size_t at = bytes.size();
  bytes.resize(at + maxEncodedTixelBytes(n));
  const size_t used = encodeTixelEntries(entries, n, fractionBits, bytes.data() + at);
  bytes.resize(at + used);
  tixelBytes.push_back(uint32_t(used));
}

void VisibilityField::assembleEntries(std::vector<EncodedRun>& runs) {
  uint64_t total = 0, tixels = 0;
  for (const EncodedRun& run : runs) {
    total += run.bytes.size();
    tixels += run.tixelBytes.size();
  }
  if (tixels != tixelCount) fail("visibility field: {} tixels encoded for a field of {}", tixels, tixelCount);
  std::vector<uint64_t> offsets(tixelCount + 1, 0);
  std::vector<unsigned char> joined;
  joined.reserve(total + kEntryBytesPadding);  // pages are touched only as the runs are copied in
  adviseHugePages(joined.data(), total + kEntryBytesPadding);
  // The runs are small heap blocks: what they free is handed back every kReleaseBytes copied.
  constexpr uint64_t kReleaseBytes = uint64_t(1) << 26;
  uint64_t t = 0, sinceRelease = 0;
  for (EncodedRun& run : runs) {
    for (uint32_t size : run.tixelBytes) {
      offsets[t + 1] = offsets[t] + size;
      ++t;
    }
    joined.insert(joined.end(), run.bytes.begin(), run.bytes.end());
    sinceRelease += run.bytes.size();
    run = EncodedRun{};
    if (sinceRelease >= kReleaseBytes) {
      releaseFreedMemory();
      sinceRelease = 0;
    }
  }
  releaseFreedMemory();
  joined.resize(total + kEntryBytesPadding, 0);
  entryBytes = FieldArray<unsigned char>(std::move(joined));
  entryOffset = FieldArray<uint64_t>(std::move(offsets));
}

void VisibilityField::setEntries(const VisibilityEntry* entries, uint32_t fractionBits) {
  const uint32_t n = directionsPerTixel();
  constexpr uint64_t kTixelsPerRun = 1024;
  std::vector<EncodedRun> runs((tixelCount + kTixelsPerRun - 1) / kTixelsPerRun);
  parallelFor(runs.size(), [&](uint64_t r) {
    const uint64_t t1 = std::min(tixelCount, (r + 1) * kTixelsPerRun);
    for (uint64_t t = r * kTixelsPerRun; t < t1; ++t) runs[r].add(entries + t * n, n, fractionBits);
  });
  assembleEntries(runs);
}

std::vector<VisibilityEntry> VisibilityField::decodeAll() const {
  const uint32_t n = directionsPerTixel();
  std::vector<VisibilityEntry> all(entryCount());
  for (uint64_t t = 0; t < tixelCount; ++t) decode(t, all.data() + t * n);
  return all;
}

}  // namespace pl
