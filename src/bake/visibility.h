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
// The field's data types (VisibilityEntry, VisibilityExtra, VisibilityField: what each entry
// means) and its .plv file are plf/plv_file.h's.
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bake/parameterisation.h"
#include "core/math.h"
#include "plf/plv_file.h"

namespace pl {

class Accel;
class EntryReader;
class VisibilityJournal;

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
  /// Every held tixel's entries decoded (8 bytes each, in field order), when the bake can
  /// afford them (holdDecoded): the gather then reads them instead of decoding each tixel in
  /// every iteration. Empty: decoded on the fly.
  FieldArray<VisibilityEntry> decoded;

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
  /// Whether the field's entries are streamed from its .plv (VisibilityField::stream): then
  /// only an EntryReader reads them, and entries() may not be called.
  bool streamed() const { return field.stream != nullptr; }
  /// Tixel g's N entries (held field): decoded into `scratch` (room for N), which it returns, or
  /// where `decoded` holds them.
  const VisibilityEntry* entries(uint64_t g, VisibilityEntry* scratch) const {
    if (!decoded.empty()) return decoded.data() + local(g) * field.directionsPerTixel();
    field.decode(local(g), scratch);
    return scratch;
  }
  /// Decodes every entry into `decoded` (in parallel) when they take at most `budget` bytes
  /// (8 per entry) and the field is held; returns whether it did. The entries are the same
  /// either way.
  bool holdDecoded(uint64_t budget);
  /// Calls body(t0, t1, reader) on disjoint sub-ranges [t0, t1) of the held tixels [begin, end)
  /// (contiguous in one of `ranges`), in parallel, each with an EntryReader of its own task:
  /// a held field in sub-ranges of at least `grain` tixels, a streamed one in whole entry
  /// blocks of its .plv (their parts inside [begin, end)), so that each block is read once.
  void forEachSpan(uint64_t begin, uint64_t end, uint64_t grain,
                   const std::function<void(uint64_t, uint64_t, EntryReader&)>& body) const;
  /// Tixel g's first extra record.
  const VisibilityExtra* extras(uint64_t g) const { return field.extras.data() + field.extraOffset[local(g)]; }
  /// How many extra records tixel g has.
  uint64_t extraCount(uint64_t g) const {
    const uint64_t t = local(g);
    return field.extraOffset[t + 1] - field.extraOffset[t];
  }
};

/// A task's reader of a shard's entries, tixel by tixel (not shared between threads): a held
/// field's are decoded from memory (VisibilityShard::entries); a streamed field's from the
/// entry block of its .plv that holds the tixel, which the reader decodes whole and keeps
/// until a tixel of another block is asked for. The entries are the same either way.
class EntryReader {
 public:
  explicit EntryReader(const VisibilityShard& vis) : vis_(vis) {}
  /// Held tixel g's N entries, in `scratch` (room for N) or where the field or the reader holds
  /// them decoded.
  const VisibilityEntry* entries(uint64_t g, VisibilityEntry* scratch) {
    if (!vis_.field.stream) return vis_.entries(g, scratch);
    return streamedEntries(g, scratch);
  }

 private:
  const VisibilityEntry* streamedEntries(uint64_t g, VisibilityEntry* scratch);
  const VisibilityShard& vis_;
  uint64_t block_ = ~uint64_t(0);  ///< the block in entries_
  std::vector<unsigned char> frame_, stream_;  ///< the block's stored frame, and its streams
  std::vector<VisibilityEntry> entries_;       ///< the block's entries, tixel-major
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
/// The gather cell (a + b·gridSide) whose directions contain the local direction `local`
/// (z ≥ 0, in the tixel's gather frame): the inverse of the cosine-weighted cell map.
uint32_t gatherCellOf(const Vec3& local, uint32_t gridSide);


/// Bits per fraction of the field's entries (plf/plv_file.h "Compact entries"):
/// kExactFractionBits when settings.exactVisibility, else kCompactFractionBits.
uint32_t visibilityFractionBits(const BakeSettings& settings);

/// Hash of everything the visibility field depends on: vertex positions, triangles and their
/// materials' *transport class* (chart kind, and mirror parameters, which the field's
/// throughputs contain — not diffuse albedo or emission), the parameterisation (charts,
/// gather points) and the settings that shape it (gather directions, mirror depth, seed,
/// fraction precision).
/// FNV-1a (core/hash.h Fnv1a64): the value is stored in every .plv header.
uint64_t visibilityHash(const Scene& scene, const Parameterisation& param, const BakeSettings& settings);

/// Traces the visibility field (parallel, with a progress bar).
VisibilityField computeVisibility(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                  const BakeSettings& settings);
/// Traces the tixels of `ranges` only (sorted, disjoint), stored one range after another: a
/// rank's shard, whose hash is visibilityShardHash. Every tixel's entries are the same as in
/// the whole field (a tixel's rays depend only on the tixel, the seed and the scene).
/// With a journal (resume.h), the blocks it restores are not traced again, and every block
/// traced is appended to it as it finishes; field.rays counts the rays traced in this call.
/// streamTo: empty, the field is held in memory (the caller saves it, writeVisibility); else
/// the field is streamed (docs/design.md, Visibility field): each block traced is written to
/// the .plv at streamTo (VisibilityWriter, in tixel order) and dropped, and the returned field
/// reads its entries from there (VisibilityField::stream); the same file writeVisibility writes.
VisibilityShard computeVisibilityShard(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                       const BakeSettings& settings, const std::vector<TixelRange>& ranges,
                                       bool showProgress = true, VisibilityJournal* journal = nullptr,
                                       const std::string& streamTo = "");

/// Rays a visibility memory estimate traces (estimateVisibilityBytesPerTixel): a few
/// hundredths of a second, against the minutes of a field that needs an estimate.
inline constexpr uint64_t kVisibilitySampleRays = uint64_t(1) << 16;
/// Bytes per tixel that the field of `ranges` (sorted, disjoint) will hold in memory.
struct VisibilityBytesPerTixel {
  double held = 0.0;      ///< held: its encoded entries, offsets and extra records (VisibilityField::bytes)
  double streamed = 0.0;  ///< streamed: the extra records and their offsets alone
};
/// VisibilityBytesPerTixel measured on a sample of the tixels of `ranges` spread evenly over
/// them (about kVisibilitySampleRays gather rays, at least one tixel), traced as the field
/// would be: the encoding's size depends on what the rays see.
VisibilityBytesPerTixel estimateVisibilityBytesPerTixel(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                                        const BakeSettings& settings, const std::vector<TixelRange>& ranges);

}  // namespace pl
