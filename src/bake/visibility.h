#pragma once
// The visibility field (seed slide 21; docs/design.md, Visibility field): for every
// tixel and each of its gather directions, what is seen — a point on a non-specular chart
// (after following ideal-specular chains), or the environment. Computed once with Embree,
// saved beside the light field (.plv) and reused while geometry and parameterisation are
// unchanged, so that a change of emission or albedo only re-propagates.
//
// Gather directions. Each tixel has N = m² directions, one per cell of an m × m grid over the
// unit square mapped to the hemisphere by the concentric cosine-weighted map
// (sampleCosineHemisphere). Every cell has the same projected solid angle π/N, so a cell's
// contribution to irradiance is (π/N)·L. Inside its cell each tixel's ray passes through one
// of 4 × 4 sub-cells (at a jittered point fixed per cell, sub-cell and seed), chosen per tixel
// as a multi-jittered pattern (gatherSubCells): stratified per cell and, more finely, along
// each axis, and decorrelated between neighbouring tixels.
//
// Entries (8 bytes in memory, tixel-major: entry k of tixel g at g·N + k; compressed on disk):
//   target  bits 0–29: global index of the tixel at the lower-left of the 2×2 bilinear
//                      footprint of the seen point (kEscape: nothing was hit)
//           bit 30:    the seen chart was hit from behind (its back side)
//           bit 31:    the entry has an extra record (see below)
//   fu, fv  bilinear fractions towards tixel (i+1, j) and (i, j+1), × 65535
// Extra records (rare: glossy targets and paths through mirrors), in entry order per tixel,
// starting at extraOffset[g]:
//   throughput  product of the mirror reflectances along the chain (1 without mirrors)
//   st          paraboloid coordinates, in the seen chart's frame, of the direction in which
//               the seen point sends light back along the path (glossy targets); for a path
//               that leaves the scene after mirrors, the octahedral encoding of its final
//               world direction (to look the environment up)
//   viaMirror   whether the path went through at least one mirror
#include "core/math.h"
#include "bake/parameterisation.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pl {

class Accel;

struct VisibilityEntry {
  static constexpr uint32_t kIndexMask = 0x3fffffffu;
  static constexpr uint32_t kEscape = kIndexMask;
  static constexpr uint32_t kBackSide = 1u << 30;
  static constexpr uint32_t kHasExtra = 1u << 31;
  uint32_t target = kEscape;
  uint16_t fu = 0, fv = 0;

  uint32_t tixel() const { return target & kIndexMask; }
  bool escaped() const { return tixel() == kEscape; }
  bool backSide() const { return (target & kBackSide) != 0; }
  bool hasExtra() const { return (target & kHasExtra) != 0; }
};
static_assert(sizeof(VisibilityEntry) == 8);

struct VisibilityExtra {
  Rgb throughput{1.0f};
  Vec2 st{0.0f};
  uint32_t viaMirror = 0;
};
static_assert(sizeof(VisibilityExtra) == 24);

/// Read-only elements of a visibility field (a field just traced, or decoded from its .plv).
/// Copies share the storage.
template <typename T>
class FieldArray {
 public:
  FieldArray() = default;
  explicit FieldArray(std::vector<T> owned) {
    auto storage = std::make_shared<const std::vector<T>>(std::move(owned));
    data_ = storage->data();
    size_ = storage->size();
    keepAlive_ = std::move(storage);
  }

  const T* data() const { return data_; }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& operator[](size_t i) const { return data_[i]; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }

 private:
  std::shared_ptr<const void> keepAlive_;
  const T* data_ = nullptr;
  size_t size_ = 0;
};

struct VisibilityField {
  uint32_t gridSide = 0;          ///< m: N = m² gather directions per tixel
  uint64_t tixelCount = 0;
  uint64_t hash = 0;              ///< of geometry + parameterisation + settings (visibilityHash)
  FieldArray<VisibilityEntry> entries;    ///< tixelCount × N
  FieldArray<uint64_t> extraOffset;       ///< tixelCount + 1
  FieldArray<VisibilityExtra> extras;
  uint64_t rays = 0;              ///< rays traced to build it (gather + mirror continuations)
  double seconds = 0.0;

  uint32_t directionsPerTixel() const { return gridSide * gridSide; }
  uint64_t bytes() const {
    return entries.size() * sizeof(VisibilityEntry) + extraOffset.size() * sizeof(uint64_t) +
           extras.size() * sizeof(VisibilityExtra);
  }
};

/// Tixels [begin, end) (global tixel indices).
struct TixelRange {
  uint64_t begin = 0, end = 0;
  uint64_t size() const { return end - begin; }
  bool operator==(const TixelRange&) const = default;
};

/// The part of a visibility field one rank of a distributed bake holds (its shard): the
/// tixels of `ranges` (sorted, disjoint), stored one range after another in `field`, whose
/// tixelCount is their total (entries still name seen tixels by global index). A
/// single-process bake holds one range, every tixel.
struct VisibilityShard {
  VisibilityField field;
  std::vector<TixelRange> ranges;
  std::vector<uint64_t> localStart;  ///< per range: field index of its first tixel

  /// The whole field as a shard of one range (shares the storage).
  static VisibilityShard whole(const VisibilityField& field);
  /// `field` holding `ranges` (sorted, disjoint; their total must be field.tixelCount).
  static VisibilityShard of(VisibilityField field, std::vector<TixelRange> ranges);
  /// Whether every tixel of [begin, end) is held.
  bool holds(uint64_t begin, uint64_t end) const;
  /// Field index of held tixel g.
  uint64_t local(uint64_t g) const {
    if (ranges.size() == 1) return g - ranges[0].begin;
    size_t lo = 0, hi = ranges.size();
    while (hi - lo > 1) {
      const size_t mid = (lo + hi) / 2;
      if (ranges[mid].begin <= g) lo = mid; else hi = mid;
    }
    return localStart[lo] + (g - ranges[lo].begin);
  }
  /// Tixel g's N entries and its first extra record.
  const VisibilityEntry* entries(uint64_t g) const { return field.entries.data() + local(g) * field.directionsPerTixel(); }
  const VisibilityExtra* extras(uint64_t g) const { return field.extras.data() + field.extraOffset[local(g)]; }
};

/// The hash a shard's .plv carries: the whole field's (visibilityHash) for one range holding
/// every tixel, else that hash combined with the ranges, so that a shard traced for another
/// rank count or partition is not reused.
uint64_t visibilityShardHash(uint64_t fieldHash, const std::vector<TixelRange>& ranges, uint64_t tixelCount);

/// Octahedral map of unit vectors to [−1, 1]² and back (exact round trip up to float error).
inline Vec2 octahedralEncode(const Vec3& d) {
  const Vec3 a = d / (std::abs(d.x) + std::abs(d.y) + std::abs(d.z));
  if (a.z >= 0.0f) return {a.x, a.y};
  return {(1.0f - std::abs(a.y)) * (a.x >= 0.0f ? 1.0f : -1.0f), (1.0f - std::abs(a.x)) * (a.y >= 0.0f ? 1.0f : -1.0f)};
}
inline Vec3 octahedralDecode(Vec2 e) {
  Vec3 d(e.x, e.y, 1.0f - std::abs(e.x) - std::abs(e.y));
  if (d.z < 0.0f) {
    const float x = d.x;
    d.x = (1.0f - std::abs(d.y)) * (x >= 0.0f ? 1.0f : -1.0f);
    d.y = (1.0f - std::abs(x)) * (d.y >= 0.0f ? 1.0f : -1.0f);
  }
  return glm::normalize(d);
}

/// m for a requested number of gather directions: round(√N), at least 1.
uint32_t gatherGridSide(uint32_t gatherDirections);

/// Side of the grid of sub-cells inside each gather cell: a tixel's ray through cell k goes
/// through one sub-cell of it, at a point of that sub-cell fixed per (cell, sub-cell, seed).
inline constexpr uint32_t kGatherJitterSide = 4;
/// The sub-cell (column + kGatherJitterSide·row) that each gather cell k (column + gridSide·row)
/// of `tixel` uses, in out[k] (out.size() becomes gridSide²): multi-jittered, i.e. along each
/// column of cells the sub-columns are used equally often (exactly, when kGatherJitterSide
/// divides gridSide), and the sub-rows along each row of cells, in a random order per (tixel,
/// column or row, seed).
void gatherSubCells(uint64_t tixel, uint32_t gridSide, uint64_t seed, std::vector<uint8_t>& out);
/// Gather direction of cell k through sub-cell `subCell`, in the chart's local frame.
Vec3 gatherCellDirection(uint32_t k, uint32_t subCell, uint32_t gridSide, uint64_t seed);


/// Hash of everything the visibility field depends on: vertex positions, triangles and their
/// materials' *transport class* (chart kind, and mirror parameters, which the field's
/// throughputs contain — not diffuse albedo or emission), the parameterisation (charts,
/// gather points) and the settings that shape it (gather directions, mirror depth, seed).
uint64_t visibilityHash(const Scene& scene, const Parameterisation& param, const BakeSettings& settings);

/// Traces the visibility field (parallel, with a progress bar).
VisibilityField computeVisibility(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                  const BakeSettings& settings);
/// Traces the tixels of `ranges` only (sorted, disjoint), stored one range after another: a
/// rank's shard, whose hash is visibilityShardHash. Every tixel's entries are the same as in
/// the whole field (a tixel's rays depend only on the tixel, the seed and the scene).
VisibilityShard computeVisibilityShard(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                       const BakeSettings& settings, const std::vector<TixelRange>& ranges);

/// Writes the field atomically (temp + rename), compressed: zstd frames of blocks of
/// entries split into index and fraction planes (format: see visibility.cpp), with a progress bar.
void writeVisibility(const std::string& path, const VisibilityField& field);

/// Bytes writeVisibility holds besides the field itself (one batch of blocks and frames).
uint64_t visibilityWriteBufferBytes(uint32_t gridSide);

/// Reads and decodes a field into memory (the in-memory layout above: the bytes the bake's
/// memory estimate counts, checked with requireMemory before allocating). Returns false and
/// sets *why when the file is absent, of an older format version, or its hash differs from
/// expectedHash (a stale field is not an error); throws pl::Error naming the file when it is
/// present but corrupt or truncated (header, payload checksum, every frame and every index are
/// checked before it returns).
/// targetTixels: how many tixels the entries may point at (0: the file's own tixel count; a
/// shard's entries point at any tixel of the scene).
bool readVisibility(const std::string& path, uint64_t expectedHash, VisibilityField& field, std::string* why,
                    uint64_t targetTixels = 0);

}  // namespace pl
