#pragma once
// Sample generators for Monte Carlo integration: one Sampler per (pixel, sample index), giving
// the numbers of one path (or one estimate) through get1D()/get2D().
//
// Two kinds:
//  * independent: the PCG32 stream Pcg32::forKey(key, sample index, seed), consumed in call
//    order (setDimension() is ignored). Every number is independent of every other: the
//    textbook estimator whose per-sample variance statistics are exact.
//  * sobol: Owen-scrambled Sobol points with a Morton-ordered per-pixel shuffle, after the
//    ZSobol sampler of pbrt-v4 (Pharr, Jakob, Humphreys, 4th ed., §8.7.7; Ahmed & Wonka 2020,
//    "Screen-space blue-noise diffusion of Monte Carlo sampling error via hierarchical ordering
//    of pixels"). All pixels of an image share one sequence: the global index of sample i of
//    pixel (x, y) is mortonIndex = (Morton(x, y) << log2(spp rounded up to 2^k)) | i. Each
//    dimension d sees that index through its own random nested shuffle (Burley 2020,
//    "Practical hash-based Owen scrambling": a hash-based Owen scramble of the index bits,
//    most significant first, so aligned blocks of indices stay aligned blocks; pbrt-v4 permutes
//    base-4 digits with one hash per digit instead: a first implementation of that here (with
//    more hashing per dimension too) made paths 2× slower, for the same per-pixel
//    stratification). Dimension d's value is then the first (1-D) or the first two (2-D)
//    dimensions of the Sobol sequence at that index, Owen-scrambled with
//    seeds hashed from (d, seed) (Burley 2020, after Laine & Karras 2011). So:
//      - a pixel's 2^k samples are an aligned block of 2^k consecutive points of an
//        Owen-scrambled (0,2)-sequence in every 2-D dimension: every elementary interval of
//        volume 2^-k holds exactly one of them (stratified in x, in y and jointly);
//      - different dimensions are decorrelated by their independent shuffles and scrambles
//        (the "padding" of Kollig & Keller 2002), so any number of dimensions is available;
//      - neighbouring pixels get different, complementary blocks (blue-noise-like error).
//    A sample depends only on (pixel, sample index, seed, image size, spp), never on the
//    thread or the tile that computes it.
//  Dimensions are explicit: the caller numbers them with setDimension(d) in a fixed layout
//  (e.g. per path bounce) so the same decision always uses the same dimension whatever was
//  drawn before it; between setDimension() calls, get1D()/get2D() use d, d + 1, ...
#include <array>
#include <algorithm>
#include <bit>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "core/math.h"
#include "core/rng.h"

namespace pl {

enum class SamplerKind : uint8_t { Independent, Sobol };

inline const char* samplerName(SamplerKind kind) { return kind == SamplerKind::Sobol ? "sobol" : "independent"; }

/// Parses "independent" or "sobol"; throws pl::Error listing the valid names otherwise.
inline SamplerKind parseSampler(const std::string& name) {
  if (name == "independent") return SamplerKind::Independent;
  if (name == "sobol") return SamplerKind::Sobol;
  fail("unknown sampler '{}' (expected independent or sobol)", name);
}

namespace sobol_detail {

/// Generator matrix columns of the second Sobol dimension (primitive polynomial x + 1, m = 1):
/// v₁ = 1/2, v_k = v_{k−1} ⊕ (v_{k−1} >> 1), as 0.32 fixed point. (The first dimension is the
/// van der Corput sequence, v_k = 2^−k: a bit reversal.)
constexpr std::array<uint32_t, 32> secondDimensionColumns() {
  std::array<uint32_t, 32> v{};
  v[0] = 0x80000000u;
  for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  return v;
}
inline constexpr std::array<uint32_t, 32> kSecondDimension = secondDimensionColumns();

constexpr uint32_t reverseBits32(uint32_t v) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
  v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
  return (v >> 16) | (v << 16);
}

/// The second dimension's matrix, columns bit-reversed, applied to each byte of the index:
/// kSecondDimensionBytes[j][v] is the XOR of the reversed columns 8j..8j+7 selected by the bits
/// of v, so a point costs 4 lookups.
constexpr std::array<std::array<uint32_t, 256>, 4> secondDimensionByteTables() {
  std::array<std::array<uint32_t, 256>, 4> t{};
  for (int j = 0; j < 4; ++j)
    for (uint32_t v = 0; v < 256; ++v)
      for (int bit = 0; bit < 8; ++bit)
        if (v & (1u << bit)) t[size_t(j)][v] ^= reverseBits32(kSecondDimension[size_t(8 * j + bit)]);
  return t;
}
inline constexpr std::array<std::array<uint32_t, 256>, 4> kSecondDimensionBytes = secondDimensionByteTables();

}  // namespace sobol_detail

using sobol_detail::reverseBits32;

/// Point `index` of the first (dimension 0) or second (dimension 1) Sobol dimension, as 0.32
/// fixed point with its bits reversed (the form the scramble works on: the first dimension,
/// the van der Corput sequence, is then the index itself).
inline uint32_t reversedSobolPoint(uint32_t index, int dimension) {
  if (dimension == 0) return index;
  const auto& t = sobol_detail::kSecondDimensionBytes;
  return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^ t[3][index >> 24];
}

/// Hash-based Owen scrambling (Burley 2020, after Laine & Karras 2011) of a 0.32 fixed-point
/// value given bit-reversed: a multiply-xor hash in which every bit only depends on the bits
/// below it is, in reversed order, a nested uniform scramble — each bit is flipped by a random
/// function of the more significant bits. A different seed gives an independent scramble.
/// Returns the scrambled value, still reversed.
inline uint32_t owenScrambleReversed(uint32_t v, uint32_t seed) {
  v ^= v * 0x3d20adeau;
  v += seed;
  v *= (seed >> 16) | 1u;
  v ^= v * 0x05526c56u;
  v ^= v * 0x53a22864u;
  return v;
}

/// An Owen-scrambled Sobol value: dimension 0 or 1 of point `index`, as 0.32 fixed point.
inline uint32_t scrambledSobol(uint32_t index, int dimension, uint32_t seed) {
  return reverseBits32(owenScrambleReversed(reversedSobolPoint(index, dimension), seed));
}

/// 0.32 fixed point to a float in [0, 1): the top 24 bits, so never 1.
inline float fixedToUnit(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

/// The part of the ZSobol sequence shared by all pixels of one image.
class ZSobolLayout {
 public:
  ZSobolLayout() = default;
  /// width, height ≤ 2^16; spp ≥ 1 (rounded up to a power of two for the index layout).
  ZSobolLayout(int width, int height, int spp, uint64_t seed) : seed_(seed) {
    if (width < 1 || height < 1 || width > (1 << 16) || height > (1 << 16) || spp < 1)
      fail("sobol sampler: image {}x{} at {} spp is out of range (sides 1..65536)", width, height, spp);
    log2Spp_ = std::bit_width(uint32_t(spp - 1));
    const int log2Resolution = std::bit_width(uint32_t(std::max(width, height) - 1));
    indexBits_ = 2 * log2Resolution + log2Spp_;
  }
  /// A layout for estimates keyed by an arbitrary number instead of a pixel: the key only
  /// selects an independent scramble, every key's samples are the sequence's first points.
  static ZSobolLayout forKey(uint64_t key, int spp, uint64_t seed) {
    ZSobolLayout l(1, 1, spp, hashCombine(key, seed ^ 0x5a534f424f4cULL));
    return l;
  }
  int log2Spp() const { return log2Spp_; }
  int indexBits() const { return indexBits_; }
  uint64_t seed() const { return seed_; }

 private:
  uint64_t seed_ = 0;
  int log2Spp_ = 0;
  int indexBits_ = 0;  ///< bits of the global index: 2·log2(resolution) + log2(spp)
};

/// Interleaves the bits of x (even positions) and y (odd positions): the Morton (Z) order.
inline uint64_t mortonEncode2(uint32_t x, uint32_t y) {
  auto spread = [](uint64_t v) {
    v &= 0xffffffffULL;
    v = (v | (v << 16)) & 0x0000ffff0000ffffULL;
    v = (v | (v << 8)) & 0x00ff00ff00ff00ffULL;
    v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0fULL;
    v = (v | (v << 2)) & 0x3333333333333333ULL;
    v = (v | (v << 1)) & 0x5555555555555555ULL;
    return v;
  };
  return spread(x) | (spread(y) << 1);
}

/// The numbers of one sample (one path): see the top of this file.
class Sampler {
 public:
  /// The PCG32 stream of (key, sample index, seed), numbers in call order.
  static Sampler independent(uint64_t key, uint64_t sampleIndex, uint64_t seed) {
    Sampler s;
    s.kind_ = SamplerKind::Independent;
    s.rng_ = Pcg32::forKey(key, sampleIndex, seed);
    return s;
  }
  /// Sample `sampleIndex` (< 2^layout.log2Spp()) of pixel (x, y) of the layout's image.
  static Sampler sobol(const ZSobolLayout& layout, int x, int y, uint64_t sampleIndex) {
    Sampler s;
    s.kind_ = SamplerKind::Sobol;
    s.layout_ = layout;
    s.mortonIndex_ = (mortonEncode2(uint32_t(x), uint32_t(y)) << layout.log2Spp()) | sampleIndex;
    return s;
  }
  /// `kind` for pixel (x, y), sample `sampleIndex`; `key` is the independent stream's key.
  static Sampler make(SamplerKind kind, const ZSobolLayout& layout, uint64_t key, int x, int y,
                      uint64_t sampleIndex, uint64_t seed) {
    return kind == SamplerKind::Sobol ? sobol(layout, x, y, sampleIndex) : independent(key, sampleIndex, seed);
  }

  SamplerKind kind() const { return kind_; }
  /// Next get1D()/get2D() uses dimension d (sobol); the independent stream ignores it.
  void setDimension(uint32_t d) { dimension_ = d; }

  float get1D() {
    if (kind_ == SamplerKind::Independent) return rng_.uniform();
    const uint64_t h = dimensionHash(dimension_++);
    const uint32_t index = shuffledIndex(h);
    return fixedToUnit(scrambledSobol(index, 0, uint32_t(h >> 32)));
  }
  Vec2 get2D() {
    if (kind_ == SamplerKind::Independent) {
      const float a = rng_.uniform();
      return {a, rng_.uniform()};
    }
    const uint64_t h = dimensionHash(dimension_++);
    const uint32_t index = shuffledIndex(h);
    return {fixedToUnit(scrambledSobol(index, 0, uint32_t(h >> 32))), fixedToUnit(scrambledSobol(index, 1, uint32_t(h)))};
  }

 private:
  /// 64 random bits per dimension, from which the index shuffle's seed and the two Owen
  /// scramble seeds are drawn (one hash per dimension). Global indices beyond 32 bits (2·16 +
  /// k > 32: images over 2^16 pixels at 2^k spp) hash their high bits in too, so each 2^32
  /// block of the sequence is scrambled on its own instead of repeating another's points.
  uint64_t dimensionHash(uint32_t d) const {
    const uint64_t high = mortonIndex_ >> 32;  // < 2^31: indexBits ≤ 63
    return mix64(((uint64_t(d) << 32) | high) ^ layout_.seed());
  }
  /// The low 32 bits of the global index as dimension d (hash h) sees them: a nested uniform
  /// shuffle, i.e. an Owen scramble of the index bits from the most significant one down
  /// (the index is left-aligned so that its top bit is the scramble's first). Aligned blocks
  /// of 2^j indices — a pixel's samples — stay aligned blocks.
  uint32_t shuffledIndex(uint64_t h) const {
    const int bits = std::min(layout_.indexBits(), 32);
    if (bits == 0) return 0;
    const int shift = 32 - bits;
    const uint32_t seed = uint32_t((h * 0x9e3779b97f4a7c15ULL) >> 32);
    return reverseBits32(owenScrambleReversed(reverseBits32(uint32_t(mortonIndex_) << shift), seed)) >> shift;
  }

  SamplerKind kind_ = SamplerKind::Independent;
  Pcg32 rng_;
  ZSobolLayout layout_;
  uint64_t mortonIndex_ = 0;
  uint32_t dimension_ = 0;
};

}  // namespace pl
