// The visibility field: gather directions, tracing and hashing (FNV-1a, core/hash.h). Its .plv file: plf/plv_file.cpp.
#include "bake/visibility.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>

#include "accel/accel.h"
#include "bake/resume.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "lightfield/lookup.h"

namespace pl {

namespace {

/// Beer–Lambert attenuation exp(−σa t) of a gather segment of length t that ends on chart
/// record c: a segment arriving at the back record of rough glass ran through the solid's
/// inside (the front of a closed mesh is its outside), as followSpecular attenuates one
/// arriving at the back of smooth glass. 1 for every other record.
Rgb insideGlassAttenuation(const Scene& scene, const Chart& c, float t) {
  const Bsdf& bsdf = scene.materials[c.material].bsdf;
  if (!c.isBack || !isRoughGlassChart(c, bsdf)) return Rgb(1.0f);
  return glm::exp(-std::get<DielectricBsdf>(bsdf).absorption * t);
}

}  // namespace

uint32_t gatherGridSide(uint32_t gatherDirections) {
  return std::max<uint32_t>(1, uint32_t(std::lround(std::sqrt(double(gatherDirections)))));
}

namespace {

// Inside its cell, a tixel's ray goes through one of kJitterSide² sub-cells, at a point of
// that sub-cell fixed by a hash of (cell, sub-cell, seed): the directions of every (cell,
// sub-cell) pair are tabulated once per field. (Sub-cell *centres* would put the directions
// on a regular lattice, and rays from regularly spaced tixels would then hit the exact edges
// and corners of axis-aligned boxes, where ray-triangle tests may miss.)
//
// The sub-cells are chosen per tixel as a multi-jittered pattern (Chiu, Shirley & Wang 1994):
// in each column of cells the G cells take sub-columns rank mod kJitterSide, where rank is
// the cell's position in a random permutation of that column (Fisher–Yates with hashed
// choices, keyed by (tixel, column, seed)), and likewise sub-rows along each row of cells.
// When kJitterSide divides G every sub-column of a column of cells (and every sub-row of a
// row) is used equally often, so besides one direction per cell the projections onto each
// axis are stratified kJitterSide times finer (jittered sampling stratifies the cells only);
// the random permutations keep tixels decorrelated.
constexpr uint32_t kJitterSide = kGatherJitterSide;
constexpr uint32_t kJitterCount = kJitterSide * kJitterSide;

uint64_t tixelSalt(uint64_t tixel, uint64_t seed) { return hashCombine(tixel, seed ^ 0x5649534942494c59ULL); }

}  // namespace

void gatherSubCells(uint64_t tixel, uint32_t gridSide, uint64_t seed, std::vector<uint8_t>& out) {
  out.assign(size_t(gridSide) * gridSide, 0);
  const uint64_t salt = tixelSalt(tixel, seed);
  // Line q of the 2G lines is column q/2 (q even: cells q/2 + i·G) or row q/2 (q odd: cells
  // i + (q/2)·G), permuted by a Fisher–Yates shuffle: order[rank] = the cell (along the line)
  // with that rank, from order = identity by swapping order[i − 1] with order[j] for i = G … 2,
  // j = 32 hashed bits of (line salt + i) scaled to [0, i) (Lemire's multiply-shift; the bias
  // is < i/2^32). kLines lines are shuffled side by side, a step of each in turn: each
  // shuffle's swaps wait on one another, those of different lines do not (the propagation
  // calls this for every normal-mapped tixel in every iteration).
  constexpr uint32_t kLines = 8;
  uint8_t order[kLines][kMaxGatherGridSide];
  uint64_t lineSalt[kLines];
  const uint32_t lines = 2 * gridSide;
  for (uint32_t q0 = 0; q0 < lines; q0 += kLines) {
    const uint32_t count = std::min(kLines, lines - q0);
    for (uint32_t l = 0; l < count; ++l) {
      lineSalt[l] = salt ^ (uint64_t(q0 + l) * 0x9e3779b97f4a7c15ULL);
      for (uint32_t i = 0; i < gridSide; ++i) order[l][i] = uint8_t(i);
    }
    for (uint32_t i = gridSide; i > 1; --i)
      for (uint32_t l = 0; l < count; ++l) {
        const uint32_t j = uint32_t((uint64_t(uint32_t(mix64(lineSalt[l] + i))) * i) >> 32);
        std::swap(order[l][i - 1], order[l][j]);
      }
    // A column's cells take sub-column rank mod J, a row's sub-row rank mod J.
    for (uint32_t l = 0; l < count; ++l) {
      const uint32_t line = (q0 + l) / 2;
      if ((q0 + l) % 2 == 0)
        for (uint32_t rank = 0; rank < gridSide; ++rank) out[line + order[l][rank] * gridSide] += uint8_t(rank % kJitterSide);
      else
        for (uint32_t rank = 0; rank < gridSide; ++rank)
          out[order[l][rank] + line * gridSide] += uint8_t(kJitterSide * (rank % kJitterSide));
    }
  }
}

namespace {

inline Vec3 cellDirection(uint32_t k, uint32_t jitter, uint32_t gridSide, uint64_t seed) {
  const uint64_t h = hashCombine(hashCombine(k, jitter), seed ^ 0x4a4954544552ULL);
  const float offsetU = float(uint32_t(h) >> 8) * 0x1p-24f, offsetV = float(uint32_t(h >> 32) >> 8) * 0x1p-24f;
  const float a = float(k % gridSide) + (float(jitter % kJitterSide) + offsetU) / kJitterSide;
  const float b = float(k / gridSide) + (float(jitter / kJitterSide) + offsetV) / kJitterSide;
  const float inv = 1.0f / float(gridSide);
  return sampleCosineHemisphere(Vec2(a * inv, b * inv));
}

}  // namespace

Vec3 gatherCellDirection(uint32_t k, uint32_t subCell, uint32_t gridSide, uint64_t seed) {
  return cellDirection(k, subCell, gridSide, seed);
}

uint32_t gatherCellOf(const Vec3& local, uint32_t gridSide) {
  const Vec2 u = inverseConcentricDisk(Vec2(local.x, local.y));
  const uint32_t a = std::min(uint32_t(u.x * float(gridSide)), gridSide - 1);
  const uint32_t b = std::min(uint32_t(u.y * float(gridSide)), gridSide - 1);
  return a + b * gridSide;
}

uint32_t visibilityFractionBits(const BakeSettings& settings) {
  return settings.exactVisibility ? kExactFractionBits : kCompactFractionBits;
}

uint64_t visibilityHash(const Scene& scene, const Parameterisation& param, const BakeSettings& settings) {
  Fnv1a64 h;
  h.value(kPlvVersion);
  h.value(visibilityFractionBits(settings));
  h.value(uint64_t(scene.meshes.size()));
  for (const Mesh& mesh : scene.meshes) {
    h.value(uint64_t(mesh.triangles.size()));
    for (const UVec3& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) h.value(mesh.positions[t[k]]);
    }
    h.update(mesh.materials.data(), mesh.materials.size() * sizeof(uint32_t));
    // Vertex alphas cut an alpha mask like its texture (meshes without them hash as before).
    if (!mesh.alphas.empty()) h.update(mesh.alphas.data(), mesh.alphas.size() * sizeof(float));
  }
  for (const Material& m : scene.materials) {
    h.value(uint8_t(chartKindOf(m.bsdf, settings)));
    // Specular models bend and weight the chains folded into the field, and transmitting
    // ones attenuate the gather rays inside them: all their parameters (the model's
    // parameters() hook, bsdf.h). Other models' parameters (a roughness, an albedo) change
    // only the propagation, so a field traced before such an edit is reused.
    if (chartKindOf(m.bsdf, settings) == ChartKind::Specular || hasTransmission(m.bsdf)) {
      h.value(uint32_t(m.bsdf.index()));
      std::visit([&](const auto& b) { std::decay_t<decltype(b)>::parameters(b, [&](const auto& field) { h.value(field); }); },
                 m.bsdf);
    }
    // An alpha mask changes what every ray sees; a normal map bends the specular chains
    // (followSpecular shades with surfaceAt's mapped normal), not the other charts' rays.
    // How they are read counts too (glTF texture mappings and samplers); the defaults hash
    // nothing, so fields traced before mappings existed stay valid.
    auto texture = [&](int index, const TextureMapping& mapping) {
      const Texture& t = scene.textures[size_t(index)];
      h.value(t.image.width);
      h.value(t.image.height);
      h.update(t.image.pixels.data(), t.image.pixels.size() * sizeof(Rgb));
      if (!mapping.isDefault()) {
        h.value(mapping.uvSet);
        h.value(mapping.linear[0]);
        h.value(mapping.linear[1]);
        h.value(mapping.offset);
      }
      if (!t.sampling.isDefault())
        h.value(uint32_t(t.sampling.wrapU) | uint32_t(t.sampling.wrapV) << 8 | uint32_t(t.sampling.nearest) << 16);
    };
    if (m.isMasked()) {
      h.value(m.alphaFactor);
      h.value(m.alphaCutoff);
      if (m.alphaTexture >= 0) texture(m.alphaTexture, m.alphaMapping);
    }
    if (m.normalTexture >= 0 && chartKindOf(m.bsdf, settings) == ChartKind::Specular) {
      h.value(m.normalScale);
      texture(m.normalTexture, m.normalMapping);
    }
  }
  for (const Chart& c : param.charts) {
    h.value(c.material);
    h.value(uint8_t(c.kind));
    h.value(c.origin);
    h.value(c.axisU);
    h.value(c.axisV);
    h.value(c.normal);
    h.value(c.tixelSize);
    h.value(c.resU);
    h.value(c.resV);
    h.value(c.dirRes);
    h.value(c.sides);
    h.value(uint8_t(c.isBack));
    // A curved chart's tixels gather around their own normals (planar charts hash as before).
    if (c.curved) {
      h.value(uint8_t(1));
      h.update(param.gatherNormal.data() + c.firstTixel, c.tixelCount() * sizeof(Vec3));
    }
  }
  h.update(param.gatherPoint.data(), param.gatherPoint.size() * sizeof(Vec3));
  h.value(gatherGridSide(settings.gatherDirections));
  h.value(settings.mirrorDepth);
  h.value(kSpecularRouletteStep);  // chains end differently with another roulette start
  h.value(settings.seed);
  return h.digest();
}

VisibilityShard VisibilityShard::whole(const VisibilityField& field) {
  return of(field, {TixelRange{0, field.tixelCount}});
}

VisibilityShard VisibilityShard::of(VisibilityField field, std::vector<TixelRange> ranges) {
  VisibilityShard shard;
  uint64_t total = 0;
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (ranges[i].end < ranges[i].begin || (i > 0 && ranges[i].begin < ranges[i - 1].end))
      fail("visibility shard: tixel ranges not sorted and disjoint");
    shard.localStart.push_back(total);
    total += ranges[i].size();
  }
  if (total != field.tixelCount) fail("visibility shard: {} tixels in its ranges, {} in its field", total, field.tixelCount);
  shard.field = std::move(field);
  shard.ranges = std::move(ranges);
  return shard;
}

bool VisibilityShard::holdDecoded(uint64_t budget) {
  const uint64_t bytes = field.entryCount() * sizeof(VisibilityEntry);
  if (!decoded.empty()) return true;
  if (field.tixelCount == 0 || bytes > budget || streamed()) return false;
  const uint32_t n = field.directionsPerTixel();
  std::vector<VisibilityEntry> all(field.entryCount());
  parallelForRange(field.tixelCount, 256, [&](uint64_t t0, uint64_t t1) {
    for (uint64_t t = t0; t < t1; ++t) field.decode(t, all.data() + t * n);
  });
  decoded = FieldArray<VisibilityEntry>(std::move(all));
  return true;
}

void VisibilityShard::forEachSpan(uint64_t begin, uint64_t end, uint64_t grain,
                                  const std::function<void(uint64_t, uint64_t, EntryReader&)>& body) const {
  if (begin >= end) return;
  if (!streamed()) {
    parallelForRange(end - begin, grain, [&](uint64_t r0, uint64_t r1) {
      EntryReader reader(*this);
      body(begin + r0, begin + r1, reader);
    });
    return;
  }
  // The parts of [begin, end) in each held range (contiguous field indices), cut at the
  // entry blocks' boundaries: spans[i] = (first tixel, end tixel) of one block each.
  const uint64_t perBlock = field.stream->perBlock();
  std::vector<TixelRange> spans;
  for (const TixelRange& r : ranges) {
    const uint64_t p0 = std::max(begin, r.begin), p1 = std::min(end, r.end);
    for (uint64_t g = p0; g < p1;) {
      const uint64_t t = local(g), blockEnd = (t / perBlock + 1) * perBlock;
      const uint64_t g1 = std::min(p1, g + (blockEnd - t));
      spans.push_back({g, g1});
      g = g1;
    }
  }
  // Consecutive blocks per task (each task's reader buffers allocated once), each read once.
  parallelForRange(spans.size(), 1, [&](uint64_t i0, uint64_t i1) {
    EntryReader reader(*this);
    for (uint64_t i = i0; i < i1; ++i) body(spans[i].begin, spans[i].end, reader);
  });
}

const VisibilityEntry* EntryReader::streamedEntries(uint64_t g, VisibilityEntry*) {
  const VisibilityBlockFile& file = *vis_.field.stream;
  const uint64_t t = vis_.local(g), perBlock = file.perBlock(), b = t / perBlock;
  if (b != block_) {
    file.readEntries(b, frame_, stream_, entries_);
    block_ = b;
  }
  return entries_.data() + (t - b * perBlock) * vis_.field.directionsPerTixel();
}

bool VisibilityShard::holds(uint64_t begin, uint64_t end) const {
  if (begin >= end) return true;
  for (const TixelRange& r : ranges) {
    if (r.end <= begin) continue;
    if (r.begin > begin) return false;
    if (r.end >= end) return true;
    begin = r.end;
  }
  return false;
}

uint64_t visibilityShardHash(uint64_t fieldHash, const std::vector<TixelRange>& ranges, uint64_t tixelCount) {
  if (ranges.size() == 1 && ranges[0] == TixelRange{0, tixelCount}) return fieldHash;
  Fnv1a64 h;
  h.value(fieldHash);
  for (const TixelRange& r : ranges) {
    h.value(r.begin);
    h.value(r.end);
  }
  return h.digest();
}

VisibilityField computeVisibility(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                  const BakeSettings& settings) {
  return computeVisibilityShard(scene, accel, param, settings, {TixelRange{0, param.tixelCount}}).field;
}

namespace {

/// A streamed field's traced blocks (runs of consecutive tixels, in field order), handed over
/// in any order as they finish, joined in field order into the entry blocks of its .plv and
/// written (VisibilityWriter), each run freed once copied: memory holds only the runs that
/// wait for an earlier one (the tracing takes its blocks in order, so a few per thread).
class StreamedFieldSink {
 public:
  StreamedFieldSink(VisibilityWriter& writer, uint64_t tixelCount, uint64_t runCount)
      : writer_(writer), tixelCount_(tixelCount), runCount_(runCount) {}

  /// Run `index` (thread-safe, each once). Throws pl::Error when the .plv cannot be written.
  void add(uint64_t index, EncodedRun run) {
    std::vector<Block> ready;
    {
      const std::lock_guard lock(mutex_);
      pending_.emplace(index, std::move(run));
      for (auto it = pending_.begin(); it != pending_.end() && it->first == next_; it = pending_.erase(it), ++next_) {
        const EncodedRun& r = it->second;
        // The run's tixels, split at the entry blocks' boundaries.
        uint64_t byte = 0;
        for (uint64_t i = 0; i < r.tixelBytes.size();) {
          const uint64_t room = blockTixels(block_.index) - block_.tixelBytes.size();
          const uint64_t take = std::min<uint64_t>(room, r.tixelBytes.size() - i);
          uint64_t bytes = 0;
          for (uint64_t k = i; k < i + take; ++k) bytes += r.tixelBytes[k];
          block_.tixelBytes.insert(block_.tixelBytes.end(), r.tixelBytes.begin() + int64_t(i),
                                   r.tixelBytes.begin() + int64_t(i + take));
          block_.encoded.insert(block_.encoded.end(), r.bytes.begin() + int64_t(byte),
                                r.bytes.begin() + int64_t(byte + bytes));
          i += take;
          byte += bytes;
          if (block_.tixelBytes.size() == blockTixels(block_.index)) {
            const uint64_t nextIndex = block_.index + 1;
            ready.push_back(std::move(block_));
            block_ = Block{nextIndex, {}, {}};
          }
        }
      }
    }
    // Compressed outside the lock; the writer puts the frames in order.
    for (const Block& b : ready) {
      uint64_t contentBytes = 0;
      std::vector<unsigned char> frame = VisibilityWriter::frameBlock(b.tixelBytes, b.encoded, writer_.directionsPerTixel(), &contentBytes);
      writer_.put(b.index, std::move(frame), contentBytes);
    }
  }
  /// Whether every run was added.
  bool complete() const { return next_ == runCount_; }

 private:
  struct Block {
    uint64_t index = 0;
    std::vector<uint32_t> tixelBytes;
    std::vector<unsigned char> encoded;
  };
  uint64_t blockTixels(uint64_t b) const {
    return std::min(writer_.perBlock(), tixelCount_ - std::min(tixelCount_, b * writer_.perBlock()));
  }

  VisibilityWriter& writer_;
  uint64_t tixelCount_, runCount_;
  std::mutex mutex_;
  std::map<uint64_t, EncodedRun> pending_;  ///< runs waiting for an earlier one
  uint64_t next_ = 0;                       ///< the next run to join
  Block block_;                             ///< the entry block being joined
};

}  // namespace

VisibilityShard computeVisibilityShard(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                       const BakeSettings& settings, const std::vector<TixelRange>& ranges,
                                       bool showProgress, VisibilityJournal* journal, const std::string& streamTo) {
  const auto start = std::chrono::steady_clock::now();
  VisibilityField field;
  field.gridSide = gatherGridSide(settings.gatherDirections);
  uint64_t heldTixels = 0;
  for (const TixelRange& r : ranges) heldTixels += r.size();
  field.tixelCount = heldTixels;
  field.hash = visibilityShardHash(visibilityHash(scene, param, settings), ranges, param.tixelCount);
  if (param.tixelCount > VisibilityEntry::kIndexMask)
    fail("{}: {} tixels exceed the visibility field's limit of {}", scene.sourcePath, param.tixelCount,
         VisibilityEntry::kIndexMask - 1);
  const uint32_t n = field.directionsPerTixel();
  const uint32_t fractionBits = visibilityFractionBits(settings);
  std::vector<Vec3> directionTable(size_t(n) * kJitterCount);  // [cell][sub-cell]
  for (uint32_t k = 0; k < n; ++k)
    for (uint32_t j = 0; j < kJitterCount; ++j) directionTable[size_t(k) * kJitterCount + j] = cellDirection(k, j, field.gridSide, settings.seed);

  // Blocks of tixels whose rays are traced as one Embree stream (~4096 rays).
  // Blocks never straddle two ranges: block i is global tixels [t0, t1), stored from `local`.
  const uint64_t tixelsPerBlock = std::max<uint64_t>(1, 4096 / n);
  struct Block {
    uint64_t t0, t1, local;
  };
  std::vector<Block> blockList;
  {
    uint64_t local = 0;
    for (const TixelRange& r : ranges) {
      for (uint64_t t = r.begin; t < r.end; t += tixelsPerBlock) {
        const uint64_t t1 = std::min(r.end, t + tixelsPerBlock);
        blockList.push_back({t, t1, local});
        local += t1 - t;
      }
    }
  }
  const uint64_t blockCount = blockList.size();
  std::vector<BlockExtras> blockExtras(blockCount);
  // Each block's entries are traced into a buffer of its own and encoded (plv_file.h, "Compact
  // entries") as soon as it is done: the field is never held at 8 bytes per entry.
  std::vector<EncodedRun> blockEntries(blockCount);
  // Blocks an interrupted bake already traced (resume.h), restored from its journal.
  std::vector<uint8_t> restored(blockCount, 0);
  if (journal) {
    std::vector<uint64_t> blockTixels(blockCount);
    for (uint64_t b = 0; b < blockCount; ++b) blockTixels[b] = blockList[b].t1 - blockList[b].t0;
    restored = journal->open(field.hash, field.gridSide, blockTixels, param.tixelCount, blockEntries, blockExtras);
  }
  // Streamed: the blocks go to the .plv as they finish (the restored ones first), not into memory.
  std::optional<VisibilityWriter> writer;
  std::optional<StreamedFieldSink> sink;
  if (!streamTo.empty()) {
    writer.emplace(streamTo, field.gridSide, field.hash, heldTixels);
    sink.emplace(*writer, heldTixels, blockCount);
    for (uint64_t b = 0; b < blockCount; ++b)
      if (restored[b]) sink->add(b, std::move(blockEntries[b]));
    std::vector<EncodedRun>().swap(blockEntries);
  }
  // The blocks are taken in order (a task takes the next untraced block, whichever index it
  // was given), so that a streamed field's blocks finish nearly in order.
  std::atomic<uint64_t> nextBlock{0};
  std::atomic<uint64_t> rayCount{0};
  std::optional<Progress> progress;
  if (showProgress) progress.emplace("visibility", heldTixels);

  struct PathState {
    uint64_t entry;
    Rgb throughput;
    bool viaMirror;
  };
  parallelFor(blockCount, [&](uint64_t) {
    const uint64_t block = nextBlock++;
    const uint64_t t0 = blockList[block].t0, t1 = blockList[block].t1, localBase = blockList[block].local;
    if (restored[block]) {
      if (progress) progress->advance(t1 - t0);
      return;
    }
    std::vector<Ray> rays, nextRays;
    std::vector<RayHit> hits;
    std::vector<PathState> states, nextStates;
    std::vector<uint8_t> jitters;
    std::vector<VisibilityEntry> entries((t1 - t0) * n);  // of this block: entry k of tixel g at (g − t0)·n + k
    rays.reserve((t1 - t0) * n);
    states.reserve((t1 - t0) * n);
    auto& extras = blockExtras[block];
    for (uint64_t g = t0; g < t1; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      if (c.kind == ChartKind::Specular) {
        // Mirror tixels store nothing and gather nothing: their entries stay "escaped" and
        // are never read. No rays are spent on them.
        continue;
      }
      // Every gather direction is in the upper hemisphere, so all rays of a tixel share one
      // origin, offset off the surface along the normal. The frame is orthonormal and the
      // local directions are unit, so the world directions need no renormalisation.
      const TixelFrame frame = tixelFrame(param, c, g);
      const Vec3 origin = offsetRayOrigin(param.gatherPoint[g], frame.n, frame.n);
      gatherSubCells(g, field.gridSide, settings.seed, jitters);
      for (uint32_t k = 0; k < n; ++k) {
        Ray ray;
        ray.origin = origin;
        ray.direction = frame.toWorld(directionTable[size_t(k) * kJitterCount + jitters[k]]);
        rays.push_back(ray);
        states.push_back({(localBase + g - t0) * n + k, Rgb(1.0f), false});
      }
    }
    for (uint32_t depth = 0; !rays.empty(); ++depth) {
      hits.resize(rays.size());
      accel.intersectIncoherent(rays, hits);
      rayCount += rays.size();
      nextRays.clear();
      nextStates.clear();
      for (size_t r = 0; r < rays.size(); ++r) {
        const Ray& ray = rays[r];
        const PathState& state = states[r];
        VisibilityEntry& entry = entries[state.entry - localBase * n];
        const RayHit& hit = hits[r];
        if (!hit.hit()) {
          entry.target = VisibilityEntry::kEscape;
          if (state.viaMirror) {
            entry.target |= VisibilityEntry::kHasExtra;
            extras.push_back({state.entry, VisibilityExtra{state.throughput, octahedralEncode(ray.direction), 1}});
          }
          continue;
        }
        // The side facing the ray (a two-sided chart's back record when it arrives from
        // behind); `back` is left only for one-sided charts seen from behind.
        const Mesh& hitMesh = scene.meshes[hit.mesh];
        const uint32_t chartIndex =
            facingChart(param.charts.data(), param.triangleChart[hit.mesh][hit.triangle], -ray.direction, hitMesh, hit.triangle);
        const Chart& c = param.charts[chartIndex];
        const Vec3 pos = ray.origin + hit.t * ray.direction;
        const bool back = glm::dot(ray.direction, chartNormalAt(c, hitMesh, hit.triangle)) > 0.0f;
        if (c.kind == ChartKind::Specular) {
          // A mirror or glass: the step the renderers take too (followSpecular). Its own
          // emission is not gathered (as before glass: mirrors were never lamps here).
          Rgb emitted, weight;
          Ray next;
          if (!followSpecular(scene, ray, hit, depth, settings.mirrorDepth, emitted, next, weight)) {
            // Chain longer than mirrorDepth, ended by roulette or a direction below the surface: absorbed.
            entry.target = VisibilityEntry::kEscape | VisibilityEntry::kHasExtra;
            extras.push_back({state.entry, VisibilityExtra{Rgb(0.0f), Vec2(0.0f), 1}});
            continue;
          }
          nextRays.push_back(next);
          nextStates.push_back({state.entry, state.throughput * weight, true});
          continue;
        }
        const Vec2 grid = tixelGridCoordinates(c, pos);
        const LinearTap tu = linearTap(grid.x, c.resU), tv = linearTap(grid.y, c.resV);
        const uint64_t base = c.firstTixel + uint64_t(tv.i0) * c.resU + tu.i0;
        entry.target = uint32_t(base) | (back ? VisibilityEntry::kBackSide : 0u);
        entry.fu = uint16_t(tu.f * 65535.0f + 0.5f);  // f ∈ [0, 1): rounds to 0 … 65535
        entry.fv = uint16_t(tv.f * 65535.0f + 0.5f);
        if (state.viaMirror || c.kind == ChartKind::Glossy) {
          entry.target |= VisibilityEntry::kHasExtra;
          // In the frame of the glossy map at the hit (a curved chart's, around its
          // interpolated normal there: the lookup every renderer makes, lookup.h).
          const TixelFrame frame = tixelFrameAround(c, chartShadingNormalAt(c, hitMesh, hit.triangle, hit.barycentrics));
          const Vec2 st = directionToParaboloid(frame.toLocal(-ray.direction));
          extras.push_back({state.entry, VisibilityExtra{state.throughput * insideGlassAttenuation(scene, c, hit.t), st,
                                                         state.viaMirror ? 1u : 0u}});
        }
      }
      std::swap(rays, nextRays);
      std::swap(states, nextStates);
    }
    std::sort(extras.begin(), extras.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    EncodedRun run;
    run.bytes.reserve((t1 - t0) * maxEncodedTixelBytes(n));
    for (uint64_t g = t0; g < t1; ++g) run.add(entries.data() + (g - t0) * n, n, fractionBits);
    run.bytes.shrink_to_fit();
    if (journal) journal->append(block, run, extras);
    if (sink) sink->add(block, std::move(run));
    else blockEntries[block] = std::move(run);
    if (progress) progress->advance(t1 - t0);
  });
  if (progress) progress->finish();

  // Per-tixel offsets of the extra records, then the records in entry order.
  std::vector<uint64_t> extraOffset(heldTixels + 1, 0);
  for (const auto& list : blockExtras)
    for (const auto& [entry, extra] : list) ++extraOffset[entry / n + 1];
  for (uint64_t g = 0; g < heldTixels; ++g) extraOffset[g + 1] += extraOffset[g];
  std::vector<VisibilityExtra> extras;
  extras.reserve(extraOffset.back());
  adviseHugePages(extras.data(), extras.capacity() * sizeof(VisibilityExtra));
  for (auto& list : blockExtras) {
    for (const auto& item : list) extras.push_back(item.second);
    std::vector<std::pair<uint64_t, VisibilityExtra>>().swap(list);
  }
  if (writer) {
    if (!sink->complete()) fail("{}: the visibility field was not traced whole", streamTo);
    VisibilityFrames frames = writer->finish(extraOffset, extras);
    field.stream = std::make_shared<const VisibilityBlockFile>(streamTo, std::move(frames));
  } else {
    field.assembleEntries(blockEntries);
  }
  field.extraOffset = FieldArray<uint64_t>(std::move(extraOffset));
  field.extras = FieldArray<VisibilityExtra>(std::move(extras));
  field.rays = rayCount.load();
  field.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return VisibilityShard::of(std::move(field), ranges);
}

VisibilityBytesPerTixel estimateVisibilityBytesPerTixel(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                                        const BakeSettings& settings, const std::vector<TixelRange>& ranges) {
  uint64_t held = 0;
  for (const TixelRange& r : ranges) held += r.size();
  if (held == 0) return {};
  const uint64_t n = uint64_t(gatherGridSide(settings.gatherDirections)) * gatherGridSide(settings.gatherDirections);
  const uint64_t count = std::clamp<uint64_t>(kVisibilitySampleRays / n, 1, held);
  // The middle tixel of each of `count` equal runs of the held tixels (in their order).
  std::vector<TixelRange> sample;
  size_t r = 0;
  uint64_t before = 0;  // held tixels in ranges[0, r)
  for (uint64_t i = 0; i < count; ++i) {
    const uint64_t local = (2 * i + 1) * held / (2 * count);
    while (local >= before + ranges[r].size()) before += ranges[r++].size();
    const uint64_t g = ranges[r].begin + (local - before);
    if (sample.empty() || sample.back().end <= g) sample.push_back({g, g + 1});
  }
  const VisibilityShard traced = computeVisibilityShard(scene, accel, param, settings, sample, false);
  const VisibilityField& f = traced.field;
  const double tixels = double(f.tixelCount);
  return {double(f.bytes()) / tixels,
          double(f.extraOffset.size() * sizeof(uint64_t) + f.extras.size() * sizeof(VisibilityExtra)) / tixels};
}

}  // namespace pl
