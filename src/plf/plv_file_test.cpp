// The .plv file on its own: the compact entry encoding's round trips on adversarial patterns,
// hand-made fields written and read back, and extra records with absurd contents or entries
// that do not decode refused though the file's checksums are valid. The round trips of traced
// fields, stale and corrupt files and the reuse decision are the bake's (bake/bake_test.cpp).
#include "plf/plv_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"

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

/// Encodes n entries, decodes them checked and unchecked, and compares bit for bit; returns the
/// encoded size.
size_t roundTrip(const std::vector<VisibilityEntry>& entries) {
  const uint32_t n = uint32_t(entries.size());
  std::vector<unsigned char> bytes(maxEncodedTixelBytes(n) + kEntryBytesPadding);
  const size_t size = encodeTixelEntries(entries.data(), n, bytes.data());
  EXPECT_LE(size, maxEncodedTixelBytes(n));
  std::vector<VisibilityEntry> checked(n), fast(n);
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), size, n, checked.data()), size);
  EXPECT_EQ(decodeTixelEntries<false>(bytes.data(), 0, n, fast.data()), size);
  EXPECT_EQ(std::memcmp(checked.data(), entries.data(), n * sizeof(VisibilityEntry)), 0);
  EXPECT_EQ(std::memcmp(fast.data(), entries.data(), n * sizeof(VisibilityEntry)), 0);
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
  const std::vector<VisibilityEntry> misses(256);
  EXPECT_EQ(roundTrip(misses), kTagBytes(256));
  // Escapes that carry flags or fractions are kept exactly (general form).
  std::vector<VisibilityEntry> odd(7, entry(VisibilityEntry::kEscape | VisibilityEntry::kHasExtra));
  odd[3] = entry(VisibilityEntry::kEscape, 1, 65535);
  odd[5] = entry(VisibilityEntry::kEscape | VisibilityEntry::kBackSide | VisibilityEntry::kHasExtra, 7, 9);
  roundTrip(odd);
}

TEST(VisibilityCodec, EveryEntryADifferentFarTixel) {
  std::mt19937_64 rng(7);
  std::vector<VisibilityEntry> far(576);
  for (VisibilityEntry& e : far) {
    const uint32_t flags = uint32_t(rng() & 3) << 30;
    e = entry(uint32_t(rng() % VisibilityEntry::kEscape) | flags, uint16_t(rng()), uint16_t(rng()));
  }
  const size_t size = roundTrip(far);
  EXPECT_LE(size, kTagBytes(576) + 576 * kMaxEntryPayloadBytes);
  // Alternating between the smallest and the largest index: the longest deltas both ways.
  std::vector<VisibilityEntry> swing(64);
  for (size_t k = 0; k < swing.size(); ++k)
    swing[k] = entry(k % 2 ? VisibilityEntry::kIndexMask - 1 : 0, uint16_t(k), 65535);
  roundTrip(swing);
}

TEST(VisibilityCodec, TheLargestTixelIndexAndEveryFlag) {
  const uint32_t largest = VisibilityEntry::kIndexMask - 1;  // kIndexMask itself is kEscape
  std::vector<VisibilityEntry> entries;
  for (uint32_t flags : {0u, VisibilityEntry::kBackSide, VisibilityEntry::kHasExtra,
                         VisibilityEntry::kBackSide | VisibilityEntry::kHasExtra})
    for (uint32_t index : {largest, largest - 1, 0u, largest, largest - 200, largest - 40000})
      entries.push_back(entry(index | flags, 65535, 0));
  roundTrip(entries);
}

TEST(VisibilityCodec, NeighbouringHitsTakeFewBytes) {
  // One tixel (grid 1) and a smooth pattern: deltas within ±127 take 1 + 4 bytes and the tag.
  roundTrip({entry(12345, 3, 4)});
  std::vector<VisibilityEntry> smooth(256);
  for (size_t k = 0; k < smooth.size(); ++k) smooth[k] = entry(uint32_t(1000 + 3 * k + (k % 16) * 4), uint16_t(k * 97), uint16_t(k * 31));
  const size_t size = roundTrip(smooth);
  EXPECT_LE(size, kTagBytes(256) + 8 + 255 * 5);  // the first delta (1000) takes 2 bytes
}

TEST(VisibilityCodec, CorruptEncodingsAreRefused) {
  std::vector<unsigned char> bytes(maxEncodedTixelBytes(4));
  VisibilityEntry out[4];
  // A negative index: tag near (1) with delta −1 from 0.
  bytes[0] = 1;
  bytes[1] = 0xff;
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), 6, 1, out), 0u);
  // A varint that never ends.
  std::fill(bytes.begin(), bytes.end(), 0xff);
  bytes[0] = 3;
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), bytes.size(), 1, out), 0u);
  // An index past kEscape: general form, delta 2^30 from 0.
  std::fill(bytes.begin(), bytes.end(), 0);
  bytes[0] = 3;
  uint64_t v = zigzag(int64_t(1) << 30) << 2;
  size_t at = 1;
  while (v >= 0x80) {
    bytes[at++] = uint8_t(v | 0x80);
    v >>= 7;
  }
  bytes[at++] = uint8_t(v);
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), at + 4, 1, out), 0u);
  // kEscape reached by a short delta (the encoder writes escapes with a tag of their own or in
  // the general form): refused, as the fast decoder would read it otherwise.
  std::fill(bytes.begin(), bytes.end(), 0);
  bytes[0] = 3 | (1 << 2);  // entry 0 general, entry 1 near
  v = zigzag(int64_t(VisibilityEntry::kEscape) - 1) << 2;
  at = 1;
  while (v >= 0x80) {
    bytes[at++] = uint8_t(v | 0x80);
    v >>= 7;
  }
  bytes[at++] = uint8_t(v);
  at += 4;
  bytes[at++] = 1;  // delta +1: kEscape
  EXPECT_EQ(decodeTixelEntries<true>(bytes.data(), at + 4, 2, out), 0u);
}

TEST(VisibilityFile, OneTixelFieldsRoundTrip) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "plenoptic_plv_one_tixel_test";
  std::filesystem::create_directories(dir);
  const std::string plv = (dir / "one.plv").string();
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
  std::filesystem::remove_all(dir);
}

TEST(VisibilityFile, RecordsWithAbsurdContentsAreRefusedDespiteAValidChecksum) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "plenoptic_plv_contents_test";
  std::filesystem::create_directories(dir);
  const std::string plv = (dir / "crafted.plv").string();
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
    try {
      readVisibility(plv, 0x1234, read, &why);
      ADD_FAILURE() << "accepted: " << c.problem;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("crafted.plv: extra record 0"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.problem), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pl
