// The visibility field: tracing, hashing and its .plv file.
//
// .plv layout (version 3; little-endian; written by writeVisibility, validated by readVisibility):
//   header, 56 bytes:
//   magic        8 bytes  "PLVIS\0\r\n"
//   version      u32      kPlvVersion
//   gridSide     u32      m (N = m² gather directions per tixel)
//   hash         u64      visibilityHash of the bake that traced it
//   tixelCount   u64
//   entryCount   u64      = tixelCount · N
//   extraCount   u64
//   payloadHash  u64      XXH64 (seed 0, as the .plf checksums) of every byte after the header
//   payload:
//   tixelsPerBlock u64    tixels per entry block (≈ 512 KiB of entries; the last block may
//                         hold fewer): B = ⌈tixelCount / tixelsPerBlock⌉ blocks
//   frames       B zstd frames of entry blocks, in tixel order, then one zstd frame of
//                extraOffset (u64 × (tixelCount + 1)) followed by the extras (24 bytes each)
//   frameSizes   u64 × (B + 1): the stored bytes of each frame, in order
// An entry block of k entries, before zstd (encodeEntryBlock): the k targets (u32), then the
// k fu (u16), then the k fv (u16). Decoding restores the 8-byte entries of visibility.h exactly,
// so a reused field gives the same light field bit for bit. Version 2 was the raw entries
// (8 bytes each, memory-mapped): a version-2 file is traced again, like a stale one.
#include "bake/visibility.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "accel/accel.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/memory.h"
#include "plf/codec_backends.h"
#include "lightfield/lookup.h"

namespace pl {

namespace {

constexpr char kPlvMagic[8] = {'P', 'L', 'V', 'I', 'S', '\0', '\r', '\n'};
constexpr uint32_t kPlvVersion = 3;  // 2: multi-jittered gather directions; 3: compressed blocks
constexpr size_t kPlvHeaderSize = 8 + 4 + 4 + 8 * 5;

// FNV-1a, 64 bit: a change detector over bytes (not a cryptographic hash).
struct Fnv1a {
  uint64_t state = 0xcbf29ce484222325ULL;
  void bytes(const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) {
      state ^= p[i];
      state *= 0x100000001b3ULL;
    }
  }
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof(T));
  }
};

}  // namespace

namespace {

// Asks Linux for transparent huge pages (2 MiB) on a large, not yet touched allocation: the
// tens to hundreds of MB of a visibility field then take a few hundred page faults to fill
// instead of tens of thousands. A hint only (THP may be off); a no-op elsewhere.
void adviseHugePages(void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHugePage = uintptr_t(1) << 21;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHugePage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

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
constexpr uint32_t kMaxGatherGridSide = 256;  // gatherDirections ≤ 65 536

/// The random permutation of line `line` (a column when row == false) of a tixel's cells:
/// order[rank] = index of the cell (along the line) with that rank.
void linePermutation(uint64_t tixelSalt, uint32_t line, bool row, uint32_t gridSide, uint8_t* order) {
  for (uint32_t i = 0; i < gridSide; ++i) order[i] = uint8_t(i);
  const uint64_t lineSalt = tixelSalt ^ ((uint64_t(line) << 1 | uint64_t(row)) * 0x9e3779b97f4a7c15ULL);
  for (uint32_t i = gridSide; i > 1; --i) {
    // 32 random bits scaled to [0, i) (Lemire's multiply-shift; the bias is < i/2^32).
    const uint32_t j = uint32_t((uint64_t(uint32_t(mix64(lineSalt + i))) * i) >> 32);
    std::swap(order[i - 1], order[j]);
  }
}

uint64_t tixelSalt(uint64_t tixel, uint64_t seed) { return hashCombine(tixel, seed ^ 0x5649534942494c59ULL); }

}  // namespace

void gatherSubCells(uint64_t tixel, uint32_t gridSide, uint64_t seed, std::vector<uint8_t>& out) {
  out.assign(size_t(gridSide) * gridSide, 0);
  const uint64_t salt = tixelSalt(tixel, seed);
  uint8_t order[kMaxGatherGridSide];
  for (uint32_t line = 0; line < gridSide; ++line) {
    linePermutation(salt, line, false, gridSide, order);  // column `line`: cells line + i·G
    for (uint32_t rank = 0; rank < gridSide; ++rank) out[line + order[rank] * gridSide] += uint8_t(rank % kJitterSide);
    linePermutation(salt, line, true, gridSide, order);  // row `line`: cells i + line·G
    for (uint32_t rank = 0; rank < gridSide; ++rank)
      out[order[rank] + line * gridSide] += uint8_t(kJitterSide * (rank % kJitterSide));
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

uint64_t visibilityHash(const Scene& scene, const Parameterisation& param, const BakeSettings& settings) {
  Fnv1a h;
  h.value(kPlvVersion);
  h.value(uint64_t(scene.meshes.size()));
  for (const Mesh& mesh : scene.meshes) {
    h.value(uint64_t(mesh.triangles.size()));
    for (const UVec3& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) h.value(mesh.positions[t[k]]);
    }
    h.bytes(mesh.materials.data(), mesh.materials.size() * sizeof(uint32_t));
  }
  for (const Material& m : scene.materials) {
    h.value(uint8_t(chartKindOf(m.bsdf)));
    // Specular models bend and weight the chains folded into the field, and transmitting
    // ones attenuate the gather rays inside them: all their parameters (the model's
    // parameters() hook, bsdf.h). Other models' parameters (a roughness, an albedo) change
    // only the propagation, so a field traced before such an edit is reused.
    if (chartKindOf(m.bsdf) == ChartKind::Specular || hasTransmission(m.bsdf)) {
      h.value(uint32_t(m.bsdf.index()));
      std::visit([&](const auto& b) { std::decay_t<decltype(b)>::parameters(b, [&](const auto& field) { h.value(field); }); },
                 m.bsdf);
    }
    // An alpha mask changes what every ray sees; a normal map bends the specular chains
    // (followSpecular shades with surfaceAt's mapped normal), not the other charts' rays.
    auto texture = [&](int index) {
      const Image& image = scene.textures[size_t(index)].image;
      h.value(image.width);
      h.value(image.height);
      h.bytes(image.pixels.data(), image.pixels.size() * sizeof(Rgb));
    };
    if (m.isMasked()) {
      h.value(m.alphaFactor);
      h.value(m.alphaCutoff);
      if (m.alphaTexture >= 0) texture(m.alphaTexture);
    }
    if (m.normalTexture >= 0 && chartKindOf(m.bsdf) == ChartKind::Specular) {
      h.value(m.normalScale);
      texture(m.normalTexture);
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
      h.bytes(param.gatherNormal.data() + c.firstTixel, c.tixelCount() * sizeof(Vec3));
    }
  }
  h.bytes(param.gatherPoint.data(), param.gatherPoint.size() * sizeof(Vec3));
  h.value(gatherGridSide(settings.gatherDirections));
  h.value(settings.mirrorDepth);
  h.value(kSpecularRouletteStep);  // chains end differently with another roulette start
  h.value(settings.seed);
  return h.state;
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
  Fnv1a h;
  h.value(fieldHash);
  for (const TixelRange& r : ranges) {
    h.value(r.begin);
    h.value(r.end);
  }
  return h.state;
}

VisibilityField computeVisibility(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                  const BakeSettings& settings) {
  return computeVisibilityShard(scene, accel, param, settings, {TixelRange{0, param.tixelCount}}).field;
}

VisibilityShard computeVisibilityShard(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                       const BakeSettings& settings, const std::vector<TixelRange>& ranges) {
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
  std::vector<VisibilityEntry> entries;
  entries.reserve(heldTixels * n);
  adviseHugePages(entries.data(), heldTixels * n * sizeof(VisibilityEntry));
  entries.resize(heldTixels * n);
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
  std::vector<std::vector<std::pair<uint64_t, VisibilityExtra>>> blockExtras(blockCount);
  std::atomic<uint64_t> rayCount{0};
  Progress progress("visibility", heldTixels);

  struct PathState {
    uint64_t entry;
    Rgb throughput;
    bool viaMirror;
  };
  parallelFor(blockCount, [&](uint64_t block) {
    const uint64_t t0 = blockList[block].t0, t1 = blockList[block].t1, localBase = blockList[block].local;
    std::vector<Ray> rays, nextRays;
    std::vector<RayHit> hits;
    std::vector<PathState> states, nextStates;
    std::vector<uint8_t> jitters;
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
        VisibilityEntry& entry = entries[state.entry];
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
    progress.advance(t1 - t0);
  });
  progress.finish();

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
  field.entries = FieldArray<VisibilityEntry>(std::move(entries));
  field.extraOffset = FieldArray<uint64_t>(std::move(extraOffset));
  field.extras = FieldArray<VisibilityExtra>(std::move(extras));
  field.rays = rayCount.load();
  field.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return VisibilityShard::of(std::move(field), ranges);
}

namespace {

/// Entry blocks of the .plv: as many whole tixels as make about kBlockEntryBytes of entries.
constexpr uint64_t kBlockEntryBytes = uint64_t(1) << 19;
/// A reader refuses blocks larger than this (a writer never makes them): it bounds the
/// scratch buffer and what one frame may claim.
constexpr uint64_t kMaxBlockEntryBytes = uint64_t(1) << 24;
/// zstd level of the .plv frames. On Sponza's default field level 3 saves 1.5 % of the bytes
/// (3.41 instead of 3.46 per entry) for about 1.4× the time, level 9 5 % for 3×.
constexpr int kPlvZstdLevel = 1;
/// Blocks compressed in parallel between two writes (bounds the writer's buffers).
constexpr uint64_t kWriteBatchBlocks = 16;

uint64_t tixelsPerBlock(uint32_t directionsPerTixel) {
  return std::max<uint64_t>(1, kBlockEntryBytes / (uint64_t(directionsPerTixel) * sizeof(VisibilityEntry)));
}

/// The bytes of an entry block before zstd (see the layout at the top): all targets, then all
/// fu, then all fv. Measured on Sponza's default field (43.5 M entries, zstd level 1): 3.89
/// bytes per entry interleaved, 3.46 split so, 3.58 with the targets also delta-coded against
/// the previous entry's (neighbouring directions mostly see the same chart, but the index
/// jumps between charts cost more than the deltas save).
void encodeEntryBlock(const VisibilityEntry* entries, uint64_t count, unsigned char* out) {
  for (uint64_t i = 0; i < count; ++i) {
    std::memcpy(out + 4 * i, &entries[i].target, 4);
    std::memcpy(out + 4 * count + 2 * i, &entries[i].fu, 2);
    std::memcpy(out + 6 * count + 2 * i, &entries[i].fv, 2);
  }
}

void decodeEntryBlock(const unsigned char* in, uint64_t count, VisibilityEntry* entries) {
  for (uint64_t i = 0; i < count; ++i) {
    std::memcpy(&entries[i].target, in + 4 * i, 4);
    std::memcpy(&entries[i].fu, in + 4 * count + 2 * i, 2);
    std::memcpy(&entries[i].fv, in + 6 * count + 2 * i, 2);
  }
}

}  // namespace

uint64_t visibilityWriteBufferBytes(uint32_t gridSide) {
  // Per block of a batch: its compressed frame (at most the raw size plus zstd's small
  // bound, counted as the raw size twice) while a worker also holds the raw transformed copy.
  const uint64_t blockBytes = tixelsPerBlock(gridSide * gridSide) * gridSide * gridSide * sizeof(VisibilityEntry);
  return kWriteBatchBlocks * 2 * blockBytes;
}

void writeVisibility(const std::string& path, const VisibilityField& field) {
  const uint64_t n = field.directionsPerTixel();
  const uint64_t perBlock = tixelsPerBlock(uint32_t(n));
  const uint64_t blocks = (field.tixelCount + perBlock - 1) / perBlock;
  const uint64_t entryCount = field.entries.size(), extraCount = field.extras.size();

  writeFileAtomically(path, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot create the temporary file {}", temp);
    Xxh64Stream payloadHash;
    auto put = [&](const void* data, size_t size) { out.write(static_cast<const char*>(data), std::streamsize(size)); };
    auto putPayload = [&](const void* data, size_t size) {
      put(data, size);
      payloadHash.update(data, size);
    };
    const uint64_t placeholder = 0;
    put(kPlvMagic, 8);
    put(&kPlvVersion, 4);
    put(&field.gridSide, 4);
    put(&field.hash, 8);
    put(&field.tixelCount, 8);
    put(&entryCount, 8);
    put(&extraCount, 8);
    put(&placeholder, 8);  // the payload hash, written last
    putPayload(&perBlock, 8);

    // Entry blocks compressed a batch at a time in parallel, written in order: memory stays
    // bounded by one batch of frames whatever the field's size.
    std::vector<uint64_t> frameSizes;
    frameSizes.reserve(blocks + 1);
    const uint64_t batch = kWriteBatchBlocks;
    std::vector<std::vector<unsigned char>> frames(batch);
    Progress progress("visibility: writing", blocks);
    for (uint64_t b0 = 0; b0 < blocks; b0 += batch) {
      const uint64_t b1 = std::min(blocks, b0 + batch);
      parallelFor(b1 - b0, [&](uint64_t i) {
        const uint64_t t0 = (b0 + i) * perBlock, t1 = std::min(field.tixelCount, t0 + perBlock);
        std::vector<unsigned char> raw((t1 - t0) * n * sizeof(VisibilityEntry));
        encodeEntryBlock(field.entries.data() + t0 * n, (t1 - t0) * n, raw.data());
        frames[i] = detail::zstdCompress(raw, kPlvZstdLevel);
      });
      for (uint64_t i = 0; i < b1 - b0; ++i) {
        putPayload(frames[i].data(), frames[i].size());
        frameSizes.push_back(frames[i].size());
      }
      progress.advance(b1 - b0);
    }
    // The extra records' frame: offsets, then records.
    std::vector<unsigned char> tail(field.extraOffset.size() * sizeof(uint64_t) + extraCount * sizeof(VisibilityExtra));
    if (!field.extraOffset.empty()) std::memcpy(tail.data(), field.extraOffset.data(), field.extraOffset.size() * sizeof(uint64_t));
    if (extraCount > 0)
      std::memcpy(tail.data() + field.extraOffset.size() * sizeof(uint64_t), field.extras.data(),
                  extraCount * sizeof(VisibilityExtra));
    const std::vector<unsigned char> tailFrame = detail::zstdCompress(tail, kPlvZstdLevel);
    putPayload(tailFrame.data(), tailFrame.size());
    frameSizes.push_back(tailFrame.size());
    putPayload(frameSizes.data(), frameSizes.size() * sizeof(uint64_t));
    const uint64_t digest = payloadHash.digest();
    out.seekp(kPlvHeaderSize - 8);
    put(&digest, 8);
    out.flush();
    if (!out) fail("write failed (disk full?)");
  });
}

bool readVisibility(const std::string& path, uint64_t expectedHash, VisibilityField& field, std::string* why,
                    uint64_t targetTixels) {
  auto reason = [&](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return reason(fmt::format("{} does not exist", path));
  const auto file = std::make_shared<const MappedFile>(path);
  const std::span<const unsigned char> bytes = file->bytes();
  const uint64_t fileSize = bytes.size();
  if (fileSize < kPlvHeaderSize) fail("{}: truncated visibility field ({} bytes, header needs {})", path, fileSize, kPlvHeaderSize);
  size_t at = 0;
  auto get = [&](void* data, size_t size) {
    std::memcpy(data, bytes.data() + at, size);
    at += size;
  };
  char magic[8];
  uint32_t version = 0, gridSide = 0;
  uint64_t hash = 0, tixelCount = 0, entryCount = 0, extraCount = 0, payloadHash = 0;
  get(magic, 8);
  if (std::memcmp(magic, kPlvMagic, 8) != 0) fail("{}: not a plenoptic visibility field (bad magic)", path);
  get(&version, 4);
  if (version != kPlvVersion) {
    // An older field is not an error: it is traced again, as a stale one is.
    if (version < kPlvVersion)
      return reason(fmt::format("{} has the older format version {} (this program writes version {})", path, version,
                                kPlvVersion));
    fail("{}: visibility field version {} (this program reads version {})", path, version, kPlvVersion);
  }
  get(&gridSide, 4);
  get(&hash, 8);
  get(&tixelCount, 8);
  get(&entryCount, 8);
  get(&extraCount, 8);
  get(&payloadHash, 8);
  if (hash != expectedHash)
    return reason(fmt::format("{} was traced for different geometry, parameterisation or settings (hash {:016x}, expected {:016x})",
                              path, hash, expectedHash));
  if (gridSide == 0 || gridSide > kMaxGatherGridSide || tixelCount > VisibilityEntry::kIndexMask ||
      entryCount != tixelCount * uint64_t(gridSide) * gridSide || extraCount > entryCount)
    fail("{}: inconsistent counts in the header (grid {}, {} tixels, {} entries, {} extra records)", path, gridSide,
         tixelCount, entryCount, extraCount);
  const uint64_t n = uint64_t(gridSide) * gridSide;

  // The payload: its checksum first (a damaged file is "corrupt", whatever its damage happens
  // to break), then the frame table at its end, checked against the bytes present.
  const std::span<const unsigned char> payload = bytes.subspan(kPlvHeaderSize);
  if (xxh64(payload.data(), payload.size()) != payloadHash)
    fail("{}: corrupt or truncated visibility field (payload checksum mismatch)", path);
  if (payload.size() < 8) fail("{}: truncated visibility field (no block size)", path);
  uint64_t perBlock;
  std::memcpy(&perBlock, payload.data(), 8);
  if (perBlock == 0 || perBlock > kMaxBlockEntryBytes / (n * sizeof(VisibilityEntry)))
    fail("{}: corrupt visibility field: {} tixels per block of {} directions each", path, perBlock, n);
  const uint64_t blocks = (tixelCount + perBlock - 1) / perBlock;
  const uint64_t tableBytes = (blocks + 1) * sizeof(uint64_t);
  if (payload.size() < 8 + tableBytes)
    fail("{}: truncated visibility field: {} bytes cannot hold the table of {} frames", path, fileSize, blocks + 1);
  std::vector<uint64_t> frameSizes(blocks + 1);
  std::memcpy(frameSizes.data(), payload.data() + payload.size() - tableBytes, tableBytes);
  const uint64_t framesBytes = payload.size() - 8 - tableBytes;
  uint64_t sum = 0;
  for (uint64_t size : frameSizes) {
    if (size > framesBytes - sum) fail("{}: corrupt visibility field: the frame sizes exceed the {} bytes present", path, framesBytes);
    sum += size;
  }
  if (sum != framesBytes)
    fail("{}: corrupt visibility field: {} bytes of frames present, the table describes {}", path, framesBytes, sum);

  // Every frame must declare the size its place in the layout gives it before anything is
  // allocated for the decoded field; then the field must fit in memory (the same bytes as the
  // bake's estimate for this parameterisation): a forged header is refused, not obeyed.
  const uint64_t decodedBytes = entryCount * sizeof(VisibilityEntry) + (tixelCount + 1) * sizeof(uint64_t) +
                                extraCount * sizeof(VisibilityExtra);
  {
    const unsigned char* frame = payload.data() + 8;
    for (uint64_t b = 0; b <= blocks; ++b) {
      const uint64_t tixels = b < blocks ? std::min(tixelCount - b * perBlock, perBlock) : 0;
      const uint64_t expected = b < blocks ? tixels * n * sizeof(VisibilityEntry)
                                           : (tixelCount + 1) * sizeof(uint64_t) + extraCount * sizeof(VisibilityExtra);
      detail::zstdCheckFrame({frame, frameSizes[b]}, expected, fmt::format("{}: visibility frame {}", path, b));
      frame += frameSizes[b];
    }
  }
  requireMemory(decodedBytes, fmt::format("{}: the visibility field", path), "bake at a coarser --preset");

  std::vector<VisibilityEntry> entries;
  entries.reserve(entryCount);
  adviseHugePages(entries.data(), entryCount * sizeof(VisibilityEntry));
  entries.resize(entryCount);
  std::vector<uint64_t> frameOffset(blocks + 2, 8);  // of each frame in the payload
  for (uint64_t b = 0; b <= blocks; ++b) frameOffset[b + 1] = frameOffset[b] + frameSizes[b];
  std::vector<uint64_t> flaggedPerTixel(tixelCount);
  // Blocks decode independently, in parallel (≈ 220 MB/s of entries per core at zstd level 1).
  parallelFor(blocks, [&](uint64_t b) {
    const uint64_t t0 = b * perBlock, t1 = std::min(tixelCount, t0 + perBlock);
    std::vector<unsigned char> raw((t1 - t0) * n * sizeof(VisibilityEntry));
    detail::zstdDecompressInto(payload.subspan(frameOffset[b], frameSizes[b]), raw,
                               fmt::format("{}: visibility block {}", path, b));
    decodeEntryBlock(raw.data(), (t1 - t0) * n, entries.data() + t0 * n);
    // The structural checks that let propagation index without bounds checks.
    for (uint64_t g = t0; g < t1; ++g) {
      uint64_t flagged = 0;
      for (uint64_t k = 0; k < n; ++k) {
        const VisibilityEntry e = entries[g * n + k];
        if (!e.escaped() && e.tixel() >= (targetTixels > 0 ? targetTixels : tixelCount))
          fail("{}: an entry of tixel {} points outside the field", path, g);
        flagged += e.hasExtra() ? 1 : 0;
      }
      flaggedPerTixel[g] = flagged;
    }
  });
  std::vector<uint64_t> extraOffset(tixelCount + 1);
  std::vector<VisibilityExtra> extras(extraCount);
  std::vector<unsigned char> raw(decodedBytes - entryCount * sizeof(VisibilityEntry));
  detail::zstdDecompressInto(payload.subspan(frameOffset[blocks], frameSizes[blocks]), raw,
                             fmt::format("{}: visibility extra records", path));
  std::memcpy(extraOffset.data(), raw.data(), extraOffset.size() * sizeof(uint64_t));
  if (extraCount > 0)
    std::memcpy(extras.data(), raw.data() + extraOffset.size() * sizeof(uint64_t), extraCount * sizeof(VisibilityExtra));
  raw = {};
  if (extraOffset[0] != 0 || extraOffset[tixelCount] != extraCount) fail("{}: corrupt extra-record offsets", path);
  for (uint64_t g = 0; g < tixelCount; ++g)
    if (extraOffset[g + 1] < extraOffset[g] || extraOffset[g + 1] - extraOffset[g] != flaggedPerTixel[g])
      fail("{}: corrupt extra-record offsets at tixel {}", path, g);
  // The records' contents, as computeVisibility writes them: a throughput is a product of
  // mirror reflectances (each channel in [0, 1]); st is a paraboloid coordinate (unit disk) or
  // an octahedral one ([−1, 1]²), so both components lie in [−1, 1] (kStSlack: float rounding
  // of x / r and x / (1 + z)); viaMirror is 0 or 1. Anything else — NaN, 1e9 — would flow
  // unchecked into every propagated value.
  constexpr float kStSlack = 1e-4f;
  for (uint64_t i = 0; i < extraCount; ++i) {
    const VisibilityExtra& x = extras[i];
    for (int c = 0; c < 3; ++c)
      if (!(x.throughput[c] >= 0.0f && x.throughput[c] <= 1.0f))
        fail("{}: extra record {} has throughput {} outside [0, 1]", path, i, x.throughput[c]);
    for (int c = 0; c < 2; ++c)
      if (!(std::abs(x.st[c]) <= 1.0f + kStSlack))
        fail("{}: extra record {} has direction coordinate {} outside [-1, 1]", path, i, x.st[c]);
    if (x.viaMirror > 1) fail("{}: extra record {} has a mirror flag of {} (0 or 1)", path, i, x.viaMirror);
  }

  VisibilityField f;
  f.gridSide = gridSide;
  f.tixelCount = tixelCount;
  f.hash = hash;
  f.entries = FieldArray<VisibilityEntry>(std::move(entries));
  f.extraOffset = FieldArray<uint64_t>(std::move(extraOffset));
  f.extras = FieldArray<VisibilityExtra>(std::move(extras));
  field = std::move(f);
  return true;
}

}  // namespace pl
