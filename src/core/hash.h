#pragma once
// The project's hashes of bytes, both stored in its files:
//  * XXH64, Yann Collet's 64-bit xxHash (Debian's libxxhash): the checksum of .plf sections and
//    headers and of the .plv payload (~10 GB/s, so verifying a file costs far less than reading it);
//  * FNV-1a (64 bit): the visibility field's key (bake/visibility.h visibilityHash), kept for
//    that alone because every saved .plv carries it in its header (file-formats.md): another
//    hash would make every existing .plv look stale to `bake --reuse-visibility`. New uses take
//    XXH64.
#include <cstddef>
#include <cstdint>
#include <type_traits>

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

/// FNV-1a, 64 bit (Fowler, Noll, Vo: offset basis 0xcbf29ce484222325, prime 0x100000001b3),
/// fed byte by byte: a change detector, not a checksum of large data (see above for its one use).
class Fnv1a64 {
 public:
  void update(const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) {
      state_ ^= p[i];
      state_ *= 0x100000001b3ULL;
    }
  }
  /// The bytes of one trivially copyable value (its object representation, padding included).
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    update(&v, sizeof(T));
  }
  uint64_t digest() const { return state_; }

 private:
  uint64_t state_ = 0xcbf29ce484222325ULL;
};

}  // namespace pl
