// XXH64 (see hash.h).
#include "core/hash.h"

#include <algorithm>
#include <bit>
#include <cstring>

namespace pl {

// XXH64 (xxHash specification, https://github.com/Cyan4973/xxHash/blob/dev/doc/xxhash_spec.md):
// four 64-bit accumulator lanes consume 32-byte stripes; the tail and the length are mixed
// in at the end and the result is avalanched. ~10 GB/s here, so verifying a file costs far
// less than reading it.
namespace {

constexpr uint64_t kPrime1 = 0x9E3779B185EBCA87ull;
constexpr uint64_t kPrime2 = 0xC2B2AE3D27D4EB4Full;
constexpr uint64_t kPrime3 = 0x165667B19E3779F9ull;
constexpr uint64_t kPrime4 = 0x85EBCA77C2B2AE63ull;
constexpr uint64_t kPrime5 = 0x27D4EB2F165667C5ull;

uint64_t load64(const unsigned char* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}
uint32_t load32(const unsigned char* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
uint64_t xxhRound(uint64_t acc, uint64_t input) {
  acc += input * kPrime2;
  acc = std::rotl(acc, 31);
  return acc * kPrime1;
}
uint64_t xxhMerge(uint64_t acc, uint64_t lane) {
  acc ^= xxhRound(0, lane);
  return acc * kPrime1 + kPrime4;
}

}  // namespace

Xxh64Stream::Xxh64Stream(uint64_t seed) : seed_(seed) {
  lanes_[0] = seed + kPrime1 + kPrime2;
  lanes_[1] = seed + kPrime2;
  lanes_[2] = seed;
  lanes_[3] = seed - kPrime1;
}

void Xxh64Stream::update(const void* data, size_t size) {
  if (size == 0) return;  // (data may then be null, e.g. an empty array's, which memcpy may not see)
  auto* p = static_cast<const unsigned char*>(data);
  totalLength_ += size;
  auto consumeStripe = [this](const unsigned char* stripe) {
    for (int lane = 0; lane < 4; ++lane) lanes_[lane] = xxhRound(lanes_[lane], load64(stripe + 8 * lane));
  };
  if (buffered_ > 0) {
    const size_t take = std::min(size, sizeof(buffer_) - buffered_);
    std::memcpy(buffer_ + buffered_, p, take);
    buffered_ += take;
    p += take;
    size -= take;
    if (buffered_ < sizeof(buffer_)) return;
    consumeStripe(buffer_);
    buffered_ = 0;
  }
  for (; size >= 32; p += 32, size -= 32) consumeStripe(p);
  std::memcpy(buffer_, p, size);
  buffered_ = size;
}

uint64_t Xxh64Stream::digest() const {
  uint64_t h;
  if (totalLength_ >= 32) {
    h = std::rotl(lanes_[0], 1) + std::rotl(lanes_[1], 7) + std::rotl(lanes_[2], 12) + std::rotl(lanes_[3], 18);
    for (uint64_t lane : lanes_) h = xxhMerge(h, lane);
  } else {
    h = seed_ + kPrime5;
  }
  h += totalLength_;
  const unsigned char* p = buffer_;
  size_t size = buffered_;
  for (; size >= 8; p += 8, size -= 8) h = std::rotl(h ^ xxhRound(0, load64(p)), 27) * kPrime1 + kPrime4;
  if (size >= 4) {
    h = std::rotl(h ^ uint64_t(load32(p)) * kPrime1, 23) * kPrime2 + kPrime3;
    p += 4;
    size -= 4;
  }
  for (; size > 0; ++p, --size) h = std::rotl(h ^ uint64_t(*p) * kPrime5, 11) * kPrime1;
  h ^= h >> 33;
  h *= kPrime2;
  h ^= h >> 29;
  h *= kPrime3;
  h ^= h >> 32;
  return h;
}

uint64_t xxh64(const void* data, size_t size, uint64_t seed) {
  Xxh64Stream stream(seed);
  stream.update(data, size);
  return stream.digest();
}

}  // namespace pl
