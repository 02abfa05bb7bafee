// The partition of the tixels between the ranks of a distributed bake (see shard.h).
#include "bake/shard.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <type_traits>

#include <fmt/format.h>

#include "bake/parameterisation.h"
#include "bake/propagation.h"
#include "core/error.h"
#include "distributed/communicator.h"

namespace pl {

namespace {
// Cost of one BSDF evaluation or operator multiply-add relative to one traced ray (Embree
// ~1 µs per incoherent ray per core on Sponza; an evaluation is a few tens of ns).
constexpr double kGlossyEvalCost = 0.05;
}  // namespace

std::vector<TixelRange> ShardPlan::owned(int rank) const {
  std::vector<TixelRange> out;
  for (size_t b = 0; b < batches(); ++b) {
    const TixelRange r = part(b, rank);
    if (r.size() == 0) continue;
    if (!out.empty() && out.back().end == r.begin)
      out.back().end = r.end;
    else
      out.push_back(r);
  }
  return out;
}

double estimatedTixelCost(const Scene& scene, const Parameterisation& param, const BakeSettings& settings, uint64_t g) {
  const Chart& c = param.charts[param.tixelChart[g]];
  if (c.kind == ChartKind::Specular) return 0.0;
  const double n = double(gatherGridSide(settings.gatherDirections)) * gatherGridSide(settings.gatherDirections);
  const double samples = double(settings.areaLightSamples);
  // The first shot's shadow rays: one per delta light (its glossy record averaged over 9
  // directions per texel), max(1, area-light samples) per other scene light (propagation.cpp).
  double deltaLights = 0.0, sampledLightRays = 0.0;
  for (const Light& light : scene.lights) {
    if (isDeltaLight(light)) deltaLights += 1.0;
    else sampledLightRays += std::max(1.0, samples);
  }
  double cost = n + deltaLights + sampledLightRays + samples;
  if (c.kind == ChartKind::Glossy)
    cost += kGlossyEvalCost * double(c.valuesPerTixel()) * (9.0 * deltaLights + sampledLightRays + samples + n / 8.0);
  return cost;
}

ShardPlan planShards(const Scene& scene, const Parameterisation& param, const BakeSettings& settings, int ranks) {
  if (ranks < 1) fail("a distributed bake needs at least one rank, not {}", ranks);
  ShardPlan plan;
  plan.ranks = ranks;
  plan.batchStart = propagationBatches(param);
  plan.rankCost.assign(size_t(ranks), 0.0);
  std::vector<double> prefix;
  for (size_t b = 0; b < plan.batches(); ++b) {
    const uint64_t begin = plan.batchStart[b], end = plan.batchStart[b + 1];
    if (ranks == 1) {  // one process: the whole batch, no cost estimate needed
      plan.split.insert(plan.split.end(), {begin, end});
      continue;
    }
    prefix.assign(1, 0.0);
    for (uint64_t g = begin; g < end; ++g) prefix.push_back(prefix.back() + estimatedTixelCost(scene, param, settings, g));
    const double total = prefix.back();
    plan.split.push_back(begin);
    for (int r = 1; r < ranks; ++r) {
      // The first tixel at which the running cost reaches r/ranks of the batch's.
      const double target = total * double(r) / double(ranks);
      const uint64_t at = uint64_t(std::lower_bound(prefix.begin(), prefix.end(), target) - prefix.begin());
      plan.split.push_back(std::max(plan.split.back(), std::min(end, begin + at)));
    }
    plan.split.push_back(end);
    for (int r = 0; r < ranks; ++r) {
      const TixelRange p = plan.part(b, r);
      plan.rankCost[size_t(r)] += prefix[p.end - begin] - prefix[p.begin - begin];
    }
  }
  return plan;
}

std::vector<TixelRange> visibilityRanges(const Scene& scene, const Parameterisation& param, const ShardPlan& plan, int rank) {
  std::vector<TixelRange> ranges = plan.owned(rank);
  const size_t ownCount = ranges.size();
  for (size_t i = 0; i < ownCount; ++i) {
    const TixelRange r = ranges[i];
    for (uint32_t ci = param.tixelChart[r.begin]; ci < param.charts.size() && param.charts[ci].firstTixel < r.end; ++ci) {
      const Chart& c = param.charts[ci];
      if (!isRoughGlassChart(c, scene.materials[c.material].bsdf)) continue;
      // The twin record has the same grid (the back follows the front).
      const Chart& twin = param.charts[c.isBack ? ci - 1 : ci + 1];
      const uint64_t a = std::max(r.begin, c.firstTixel) - c.firstTixel;
      const uint64_t b = std::min(r.end, c.firstTixel + c.tixelCount()) - c.firstTixel;
      ranges.push_back({twin.firstTixel + a, twin.firstTixel + b});
    }
  }
  std::sort(ranges.begin(), ranges.end(), [](const TixelRange& x, const TixelRange& y) { return x.begin < y.begin; });
  std::vector<TixelRange> merged;
  for (const TixelRange& r : ranges) {
    if (r.size() == 0) continue;
    if (!merged.empty() && r.begin <= merged.back().end)
      merged.back().end = std::max(merged.back().end, r.end);
    else
      merged.push_back(r);
  }
  return merged;
}

std::string shardVisibilityPath(const std::string& path, int rank, int ranks) {
  if (ranks <= 1 || path.empty()) return path;
  std::filesystem::path p(path);
  const std::string extension = p.extension().string();
  p.replace_extension();
  return fmt::format("{}.rank{}-of-{}{}", p.string(), rank, ranks, extension);
}

std::vector<uint32_t> tixelSetupSplit(const Parameterisation& param, int ranks) {
  if (ranks < 1) fail("a distributed bake needs at least one rank, not {}", ranks);
  const size_t records = param.charts.size();
  std::vector<double> prefix(records + 1, 0.0);
  for (size_t ci = 0; ci < records; ++ci) {
    const Chart& c = param.charts[ci];
    const double perTixel = c.kind == ChartKind::Specular ? 0.25 : 1.0;
    prefix[ci + 1] = prefix[ci] + 1.0 + perTixel * double(c.tixelCount());
  }
  return splitByCost(prefix, ranks);
}

std::vector<uint32_t> splitByCost(const std::vector<double>& prefix, int ranks) {
  const size_t items = prefix.size() - 1;
  std::vector<uint32_t> split{0};
  for (int r = 1; r < ranks; ++r) {
    // The first item at which the running cost reaches r/ranks of the total.
    const double target = prefix.back() * double(r) / double(ranks);
    const size_t at = size_t(std::lower_bound(prefix.begin(), prefix.end(), target) - prefix.begin());
    split.push_back(std::max(split.back(), uint32_t(std::min(at, items))));
  }
  split.push_back(uint32_t(items));
  return split;
}

TixelSetupTiming fillTixelsDistributed(const Scene& scene, const Accel& accel, Parameterisation& param, Communicator& comm,
                                       uint64_t windowBytes) {
  TixelSetupTiming timing;
  const int rank = comm.rank(), ranks = comm.size();
  const std::vector<uint32_t> split = tixelSetupSplit(param, ranks);
  const auto start = std::chrono::steady_clock::now();
  fillTixels(scene, accel, param, split[size_t(rank)], split[size_t(rank) + 1]);
  const auto filled = std::chrono::steady_clock::now();
  timing.seconds = std::chrono::duration<double>(filled - start).count();
  if (ranks == 1) return timing;
  // Rank r's records hold tixels [first tixel of split[r], first tixel of split[r + 1]).
  auto firstTixelOf = [&](uint32_t record) { return record < param.charts.size() ? param.charts[record].firstTixel : param.tixelCount; };
  // In windows of at most windowBytes of the array, so that no collective addresses more than
  // an MPI int can (the communicator refuses layouts spanning over 2 GB).
  auto exchange = [&](auto& array) {
    using Element = typename std::decay_t<decltype(array)>::value_type;
    const uint64_t window = std::max<uint64_t>(1, windowBytes / sizeof(Element));
    std::vector<uint64_t> displacement(static_cast<size_t>(ranks)), count(static_cast<size_t>(ranks));
    for (uint64_t w0 = 0; w0 < param.tixelCount; w0 += window) {
      const uint64_t w1 = std::min(param.tixelCount, w0 + window);
      for (int r = 0; r < ranks; ++r) {
        const uint64_t t0 = std::clamp(firstTixelOf(split[size_t(r)]), w0, w1);
        const uint64_t t1 = std::clamp(firstTixelOf(split[size_t(r) + 1]), w0, w1);
        displacement[size_t(r)] = t0 * sizeof(Element);
        count[size_t(r)] = (t1 - t0) * sizeof(Element);
      }
      comm.allgatherv(array.data(), displacement, count);
    }
  };
  // Every per-tixel array fillTixels fills (one list: forEachTixelSetupArray), and the sun masks.
  forEachTixelSetupArray(param, [&](const char*, auto& array) {
    if (!array.empty()) exchange(array);
  });
  exchange(param.sunMask);
  timing.exchangeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - filled).count();
  return timing;
}

uint64_t firstValueOf(const Parameterisation& param, uint64_t g) {
  if (g >= param.tixelCount) return param.valueCount;
  const Chart& c = param.charts[param.tixelChart[g]];
  return c.firstValue + (g - c.firstTixel) * c.valuesPerTixel();
}

}  // namespace pl
