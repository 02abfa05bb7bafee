// XXH64 (see hash.h), from Debian's libxxhash. Its digests are those of the specification
// (https://github.com/Cyan4973/xxHash/blob/dev/doc/xxhash_spec.md), the ones every .plf and
// .plv file was written with; hash_test.cpp pins them.
#include "core/hash.h"

#define XXH_STATIC_LINKING_ONLY  // XXH64_state_t's definition, to hold it by value
#include <xxhash.h>

#include <new>

namespace pl {
namespace {

static_assert(sizeof(XXH64_state_t) <= 96 && alignof(XXH64_state_t) <= 8,
              "Xxh64Stream::state_ is too small for this libxxhash's XXH64_state_t");

XXH64_state_t* stateOf(unsigned char* bytes) { return std::launder(reinterpret_cast<XXH64_state_t*>(bytes)); }
const XXH64_state_t* stateOf(const unsigned char* bytes) {
  return std::launder(reinterpret_cast<const XXH64_state_t*>(bytes));
}

}  // namespace

Xxh64Stream::Xxh64Stream(uint64_t seed) : state_{} {
  new (state_) XXH64_state_t{};
  XXH64_reset(stateOf(state_), seed);
}

void Xxh64Stream::update(const void* data, size_t size) {
  if (size == 0) return;  // (data may then be null, e.g. an empty array's)
  XXH64_update(stateOf(state_), data, size);
}

uint64_t Xxh64Stream::digest() const { return XXH64_digest(stateOf(state_)); }

uint64_t xxh64(const void* data, size_t size, uint64_t seed) { return XXH64(size == 0 ? "" : data, size, seed); }

}  // namespace pl
