// Known XXH64 digests of fixed inputs (core/hash.h). The values were computed by the
// hand-written XXH64 that core/hash.cpp held before it called Debian's libxxhash: every .plf
// and .plv checksum written before the switch must verify after it, so these must never change.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/hash.h"

namespace pl {
namespace {

/// 1 MiB of fixed bytes: the top byte of a 64-bit LCG (Knuth's MMIX constants).
const std::vector<unsigned char>& fixedBytes() {
  static const std::vector<unsigned char> bytes = [] {
    std::vector<unsigned char> v(size_t(1) << 20);
    uint64_t state = 0x243F6A8885A308D3ull;
    for (unsigned char& b : v) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      b = static_cast<unsigned char>(state >> 56);
    }
    return v;
  }();
  return bytes;
}

constexpr uint64_t kSeeds[4] = {0, 1, 0x9E3779B97F4A7C15ull, ~0ull};

struct Known {
  size_t size;  ///< a prefix of fixedBytes()
  uint64_t digest[4];  ///< for each of kSeeds
};

// Sizes around every branch of XXH64: the short path and its 8-, 4- and 1-byte tails, the
// 32-byte stripe boundary, several stripes, and large inputs.
const Known kKnown[] = {
    {0, {0xef46db3751d8e999ull, 0xd5afba1336a3be4bull, 0xc4349fc93c010000ull, 0x298f4c84b24f5380ull}},
    {1, {0xdb3a37b824eaec5bull, 0x221f4c8babe9e31aull, 0xf287511522270d96ull, 0x36652e8771b6ae2cull}},
    {2, {0x439bd150a96b5192ull, 0x9a1b24e22ca4b137ull, 0xa11230d1c529f5a5ull, 0x955f2066d7c9996dull}},
    {3, {0x560c4751a56a8d7full, 0x69d6e4785b166e3eull, 0xcd20071f020303e6ull, 0x96f6194dff3eea8dull}},
    {4, {0x7e59541344eedbbcull, 0xb71496c6594667f5ull, 0x377f75b49ffde35full, 0xce1322a1e04e5ab8ull}},
    {5, {0x47b48ea47dde0cc9ull, 0x9a58e1f3b9ceadedull, 0x953478d4d95325f2ull, 0x0b5aa9a2527d016full}},
    {7, {0xa6da705a5199db33ull, 0x8fb6e50164e264dcull, 0x01fc2a3934d522c3ull, 0x3274c69428858524ull}},
    {8, {0x66b9b439797f72e0ull, 0x540909c6b3bcd00aull, 0xb37210c944cc13c6ull, 0xd850c2cc988bcc4cull}},
    {9, {0xa1efc9e31fd7b57full, 0x68a811cb096855baull, 0x580e983992b49086ull, 0x90ba558edc8c51f8ull}},
    {15, {0x15356ab76781fe61ull, 0x4ff380aacb0748c9ull, 0x63186f3c551e2310ull, 0x8addba660d2db792ull}},
    {16, {0xf86160a8f4442f8eull, 0xddb7d20e2d42df0bull, 0x693824e92294abffull, 0x3a1993b9c23497b5ull}},
    {17, {0xdcadc41226941d92ull, 0x816f039a8ffa0217ull, 0xaed4f81b0d03a93bull, 0x2fb4b4cb8fbd423full}},
    {31, {0xfa3d2dc9c4d0e713ull, 0xbb4d95cd62e8287cull, 0x8e893dbc69614e78ull, 0xdb5a310c40401635ull}},
    {32, {0x81e5f5a26aef3225ull, 0xa02a61ed2d06e912ull, 0x0ba5e0aec4dd9b80ull, 0xe1878d51d2b9e85cull}},
    {33, {0x0bdabb3c4bc92164ull, 0x84d38ca9cd0c05b6ull, 0x064a31fcd2300117ull, 0x9889ce0961c22e0aull}},
    {63, {0x94f430626935e311ull, 0x099f6b3876b3d356ull, 0xa1e4b8fe4b6642cbull, 0x7b36910f0bc67d50ull}},
    {64, {0x2d26d7c0241a4babull, 0x05887b7cc9f51178ull, 0xaca5994c167bd0fdull, 0x774fd3a41c865beaull}},
    {65, {0x14342984a71a7394ull, 0x5d574cd3f2c48962ull, 0x9bbd0feea876a848ull, 0x3dbffe3a44afaf9aull}},
    {100, {0xe569e218376f833cull, 0xd7fce40d099712c6ull, 0x87fc487096e655ddull, 0x03d676fbc6c4c339ull}},
    {255, {0x98a0502324385e52ull, 0xee1dfc5d060fbcacull, 0xa2a619a91ee15da2ull, 0x440f6da5a53586a7ull}},
    {256, {0x9612f4adfeb393d9ull, 0x1c1b7b6c59ae48efull, 0x2a6b4046b2eb91c3ull, 0x8af8d52a6d692c68ull}},
    {1000, {0x406674660863df6cull, 0xc88b439d8f63f42dull, 0xb50a79500a68800full, 0x367cfc8a86843029ull}},
    {4096, {0x199d3f1d52ddf677ull, 0x84a8c991fbd6fc46ull, 0x086e93452943a914ull, 0x7c90e945610b0cc7ull}},
    {65537, {0x3f4b0dc956329066ull, 0xd6446b5a233381d9ull, 0x02579e1b34a17527ull, 0x095a5631e2a731b3ull}},
    {1048576, {0x8ca507f41ad25f85ull, 0x884fae3bfa2a6721ull, 0x6feeb925d0d61aeaull, 0x42d57a604fe25cf8ull}},
};

/// The known digest of the first `size` fixed bytes with kSeeds[seedIndex].
uint64_t known(size_t size, int seedIndex) {
  for (const Known& k : kKnown)
    if (k.size == size) return k.digest[seedIndex];
  ADD_FAILURE() << "no known digest of " << size << " bytes";
  return 0;
}

TEST(Xxh64KnownDigests, OneShotMatchesTheDigestsFilesWereWrittenWith) {
  const std::vector<unsigned char>& bytes = fixedBytes();
  for (const Known& k : kKnown)
    for (int s = 0; s < 4; ++s)
      EXPECT_EQ(xxh64(bytes.data(), k.size, kSeeds[s]), k.digest[s]) << k.size << " bytes, seed " << kSeeds[s];
}

TEST(Xxh64KnownDigests, StreamingInPiecesMatchesTheSameDigests) {
  const std::vector<unsigned char>& bytes = fixedBytes();
  for (const Known& k : kKnown)
    for (size_t piece : {size_t(1), size_t(5), size_t(32), size_t(33), size_t(4099)}) {
      if (k.size > 70000 && piece < 32) continue;  // (1 MiB in single bytes adds nothing)
      Xxh64Stream stream(kSeeds[2]);
      for (size_t at = 0; at < k.size; at += piece) stream.update(bytes.data() + at, std::min(piece, k.size - at));
      EXPECT_EQ(stream.digest(), k.digest[2]) << k.size << " bytes in pieces of " << piece;
    }
}

TEST(Xxh64KnownDigests, DigestIsRepeatableAndACopyContinuesIndependently) {
  const std::vector<unsigned char>& bytes = fixedBytes();
  Xxh64Stream stream(kSeeds[1]);
  stream.update(bytes.data(), 40);
  EXPECT_EQ(stream.digest(), stream.digest());
  Xxh64Stream copy = stream;
  copy.update(bytes.data() + 40, 60);
  stream.update(bytes.data() + 40, 24);
  EXPECT_EQ(copy.digest(), known(100, 1));
  EXPECT_EQ(stream.digest(), known(64, 1));
  EXPECT_EQ(Xxh64Stream(kSeeds[3]).digest(), known(0, 3));  // nothing fed
  stream.update(nullptr, 0);  // an empty array's null pointer is allowed
  EXPECT_EQ(stream.digest(), known(64, 1));
}

// FNV-1a 64 (the .plv header's visibility hash): the published test vectors of Fowler, Noll
// and Vo, so that every saved .plv keeps its hash.
TEST(Fnv1a64KnownDigests, MatchesThePublishedVectors) {
  auto digest = [](const char* text, size_t size) {
    Fnv1a64 h;
    h.update(text, size);
    return h.digest();
  };
  EXPECT_EQ(digest("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(digest("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(digest("foobar", 6), 0x85944171f73967e8ull);
  Fnv1a64 pieces;  // value() feeds a value's bytes, in pieces as the whole
  pieces.value('f');
  pieces.update("oob", 3);
  pieces.value(uint16_t('a' | 'r' << 8));  // little-endian: 'a' then 'r'
  EXPECT_EQ(pieces.digest(), 0x85944171f73967e8ull);
}

}  // namespace
}  // namespace pl
