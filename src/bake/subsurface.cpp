// The light field's subsurface transport operator (see subsurface.h).
#include "bake/subsurface.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "accel/accel.h"
#include "bake/parameterisation.h"
#include "bake/shard.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sampler.h"
#include "core/sampling.h"
#include "core/timing.h"
#include "distributed/communicator.h"
#include "scene/scene.h"
#include "trace/subsurface_walk.h"

namespace pl {

uint64_t SubsurfaceOperator::bytes() const {
  return rowTixel.size() * sizeof(uint64_t) + rowStart.size() * sizeof(uint64_t) + entryTixel.size() * sizeof(uint64_t) +
         weight.size() * sizeof(Rgb) + area.size() * sizeof(float);
}

namespace {

/// One walk's contribution before merging: exit tixel j, entry tixel i, w·a (scene units²).
struct Contribution {
  uint64_t exit, entry;
  Rgb power;
};

/// The tixel of subsurface chart c under world point p (the projection along the chart's
/// normal; clamped to the grid, for points of the polygon at its very edge).
uint64_t tixelUnder(const Chart& c, const Vec3& p) {
  const Vec3 d = p - c.origin;
  const float u = glm::dot(d, c.axisU) / c.tixelSize, v = glm::dot(d, c.axisV) / c.tixelSize;
  const uint32_t i = uint32_t(std::clamp(int64_t(std::floor(u)), int64_t(0), int64_t(c.resU) - 1));
  const uint32_t j = uint32_t(std::clamp(int64_t(std::floor(v)), int64_t(0), int64_t(c.resV) - 1));
  return c.firstTixel + uint64_t(j) * c.resU + i;
}

/// The walks of one triangle of area `area` on a chart of tixel area `tixelArea`: about
/// walksPerTixel per tixel area, at least one.
uint32_t triangleWalks(float area, uint32_t walksPerTixel, float tixelArea) {
  return std::max(1u, uint32_t(std::ceil(float(walksPerTixel) * area / tixelArea)));
}

float triangleArea(const Mesh& m, uint32_t triangle) {
  const UVec3& t = m.triangles[triangle];
  return 0.5f * glm::length(glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]));
}

/// What the walks entering one chart record gave (chartWalks).
struct ChartWalks {
  std::vector<Contribution> contributions;  ///< merged per (entry, exit) and truncated
  std::vector<double> area;                 ///< per tixel of the chart: the surface area its walks stand for
  uint64_t walks = 0, exited = 0, rays = 0, dropped = 0;
};

/// The walks entering chart record `ci` (its front record: the outside of the closed mesh),
/// merged per (entry, exit) pair and truncated per entry tixel (kSubsurfaceDroppedFraction),
/// with the area each walk stands for added to its entry tixel's (indexed from c.firstTixel):
/// the surface area under each tixel, which on a curved chart is larger than the tixel's
/// square covers in the chart's plane. Depends only on the chart and the seed.
ChartWalks chartWalks(const Scene& scene, const Accel& accel, const Parameterisation& param, uint32_t ci,
                      uint32_t walksPerTixel, uint64_t seed) {
  const Chart& c = param.charts[ci];
  ChartWalks result;
  result.area.assign(c.tixelCount(), 0.0);
  std::vector<Contribution> out;
  const float tixelArea = c.tixelSize * c.tixelSize;
  for (const auto& [mesh, triangle] : param.chartTriangles[ci]) {
    const Mesh& m = scene.meshes[mesh];
    const float area = triangleArea(m, triangle);
    if (!(area > 0.0f)) continue;
    const uint32_t count = triangleWalks(area, walksPerTixel, tixelArea);
    const float share = area / float(count);  // the area each walk stands for
    const uint64_t key = (uint64_t(mesh) << 32) | triangle;
    // Entry points: a Hammersley set over the triangle (Heitz's low-distortion map), shifted
    // by a random offset per triangle — stratified, so each tixel gets close to its share of
    // walks (independent points would add a binomial count noise of 1/√N to every tixel).
    Pcg32 shiftRng = Pcg32::forKey(key, uint64_t(1) << 40, seed ^ 0x5353535353ULL);
    const float shiftU = shiftRng.uniform(), shiftV = shiftRng.uniform();
    auto wrap = [](float x) { return x >= 1.0f ? x - 1.0f : x; };
    for (uint32_t k = 0; k < count; ++k) {
      const Vec2 u(wrap((float(k) + 0.5f) / float(count) + shiftU), wrap(float(reverseBits32(k)) * 0x1p-32f + shiftV));
      Sampler sampler = Sampler::independent(key, k, seed ^ 0x5353535353ULL);
      const SurfaceHit entry = surfaceAt(scene, mesh, triangle, sampleUniformTriangle(u));
      const Bsdf bsdf = bsdfAt(scene, entry);  // a textured albedo: the entry point's medium
      const std::optional<SubsurfaceMedium> medium = subsurfaceMedium(bsdf);
      if (!medium) continue;
      ++result.walks;
      result.area[tixelUnder(c, entry.position) - c.firstTixel] += share;
      // The light comes from the outside: the winding normal's side (the chart's front).
      const ScatteringFrame frame = scatteringFrame(entry, entry.geometricNormal, bsdf);
      const std::optional<WalkExit> exit =
          subsurfaceWalk(scene, accel, entry.position, frame, *medium, Rgb(1.0f), sampler, 0, result.rays);
      if (!exit) continue;
      const uint32_t exitChart = param.triangleChart[exit->surface.mesh][exit->surface.triangle];
      const Chart& e = param.charts[exitChart];
      if (!isSubsurfaceChart(scene, e)) continue;
      ++result.exited;
      out.push_back({tixelUnder(e, exit->surface.position), tixelUnder(c, entry.position), exit->weight * share});
    }
  }
  // Merge per (entry, exit), then per entry tixel drop the smallest while their sum stays
  // within the bound.
  std::sort(out.begin(), out.end(), [](const Contribution& a, const Contribution& b) {
    return a.entry != b.entry ? a.entry < b.entry : a.exit < b.exit;
  });
  std::vector<Contribution> merged;
  for (const Contribution& x : out) {
    if (!merged.empty() && merged.back().entry == x.entry && merged.back().exit == x.exit)
      merged.back().power += x.power;
    else
      merged.push_back(x);
  }
  std::vector<Contribution>& kept = result.contributions;
  kept.reserve(merged.size());
  for (size_t begin = 0; begin < merged.size();) {
    size_t end = begin;
    double total = 0.0;
    while (end < merged.size() && merged[end].entry == merged[begin].entry) total += luminance(merged[end++].power);
    std::vector<size_t> order;
    for (size_t k = begin; k < end; ++k) order.push_back(k);
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return luminance(merged[a].power) < luminance(merged[b].power); });
    std::vector<uint8_t> drop(end - begin, 0);
    double droppedSum = 0.0;
    for (size_t k : order) {
      droppedSum += luminance(merged[k].power);
      if (droppedSum > kSubsurfaceDroppedFraction * total) break;
      drop[k - begin] = 1;
      ++result.dropped;
    }
    for (size_t k = begin; k < end; ++k)
      if (!drop[k - begin]) kept.push_back(merged[k]);
    begin = end;
  }
  return result;
}

// ---- Distributed: the walking records split between the ranks, their results exchanged ----

/// The split of the walking records `charts` between `ranks`: ranks + 1 boundaries into
/// `charts`, rank r walking [result[r], result[r + 1]), contiguous runs of about equal walk
/// counts (a walk's rays vary with the medium, but every rank gets a slice of each object
/// only where an object spans several records). Deterministic: every rank computes the same.
std::vector<uint32_t> walkSplit(const Scene& scene, const Parameterisation& param, const std::vector<uint32_t>& charts,
                                uint32_t walksPerTixel, int ranks) {
  std::vector<double> prefix(charts.size() + 1, 0.0);
  for (size_t k = 0; k < charts.size(); ++k) {
    const Chart& c = param.charts[charts[k]];
    double walks = 0.0;
    for (const auto& [mesh, triangle] : param.chartTriangles[charts[k]]) {
      const float area = triangleArea(scene.meshes[mesh], triangle);
      if (area > 0.0f) walks += triangleWalks(area, walksPerTixel, c.tixelSize * c.tixelSize);
    }
    prefix[k + 1] = prefix[k] + walks;
  }
  return splitByCost(prefix, ranks);
}

// A record's walks as bytes: walks, exited, rays, dropped, the contribution count (uint64
// each), the per-tixel areas (double), the contributions. Ranks run the same build, so the
// structs' layout is the same on every rank.
void appendBytes(std::vector<unsigned char>& out, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  out.insert(out.end(), p, p + bytes);
}
void appendChartWalks(std::vector<unsigned char>& out, const ChartWalks& w) {
  const uint64_t header[5] = {w.walks, w.exited, w.rays, w.dropped, uint64_t(w.contributions.size())};
  appendBytes(out, header, sizeof(header));
  appendBytes(out, w.area.data(), w.area.size() * sizeof(double));
  appendBytes(out, w.contributions.data(), w.contributions.size() * sizeof(Contribution));
}
ChartWalks readChartWalks(const unsigned char*& at, uint64_t tixels) {
  ChartWalks w;
  uint64_t header[5];
  std::memcpy(header, at, sizeof(header));
  at += sizeof(header);
  w.walks = header[0], w.exited = header[1], w.rays = header[2], w.dropped = header[3];
  w.area.resize(tixels);
  std::memcpy(w.area.data(), at, tixels * sizeof(double));
  at += tixels * sizeof(double);
  w.contributions.resize(header[4]);
  std::memcpy(w.contributions.data(), at, header[4] * sizeof(Contribution));
  at += header[4] * sizeof(Contribution);
  return w;
}

/// Every rank's records of `split` into `perChart` on every rank: each rank's serialised
/// records are one contiguous run of a byte buffer, exchanged in place (in windows of at most
/// windowBytes, as shard.h fillTixelsDistributed, so that no collective spans more than an MPI
/// int addresses).
void exchangeChartWalks(const Parameterisation& param, const std::vector<uint32_t>& charts, const std::vector<uint32_t>& split,
                        Communicator& comm, std::vector<ChartWalks>& perChart, uint64_t windowBytes = uint64_t(1) << 30) {
  const int rank = comm.rank(), ranks = comm.size();
  std::vector<unsigned char> local;
  for (uint32_t k = split[size_t(rank)]; k < split[size_t(rank) + 1]; ++k) appendChartWalks(local, perChart[k]);
  const std::vector<uint64_t> sizes = comm.allgather(local.size());
  std::vector<uint64_t> start(static_cast<size_t>(ranks) + 1, 0);
  for (int r = 0; r < ranks; ++r) start[size_t(r) + 1] = start[size_t(r)] + sizes[size_t(r)];
  std::vector<unsigned char> all(start.back());
  std::copy(local.begin(), local.end(), all.begin() + std::ptrdiff_t(start[size_t(rank)]));
  local = {};
  std::vector<uint64_t> displacement(static_cast<size_t>(ranks)), count(static_cast<size_t>(ranks));
  for (uint64_t w0 = 0; w0 < all.size(); w0 += windowBytes) {
    const uint64_t w1 = std::min<uint64_t>(all.size(), w0 + windowBytes);
    for (int r = 0; r < ranks; ++r) {
      const uint64_t b0 = std::clamp(start[size_t(r)], w0, w1), b1 = std::clamp(start[size_t(r) + 1], w0, w1);
      displacement[size_t(r)] = b0;
      count[size_t(r)] = b1 - b0;
    }
    comm.allgatherv(all.data(), displacement, count);
  }
  for (int r = 0; r < ranks; ++r) {
    if (r == rank) continue;
    const unsigned char* at = all.data() + start[size_t(r)];
    for (uint32_t k = split[size_t(r)]; k < split[size_t(r) + 1]; ++k)
      perChart[k] = readChartWalks(at, param.charts[charts[k]].tixelCount());
  }
}

}  // namespace

uint64_t subsurfaceOperatorBytesEstimate(const Scene& scene, const Parameterisation& param, uint32_t walksPerTixel,
                                          int ranks) {
  uint64_t tixels = 0;
  for (const Chart& c : param.charts)
    if (isSubsurfaceChart(scene, c)) tixels += c.tixelCount();
  // Per walk: its contribution record, its entry in the rows and, over several ranks, its
  // bytes in the exchange buffer.
  constexpr uint64_t kEntryBytes = sizeof(uint64_t) + sizeof(Rgb);
  const uint64_t perWalk = sizeof(Contribution) + kEntryBytes + (ranks > 1 ? sizeof(Contribution) : 0);
  return tixels * (uint64_t(std::max(1u, walksPerTixel)) * perWalk + 3 * sizeof(uint64_t) + sizeof(float) + sizeof(Rgb));
}

SubsurfaceOperator buildSubsurfaceOperator(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                           uint32_t walksPerTixel, uint64_t seed) {
  SingleProcess single;
  return buildSubsurfaceOperator(scene, accel, param, walksPerTixel, seed, single);
}

SubsurfaceOperator buildSubsurfaceOperator(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                           uint32_t walksPerTixel, uint64_t seed, Communicator& comm) {
  const auto start = std::chrono::steady_clock::now();
  SubsurfaceOperator op;
  std::vector<uint32_t> charts;
  for (uint32_t ci = 0; ci < param.charts.size(); ++ci) {
    const Chart& c = param.charts[ci];
    if (!isSubsurfaceChart(scene, c)) continue;
    for (uint64_t g = c.firstTixel; g < c.firstTixel + c.tixelCount(); ++g) op.rowTixel.push_back(g);
    if (!c.isBack) charts.push_back(ci);  // walks enter from the outside only
  }
  if (op.rowTixel.empty()) return op;
  std::sort(op.rowTixel.begin(), op.rowTixel.end());

  // The walks, per chart in parallel, this rank's records of the split (every record for one
  // rank), then every rank's exchanged: each record's result depends only on the record, so
  // every rank ends with the one-process results, in chart order (deterministic).
  walksPerTixel = std::max(1u, walksPerTixel);
  const std::vector<uint32_t> split = walkSplit(scene, param, charts, walksPerTixel, comm.size());
  const uint32_t first = split[size_t(comm.rank())], last = split[size_t(comm.rank()) + 1];
  std::vector<ChartWalks> perChart(charts.size());
  parallelFor(last - first, [&](uint64_t k) {
    perChart[first + k] = chartWalks(scene, accel, param, charts[first + k], walksPerTixel, seed);
  });
  for (uint32_t k = first; k < last; ++k) op.walkedHere += perChart[k].walks;
  if (comm.size() > 1) exchangeChartWalks(param, charts, split, comm, perChart);
  for (const ChartWalks& w : perChart) {
    op.walks += w.walks;
    op.exited += w.exited;
    op.rays += w.rays;
    op.dropped += w.dropped;
  }

  // Compressed by exit tixel: count, prefix sums, fill (entries in chart, then entry order).
  const auto rowOf = [&](uint64_t g) {
    return uint64_t(std::lower_bound(op.rowTixel.begin(), op.rowTixel.end(), g) - op.rowTixel.begin());
  };
  // A_j: the surface area the entry walks found under tixel j; where they found none (a back
  // record, or a sliver between their points) one footprint sub-sample's share of the tixel,
  // so that a walk leaving there does not divide by zero.
  op.area.resize(op.rowTixel.size());
  for (size_t r = 0; r < op.rowTixel.size(); ++r) {
    const Chart& c = param.charts[param.tixelChart[op.rowTixel[r]]];
    op.area[r] = std::max(param.coverage[op.rowTixel[r]], 1.0f / 16.0f) * c.tixelSize * c.tixelSize;
  }
  for (size_t k = 0; k < charts.size(); ++k) {
    const Chart& c = param.charts[charts[k]];
    for (uint64_t local = 0; local < c.tixelCount(); ++local)
      if (perChart[k].area[local] > 0.0) op.area[rowOf(c.firstTixel + local)] = float(perChart[k].area[local]);
  }
  op.rowStart.assign(op.rowTixel.size() + 1, 0);
  for (const ChartWalks& w : perChart)
    for (const Contribution& x : w.contributions) ++op.rowStart[rowOf(x.exit) + 1];
  for (size_t r = 0; r < op.rowTixel.size(); ++r) op.rowStart[r + 1] += op.rowStart[r];
  op.entryTixel.resize(op.rowStart.back());
  op.weight.resize(op.rowStart.back());
  std::vector<uint64_t> fill(op.rowStart.begin(), op.rowStart.end() - 1);
  for (const ChartWalks& w : perChart)
    for (const Contribution& x : w.contributions) {
      const uint64_t r = rowOf(x.exit);
      op.entryTixel[fill[r]] = x.entry;
      op.weight[fill[r]] = x.power / op.area[r];  // K[j ← i] = Σ w·a / A_j
      ++fill[r];
    }
  op.seconds = secondsSince(start);
  return op;
}

void applySubsurfaceOperator(const SubsurfaceOperator& op, const std::vector<Rgb>& irradiance, std::vector<Rgb>& exitance) {
  exitance.resize(op.rowTixel.size());
  parallelForRange(op.rowTixel.size(), 256, [&](uint64_t r0, uint64_t r1) {
    for (uint64_t r = r0; r < r1; ++r) {
      Rgb sum(0.0f);
      for (uint64_t k = op.rowStart[r]; k < op.rowStart[r + 1]; ++k) sum += op.weight[k] * irradiance[op.entryTixel[k]];
      exitance[r] = sum;
    }
  });
}

std::vector<Rgb> subsurfaceLeavingFractions(const SubsurfaceOperator& op) {
  std::vector<DVec3> leaving(op.rowTixel.size(), DVec3(0.0));
  for (size_t r = 0; r < op.rowTixel.size(); ++r)
    for (uint64_t k = op.rowStart[r]; k < op.rowStart[r + 1]; ++k) {
      const uint64_t i = uint64_t(std::lower_bound(op.rowTixel.begin(), op.rowTixel.end(), op.entryTixel[k]) -
                                  op.rowTixel.begin());
      leaving[i] += DVec3(op.weight[k]) * double(op.area[r]);
    }
  std::vector<Rgb> out(op.rowTixel.size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = Rgb(leaving[i] / double(op.area[i]));
  return out;
}

}  // namespace pl
