#pragma once
// XXH64, Yann Collet's 64-bit xxHash (Debian's libxxhash): the checksum of .plf sections and
// headers and of the .plv payload (~10 GB/s, so verifying a file costs far less than reading it).
#include <cstddef>
#include <cstdint>

namespace pl {

/// XXH64 (Yann Collet's xxHash, 64-bit variant) of `size` bytes: the checksum of .plf and .plv files.
uint64_t xxh64(const void* data, size_t size, uint64_t seed = 0);

/// Incremental XXH64 for data that arrives in pieces; equals xxh64() of the concatenation.
/// Copyable: a copy continues independently from the same point.
class Xxh64Stream {
 public:
  explicit Xxh64Stream(uint64_t seed = 0);
  void update(const void* data, size_t size);
  uint64_t digest() const;

 private:
  // libxxhash's XXH64_state_t, held by value so that this header does not include xxhash.h
  // (hash.cpp checks that it fits). A plain struct: copying its bytes copies the state.
  alignas(8) unsigned char state_[96];
};

}  // namespace pl
