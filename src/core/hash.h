#pragma once
// XXH64, Yann Collet's 64-bit xxHash: the checksum of .plf sections and headers and of the .plv
// payload (~10 GB/s, so verifying a file costs far less than reading it).
#include <cstddef>
#include <cstdint>

namespace pl {

/// XXH64 (Yann Collet's xxHash, 64-bit variant) of `size` bytes: the checksum of .plf and .plv files.
uint64_t xxh64(const void* data, size_t size, uint64_t seed = 0);

/// Incremental XXH64 for data that arrives in pieces; equals xxh64() of the concatenation.
class Xxh64Stream {
 public:
  explicit Xxh64Stream(uint64_t seed = 0);
  void update(const void* data, size_t size);
  uint64_t digest() const;

 private:
  uint64_t lanes_[4];
  uint64_t seed_;
  uint64_t totalLength_ = 0;
  unsigned char buffer_[32];
  size_t buffered_ = 0;
};

}  // namespace pl
