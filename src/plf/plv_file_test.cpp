// The .plv file on its own: the compact entry encoding's round trips on adversarial patterns,
// hand-made fields written and read back, and extra records with absurd contents or entries
// that do not decode refused though the file's checksums are valid. The round trips of traced
// fields, stale and corrupt files and the reuse decision are the bake's (bake/bake_test.cpp).
#include "plf/plv_file.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/hash.h"
#include "plf/codec_backends.h"
#include "support/expect_error.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

/// A two-tixel field (grid 1): tixel 0 sees tixel 1 through a mirror (one extra record),
/// tixel 1 sees the environment.
VisibilityField tinyField(const VisibilityExtra& extra) {
  VisibilityField field;
  field.gridSide = 1;
  field.tixelCount = 2;
  field.hash = 0x1234;
  VisibilityEntry seen, escaped;
  seen.target = 1u | VisibilityEntry::kHasExtra;
  const VisibilityEntry entries[] = {seen, escaped};
  field.setEntries(entries);
  field.extraOffset = FieldArray<uint64_t>(std::vector<uint64_t>{0, 1, 1});
  field.extras = FieldArray<VisibilityExtra>(std::vector<VisibilityExtra>{extra});
  return field;
}

/// The fraction precisions a tixel's encoding may take: the exact one and every quantised
/// width (kCompactFractionBits among them).
const std::vector<uint32_t> kEveryFractionBits = {kExactFractionBits, 1, 2, 3, 4, 5, 6, 7, 8};

/// What an entry decodes to at `bits` per fraction: itself (exact), or with its fractions
/// quantised.
VisibilityEntry expected(VisibilityEntry e, uint32_t bits) {
  if (bits == kExactFractionBits) return e;
  e.fu = fractionLevel(quantiseFraction(e.fu, bits), bits);
  e.fv = fractionLevel(quantiseFraction(e.fv, bits), bits);
  return e;
}

/// Encodes n entries with `bits` per fraction, decodes them checked and unchecked, and compares
/// bit for bit with what they must decode to; encodes the decoded entries again and checks the
/// bytes are the same (quantising is idempotent). Returns the encoded size.
size_t roundTrip(const std::vector<VisibilityEntry>& entries, uint32_t bits = kExactFractionBits) {
  const uint32_t n = uint32_t(entries.size());
  std::vector<unsigned char> bytes(maxEncodedTixelBytes(n) + kEntryBytesPadding);
  const size_t size = encodeTixelEntries(entries.data(), n, bits, bytes.data());
  EXPECT_LE(size, maxEncodedTixelBytes(n));
  std::vector<VisibilityEntry> want(n), checked(n), fast(n);
  for (uint32_t k = 0; k < n; ++k) want[k] = expected(entries[k], bits);
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), size, n, checked.data()), size) << bits;
  EXPECT_EQ(decodeTixelEntries<false>(bytes.data(), 0, n, fast.data()), size) << bits;
  EXPECT_EQ(std::memcmp(checked.data(), want.data(), n * sizeof(VisibilityEntry)), 0) << bits;
  EXPECT_EQ(std::memcmp(fast.data(), want.data(), n * sizeof(VisibilityEntry)), 0) << bits;
  std::vector<unsigned char> again(maxEncodedTixelBytes(n));
  EXPECT_EQ(encodeTixelEntries(checked.data(), n, bits, again.data()), size) << bits;
  EXPECT_EQ(std::memcmp(again.data(), bytes.data(), size), 0) << bits;
  // Every shorter prefix is refused by the checked decoder (it never reads past `size`).
  for (size_t cut = 0; cut < size; ++cut) EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), cut, n, checked.data()), 0u) << cut;
  return size;
}

uint64_t zigzag(int64_t d) { return (uint64_t(d) << 1) ^ uint64_t(d >> 63); }

VisibilityEntry entry(uint32_t target, uint16_t fu = 0, uint16_t fv = 0) {
  VisibilityEntry e;
  e.target = target;
  e.fu = fu;
  e.fv = fv;
  return e;
}

TEST(VisibilityCodec, AllMissesTakeTheTagsOnly) {
  for (uint32_t bits : kEveryFractionBits) {
    const std::vector<VisibilityEntry> misses(256);
    EXPECT_EQ(roundTrip(misses, bits), kTixelHeaderBytes(256));
    // Escapes that carry flags or fractions are kept (general form).
    std::vector<VisibilityEntry> odd(7, entry(VisibilityEntry::kEscape | VisibilityEntry::kHasExtra));
    odd[3] = entry(VisibilityEntry::kEscape, 1, 65535);
    odd[5] = entry(VisibilityEntry::kEscape | VisibilityEntry::kBackSide | VisibilityEntry::kHasExtra, 7, 9);
    roundTrip(odd, bits);
  }
}

TEST(VisibilityCodec, EveryEntryADifferentFarTixel) {
  for (uint32_t bits : kEveryFractionBits) {
    std::mt19937_64 rng(7);
    std::vector<VisibilityEntry> far(576);
    for (VisibilityEntry& e : far) {
      const uint32_t flags = uint32_t(rng() & 3) << 30;
      e = entry(uint32_t(rng() % VisibilityEntry::kEscape) | flags, uint16_t(rng()), uint16_t(rng()));
    }
    const size_t size = roundTrip(far, bits);
    EXPECT_LE(size, kTixelHeaderBytes(576) + 576 * kMaxEntryPayloadBytes);
    // Alternating between the smallest and the largest index: the longest deltas both ways.
    std::vector<VisibilityEntry> swing(64);
    for (size_t k = 0; k < swing.size(); ++k)
      swing[k] = entry(k % 2 ? VisibilityEntry::kIndexMask - 1 : 0, uint16_t(k), 65535);
    roundTrip(swing, bits);
  }
}

TEST(VisibilityCodec, TheLargestTixelIndexAndEveryFlag) {
  const uint32_t largest = VisibilityEntry::kIndexMask - 1;  // kIndexMask itself is kEscape
  std::vector<VisibilityEntry> entries;
  for (uint32_t flags : {0u, VisibilityEntry::kBackSide, VisibilityEntry::kHasExtra,
                         VisibilityEntry::kBackSide | VisibilityEntry::kHasExtra})
    for (uint32_t index : {largest, largest - 1, 0u, largest, largest - 200, largest - 40000})
      entries.push_back(entry(index | flags, 65535, 0));
  for (uint32_t bits : kEveryFractionBits) roundTrip(entries, bits);
}

TEST(VisibilityCodec, DeltasAtTheEdgesOfEachForm) {
  // Per precision, deltas just inside and just outside the near and far forms' ranges, both
  // signs, from a middle index (so that none leaves [0, kEscape)).
  for (uint32_t bits : kEveryFractionBits) {
    const int64_t nearBits = bits == kExactFractionBits ? 8 : int64_t(8 * nearHitBytes(bits) - 2 * bits);
    std::vector<VisibilityEntry> entries;
    int64_t at = int64_t(1) << 28;
    entries.push_back(entry(uint32_t(at), 1, 2));
    for (int64_t width : {nearBits, nearBits + 8}) {
      const int64_t half = int64_t(1) << (width - 1);
      for (int64_t delta : {half - 1, half, -half, -half - 1, int64_t(0), int64_t(1), int64_t(-1)}) {
        at += delta;
        entries.push_back(entry(uint32_t(at), uint16_t(at * 7919), uint16_t(at * 104729)));
      }
    }
    roundTrip(entries, bits);
  }
}

TEST(VisibilityCodec, QuantisedFractionsKeepTheEdgesAndStayWithinHalfALevel) {
  for (uint32_t bits = 1; bits <= 8; ++bits) {
    const uint32_t top = (1u << bits) - 1;
    EXPECT_EQ(quantiseFraction(0, bits), 0u);
    EXPECT_EQ(quantiseFraction(65535, bits), top);
    EXPECT_EQ(fractionLevel(0, bits), 0u);
    EXPECT_EQ(fractionLevel(top, bits), 65535u);
    // Half a level of 65535/top, plus the 16-bit rounding of the level itself.
    const double bound = 0.5 * 65535.0 / top + 0.5;
    uint32_t previous = 0;
    for (uint32_t f = 0; f <= 65535; ++f) {
      const uint32_t q = quantiseFraction(uint16_t(f), bits);
      ASSERT_LE(q, top);
      ASSERT_GE(q, previous);  // monotone
      previous = q;
      ASSERT_LE(std::abs(double(fractionLevel(q, bits)) - double(f)), bound) << bits << " " << f;
      ASSERT_EQ(kFractionLevels[bits][q], fractionLevel(q, bits));
      ASSERT_EQ(quantiseFraction(fractionLevel(q, bits), bits), q);  // idempotent
    }
  }
  // The fractions' edges in a tixel: 0 and 65535 decode exactly at every precision.
  std::vector<VisibilityEntry> edges;
  for (uint16_t fu : {0, 1, 65534, 65535})
    for (uint16_t fv : {0, 1, 65534, 65535}) edges.push_back(entry(uint32_t(40 + edges.size()), fu, fv));
  for (uint32_t bits : kEveryFractionBits) {
    roundTrip(edges, bits);
    EXPECT_EQ(expected(edges[0], bits).fu, 0u);
    EXPECT_EQ(expected(edges.back(), bits).fv, 65535u);
  }
}

TEST(VisibilityCodec, NeighbouringHitsTakeFewBytes) {
  // One tixel (grid 1) and a smooth pattern.
  for (uint32_t bits : kEveryFractionBits) roundTrip({entry(12345, 3, 4)}, bits);
  std::vector<VisibilityEntry> smooth(256);
  for (size_t k = 0; k < smooth.size(); ++k) smooth[k] = entry(uint32_t(1000 + 3 * k + (k % 16) * 4), uint16_t(k * 97), uint16_t(k * 31));
  // Exact: deltas within ±127 take 1 + 4 bytes and the tag; the first (1000) takes 2 + 4.
  EXPECT_LE(roundTrip(smooth), kTixelHeaderBytes(256) + 6 + 255 * 5);
  // 8 bits: 1 + 2 bytes, the first 2 + 2; 4 bits: 2 bytes, the first 3.
  EXPECT_LE(roundTrip(smooth, 8), kTixelHeaderBytes(256) + 4 + 255 * 3);
  EXPECT_LE(roundTrip(smooth, 4), kTixelHeaderBytes(256) + 3 + 255 * 2);
}

TEST(VisibilityCodec, CorruptEncodingsAreRefused) {
  std::vector<unsigned char> bytes(maxEncodedTixelBytes(4));
  VisibilityEntry out[4];
  // A fraction precision that no encoder writes.
  for (uint8_t bits : {0, 9, 15, 17, 255}) {
    std::fill(bytes.begin(), bytes.end(), 0);
    bytes[0] = bits;
    EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), bytes.size(), 1, out), 0u) << int(bits);
  }
  // A negative index: tag near (1) with delta −1 from 0.
  std::fill(bytes.begin(), bytes.end(), 0);
  bytes[0] = kExactFractionBits;
  bytes[1] = 1;
  bytes[2] = 0xff;
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), 7, 1, out), 0u);
  // The same quantised: a near hit of 8-bit fractions whose delta byte is −1.
  bytes[0] = 8;
  bytes[2] = 0;
  bytes[3] = 0;
  bytes[4] = 0xff;
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), 5, 1, out), 0u);
  // A varint that never ends.
  std::fill(bytes.begin(), bytes.end(), 0xff);
  bytes[0] = kExactFractionBits;
  bytes[1] = 3;
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), bytes.size(), 1, out), 0u);
  auto putVarint = [&](uint64_t v, size_t at) {
    while (v >= 0x80) {
      bytes[at++] = uint8_t(v | 0x80);
      v >>= 7;
    }
    bytes[at++] = uint8_t(v);
    return at;
  };
  // An index past kEscape: general form, delta 2^30 from 0.
  std::fill(bytes.begin(), bytes.end(), 0);
  bytes[0] = kExactFractionBits;
  bytes[1] = 3;
  size_t at = putVarint(zigzag(int64_t(1) << 30) << 2, 2);
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), at + 4, 1, out), 0u);
  // A quantised general form whose fraction bytes set bits above the two levels (6 bits each:
  // bit 12 of the 2 bytes), which the encoder leaves 0.
  std::fill(bytes.begin(), bytes.end(), 0);
  bytes[0] = 6;
  bytes[1] = 3;
  at = putVarint(zigzag(5) << 2, 2);
  bytes[at + 1] = 0x10;
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), at + 2, 1, out), 0u);
  bytes[at + 1] = 0x0f;  // within the levels: accepted
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), at + 2, 1, out), at + 2);
  // kEscape reached by a short delta (the encoder writes escapes with a tag of their own or in
  // the general form): refused, as the fast decoder would read it otherwise.
  std::fill(bytes.begin(), bytes.end(), 0);
  bytes[0] = kExactFractionBits;
  bytes[1] = 3 | (1 << 2);  // entry 0 general, entry 1 near
  at = putVarint(zigzag(int64_t(VisibilityEntry::kEscape) - 1) << 2, 2);
  at += 4;
  bytes[at++] = 1;  // delta +1: kEscape
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), at + 4, 2, out), 0u);
}

/// Each test's own directory (TempDirTest: parallel ctest runs never share one).
using VisibilityFile = test_support::TempDirTest;

/// Expects reading `plv` as a field of `hash` to throw a pl::Error whose message names `where`
/// and `problem`.
void expectRefused(const std::string& plv, uint64_t hash, const std::string& where, const std::string& problem) {
  VisibilityField read;
  std::string why;
  test_support::expectError([&] { readVisibility(plv, hash, read, &why); }, {where, problem});
}

TEST_F(VisibilityFile, OneTixelFieldsRoundTrip) {
  const std::string plv = path("one.plv");
  for (uint32_t gridSide : {1u, 3u, 16u}) {
    VisibilityField field;
    field.gridSide = gridSide;
    field.tixelCount = 1;
    field.hash = 99;
    std::vector<VisibilityEntry> entries(gridSide * gridSide);
    for (size_t k = 0; k < entries.size(); ++k) entries[k] = k % 3 ? entry(0, uint16_t(k), 1) : VisibilityEntry{};
    field.setEntries(entries.data());
    field.extraOffset = FieldArray<uint64_t>(std::vector<uint64_t>{0, 0});
    writeVisibility(plv, field);
    VisibilityField read;
    std::string why;
    ASSERT_TRUE(readVisibility(plv, 99, read, &why)) << why;
    const std::vector<VisibilityEntry> back = read.decodeAll();
    ASSERT_EQ(back.size(), entries.size());
    EXPECT_EQ(std::memcmp(back.data(), entries.data(), entries.size() * sizeof(VisibilityEntry)), 0);
  }
}

// The stored streams (plv_file.h, "A stored entry block") at every precision, on tixels made
// to reach each op's edges: all misses; escapes that carry a flag or fractions (op 3); deltas
// just inside and outside the near (i8) and far (i16) ops, both signs; a flagged hit; the
// field's smallest and largest index in turn. Written, read back held and streamed.
TEST_F(VisibilityFile, EveryOpsEdgeRoundTripsThroughTheStreams) {
  const std::string plv = path("edges.plv");
  VisibilityField field;
  field.gridSide = 4;  // 16 entries per tixel
  field.tixelCount = 70000;  // indices up to 69 999: deltas past ±32 768
  field.hash = 11;
  const uint32_t n = field.directionsPerTixel(), last = uint32_t(field.tixelCount - 1);
  std::vector<VisibilityEntry> entries(field.tixelCount * n);  // tixel 0 and most others: all misses
  VisibilityEntry* const odd = entries.data() + 1 * n;
  odd[0] = entry(VisibilityEntry::kEscape | VisibilityEntry::kBackSide);
  odd[1] = entry(VisibilityEntry::kEscape, 1, 65535);
  odd[2] = entry(5 | VisibilityEntry::kBackSide, 65535, 0);
  VisibilityEntry* const deltas = entries.data() + 2 * n;
  int64_t at = 35000, k = 0;
  deltas[k++] = entry(uint32_t(at), 1, 2);
  for (int64_t delta : {127, 128, -128, -129, 32767, -32767, -32768, 32768, -32769, 0, 1, -1}) {
    at += delta;
    deltas[k] = entry(uint32_t(at), uint16_t(at * 7919), uint16_t(at * 104729));
    ++k;
  }
  VisibilityEntry* const swing = entries.data() + 3 * n;
  for (uint32_t i = 0; i < n; ++i) swing[i] = entry(i % 2 ? last : 0, uint16_t(i), 65535);
  entries[(field.tixelCount - 1) * n] = entry(last, 65535, 65535);  // the last block's last tixel
  for (uint32_t bits : kEveryFractionBits) {
    field.setEntries(entries.data(), bits);
    field.extraOffset = FieldArray<uint64_t>(std::vector<uint64_t>(field.tixelCount + 1, 0));
    writeVisibility(plv, field);
    std::vector<VisibilityEntry> want(entries.size());
    for (size_t i = 0; i < entries.size(); ++i) want[i] = expected(entries[i], bits);
    VisibilityField held;
    std::string why;
    ASSERT_TRUE(readVisibility(plv, 11, held, &why)) << bits << ": " << why;
    const std::vector<VisibilityEntry> back = held.decodeAll();
    ASSERT_EQ(back.size(), want.size());
    EXPECT_EQ(std::memcmp(back.data(), want.data(), want.size() * sizeof(VisibilityEntry)), 0) << bits;
    // The held field's bytes are the writer's, as the format promises.
    EXPECT_EQ(held.entryOffset.size(), field.entryOffset.size());
    EXPECT_EQ(std::memcmp(held.entryBytes.data(), field.entryBytes.data(), field.entryOffset[field.tixelCount]), 0) << bits;
    VisibilityField streamed;
    ASSERT_TRUE(readVisibility(plv, 11, streamed, &why, 0, nullptr, true)) << bits << ": " << why;
    std::vector<unsigned char> frame, stream;
    std::vector<VisibilityEntry> block;
    for (uint64_t b = 0; b < streamed.stream->blocks(); ++b) {
      streamed.stream->readEntries(b, frame, stream, block);
      const uint64_t first = b * streamed.stream->perBlock() * n;
      ASSERT_LE(first + block.size(), want.size());
      EXPECT_EQ(std::memcmp(block.data(), want.data() + first, block.size() * sizeof(VisibilityEntry)), 0)
          << bits << " block " << b;
    }
  }
}

TEST_F(VisibilityFile, RecordsWithAbsurdContentsAreRefusedDespiteAValidChecksum) {
  const std::string plv = path("crafted.plv");
  VisibilityField read;
  std::string why;
  const VisibilityExtra sane{Rgb(0.9f, 0.5f, 0.0f), Vec2(-1.0f, 0.7f), 1};
  writeVisibility(plv, tinyField(sane));
  ASSERT_TRUE(readVisibility(plv, 0x1234, read, &why)) << why;
  EXPECT_EQ(read.extras[0].throughput, sane.throughput);

  const float nan = std::numeric_limits<float>::quiet_NaN();
  const struct {
    VisibilityExtra extra;
    const char* problem;
  } cases[] = {
      {{Rgb(1e9f, 1.0f, 1.0f), Vec2(0.0f), 1}, "throughput 1000000000 outside [0, 1]"},
      {{Rgb(1.0f, nan, 1.0f), Vec2(0.0f), 1}, "throughput nan outside [0, 1]"},
      {{Rgb(1.0f, 1.0f, -0.5f), Vec2(0.0f), 1}, "throughput -0.5 outside [0, 1]"},
      {{Rgb(1.0f), Vec2(0.0f, 3.0f), 1}, "direction coordinate 3 outside [-1, 1]"},
      {{Rgb(1.0f), Vec2(nan, 0.0f), 1}, "direction coordinate nan outside [-1, 1]"},
      {{Rgb(1.0f), Vec2(0.0f), 7}, "mirror flag of 7"},
  };
  for (const auto& c : cases) {
    writeVisibility(plv, tinyField(c.extra));
    expectRefused(plv, 0x1234, "crafted.plv: extra record 0", c.problem);
  }
}

/// A stored entry block made by hand (plv_file.h, "A stored entry block"): `bits`, then each
/// stream's raw and stored sizes, then the streams' zstd frames; `rawSizes` overrides the
/// declared raw sizes where given.
std::vector<unsigned char> handMadeBlock(uint32_t bits, const std::array<std::vector<unsigned char>, kPlvStreams>& streams,
                                         std::array<int64_t, kPlvStreams> rawSizes = {-1, -1, -1, -1, -1, -1}) {
  std::vector<unsigned char> block{uint8_t(bits)};
  std::array<std::vector<unsigned char>, kPlvStreams> frames;
  auto put32 = [&](uint32_t v) { block.insert(block.end(), reinterpret_cast<unsigned char*>(&v), reinterpret_cast<unsigned char*>(&v) + 4); };
  for (uint32_t i = 0; i < kPlvStreams; ++i) {
    if (!streams[i].empty()) frames[i] = detail::zstdCompress(streams[i], 1);
    put32(uint32_t(rawSizes[i] >= 0 ? rawSizes[i] : int64_t(streams[i].size())));
  }
  for (uint32_t i = 0; i < kPlvStreams; ++i) put32(uint32_t(frames[i].size()));
  for (const auto& f : frames) block.insert(block.end(), f.begin(), f.end());
  return block;
}

/// `file` (a .plv of one entry block) with that block replaced by `block`: the frame table and
/// the payload checksum made to agree, so that only the block itself is wrong.
std::string withEntryBlock(const std::string& file, const std::vector<unsigned char>& block) {
  constexpr size_t kHeader = 56, kFramesAt = kHeader + 8;
  uint64_t table[4];  // stored sizes of the block and the extra records' frame, then content sizes
  std::memcpy(table, file.data() + file.size() - sizeof(table), sizeof(table));
  const std::string extras = file.substr(kFramesAt + table[0], table[1]);
  std::string out = file.substr(0, kFramesAt) + std::string(block.begin(), block.end()) + extras;
  table[0] = block.size();
  out.append(reinterpret_cast<const char*>(table), sizeof(table));
  const uint64_t hash = xxh64(out.data() + kHeader, out.size() - kHeader);
  std::memcpy(out.data() + 48, &hash, 8);
  return out;
}

// The stored entry blocks' streams are checked as they are read: a block the writer cannot
// have made is refused naming the file and the block, though every checksum and frame is valid.
TEST_F(VisibilityFile, StoredEntryBlocksTheWriterCannotMakeAreRefused) {
  const std::string plv = path("crafted.plv");
  VisibilityField field;  // one tixel, one direction, compact: a block of one entry
  field.gridSide = 1;
  field.tixelCount = 1;
  field.hash = 5;
  const VisibilityEntry seen = entry(0, 30000, 40000);
  field.setEntries(&seen, kCompactFractionBits);
  field.extraOffset = FieldArray<uint64_t>(std::vector<uint64_t>{0, 0});
  writeVisibility(plv, field);
  std::string written;
  {
    std::ifstream in(plv, std::ios::binary);
    written.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto readWith = [&](const std::vector<unsigned char>& block, VisibilityField& read) {
    std::ofstream(plv, std::ios::binary | std::ios::trunc) << withEntryBlock(written, block);
    std::string why;
    EXPECT_TRUE(readVisibility(plv, 5, read, &why)) << why;
  };
  using Streams = std::array<std::vector<unsigned char>, kPlvStreams>;  // ops, near, far low, far high, targets, fractions
  const uint32_t bits = kCompactFractionBits;
  const uint8_t levels = uint8_t(quantiseFraction(30000, bits) | quantiseFraction(40000, bits) << bits);
  // The hand-made block of what was written reads back as written: the maker is right.
  VisibilityField read;
  readWith(handMadeBlock(bits, Streams{{{1}, {0}, {}, {}, {}, {levels}}}), read);
  EXPECT_EQ(read.decodeAll()[0].target, 0u);
  EXPECT_EQ(read.decodeAll()[0].fu, expected(seen, bits).fu);
  EXPECT_EQ(read.decodeAll()[0].fv, expected(seen, bits).fv);

  const struct {
    std::vector<unsigned char> block;
    const char* problem;
  } cases[] = {
      {handMadeBlock(9, Streams{{{1}, {0}, {}, {}, {}, {levels}}}), "9 bits per fraction"},
      {handMadeBlock(bits, Streams{{{1}, {0}, {}, {}, {}, {levels}}}, {2, -1, -1, -1, -1, -1}), "stream 0 declares 2 bytes"},
      {handMadeBlock(bits, Streams{{{4}, {0}, {}, {}, {}, {levels}}}), "op 4 of entry 0"},
      {handMadeBlock(bits, Streams{{{1}, {}, {}, {}, {}, {levels}}}), "its streams' sizes disagree with its ops"},
      {handMadeBlock(bits, Streams{{{2}, {}, {0xff}, {0xff}, {}, {levels}}}), "tixel 0 do not decode"},  // index −1
      {handMadeBlock(bits, Streams{{{3}, {}, {}, {}, {0, 0, 0, 0}, {0x10}}}), "tixel 0 do not decode"},  // a bit above 2F
  };
  for (const auto& c : cases) {
    std::ofstream(plv, std::ios::binary | std::ios::trunc) << withEntryBlock(written, c.block);
    expectRefused(plv, 5, "crafted.plv: visibility block 0", c.problem);
  }
}

// The streaming writer: entry blocks handed over in any order give writeVisibility's file byte
// for byte, and the block file reads each block's content back (sizes, then encodings,
// decoding to the entries); readVisibility's streamed form holds the extra records only.
TEST_F(VisibilityFile, BlocksWrittenOutOfOrderAndReadBackOneAtATime) {
  const std::string held = path("held.plv"), streamed = path("streamed.plv");
  VisibilityField field;
  field.gridSide = 16;  // 256 directions: 256 tixels per block
  field.tixelCount = 1000;
  field.hash = 7;
  const uint32_t n = field.directionsPerTixel();
  std::mt19937 random(3);
  std::vector<VisibilityEntry> entries(field.tixelCount * n);
  for (VisibilityEntry& e : entries)
    e = random() % 4 ? entry(uint32_t(random() % field.tixelCount), uint16_t(random()), uint16_t(random())) : VisibilityEntry{};
  field.setEntries(entries.data(), kCompactFractionBits);
  field.extraOffset = FieldArray<uint64_t>(std::vector<uint64_t>(field.tixelCount + 1, 0));
  writeVisibility(held, field);

  VisibilityWriter writer(streamed, field.gridSide, field.hash, field.tixelCount);
  ASSERT_EQ(writer.blocks(), 4u);
  for (uint64_t b : {2u, 0u, 3u, 1u}) {
    const uint64_t t0 = b * writer.perBlock(), t1 = std::min(field.tixelCount, t0 + writer.perBlock());
    std::vector<uint32_t> sizes;
    for (uint64_t t = t0; t < t1; ++t) sizes.push_back(uint32_t(field.entryOffset[t + 1] - field.entryOffset[t]));
    uint64_t contentBytes = 0;
    std::vector<unsigned char> frame = VisibilityWriter::frameBlock(
        sizes, {field.entryBytes.data() + field.entryOffset[t0], field.entryOffset[t1] - field.entryOffset[t0]}, n,
        &contentBytes);
    writer.put(b, std::move(frame), contentBytes);
    EXPECT_EQ(writer.waitingBytes() > 0, b != 1);  // 2 and 3 wait for 1, the last handed over
  }
  EXPECT_THROW(writer.put(1, {}, 0), Error);  // each block once
  const VisibilityFrames frames = writer.finish({field.extraOffset.data(), field.extraOffset.size()}, {});
  auto bytes = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes(streamed), bytes(held));

  const VisibilityBlockFile file(streamed, frames);
  std::vector<unsigned char> frame, stream;
  std::vector<VisibilityEntry> decoded;
  for (uint64_t b = 0; b < file.blocks(); ++b) {
    file.readEntries(b, frame, stream, decoded);
    const uint64_t t0 = b * file.perBlock(), t1 = std::min(field.tixelCount, t0 + file.perBlock());
    ASSERT_EQ(decoded.size(), (t1 - t0) * n);
    for (uint64_t t = t0; t < t1; ++t) {
      std::vector<VisibilityEntry> want(n);
      field.decode(t, want.data());
      ASSERT_EQ(std::memcmp(decoded.data() + (t - t0) * n, want.data(), n * sizeof(VisibilityEntry)), 0) << "tixel " << t;
    }
  }

  VisibilityField read;
  std::string why;
  ASSERT_TRUE(readVisibility(held, 7, read, &why, 0, nullptr, true)) << why;
  ASSERT_TRUE(read.stream);
  EXPECT_TRUE(read.entryBytes.empty());
  EXPECT_EQ(read.stream->blocks(), 4u);
  EXPECT_EQ(read.extraOffset.size(), field.tixelCount + 1);
}

// An unfinished writer (an error, an interrupted bake) leaves no .plv.
TEST_F(VisibilityFile, AnUnfinishedWriterLeavesNoFile) {
  const std::string plv = path("u.plv");
  {
    VisibilityWriter writer(plv, 2, 1, 10);
    EXPECT_THROW(writer.finish({}, {}), Error);  // no block written
  }
  EXPECT_FALSE(std::filesystem::exists(plv));
  EXPECT_EQ(fileCount(), 0u);  // nor its temporary
}

}  // namespace
}  // namespace pl
