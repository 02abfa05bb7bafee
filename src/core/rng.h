#pragma once
// Reproducible random numbers: PCG32 (O'Neill 2014), seeded by hashing (pixel, sample, seed)
// so that every sample of every pixel gets the same stream whatever thread renders it.
#include <cstdint>

namespace pl {

/// 64-bit mix (SplitMix64 finaliser): a good avalanche for combining integer keys.
inline uint64_t mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

inline uint64_t hashCombine(uint64_t a, uint64_t b) { return mix64(a ^ (mix64(b) + 0x9e3779b97f4a7c15ULL)); }

class Pcg32 {
 public:
  Pcg32() { seed(0x853c49e6748fea9bULL, 0xda3e39cb94b95bdbULL); }
  Pcg32(uint64_t state, uint64_t stream) { seed(state, stream); }

  /// A generator for (a, b, c) keys, e.g. (pixel index, sample index, user seed).
  static Pcg32 forKey(uint64_t a, uint64_t b, uint64_t c) {
    return Pcg32(hashCombine(hashCombine(a, b), c), mix64(c + 0x632be59bd9b4e019ULL));
  }

  void seed(uint64_t initState, uint64_t stream) {
    state_ = 0;
    inc_ = (stream << 1u) | 1u;
    next();
    state_ += initState;
    next();
  }
  uint32_t next() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  /// Uniform float in [0, 1): 24 random mantissa bits, never returns 1.
  float uniform() { return static_cast<float>(next() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_ = 0, inc_ = 0;
};

}  // namespace pl
