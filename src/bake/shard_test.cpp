// The split of a bake between ranks (shard.h) and the propagation of several ranks, simulated
// in one process by threads exchanging through shared memory (ThreadRanks below): the light
// field of 2, 3 and 5 ranks must be the one-process bake's bit for bit, on the built-in Cornell
// box, McGuire's glossy box, a rough-glass sphere (whose records gather each other's light) and
// a subsurface sphere and slab (whose light crosses the object between the ranks' shares).
// The same through real MPI processes is distributed_bake_test.
#include "bake/shard.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <barrier>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bake/parameterisation.h"
#include "bake/propagation.h"
#include "core/error.h"
#include "core/progress.h"
#include "distributed/communicator.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

BakeSettings smallSettings(float tixelsAcross, uint32_t directions) {
  BakeSettings s = bakePreset("draft");
  s.tixelsAcrossScene = tixelsAcross;
  s.gatherDirections = directions;
  return s;
}

/// N ranks as N threads of this process: what a collective moves goes through shared memory,
/// between two barriers (so no rank reads a buffer while another writes it).
class ThreadRanks {
 public:
  explicit ThreadRanks(int ranks) : ranks_(ranks), barrier_(ranks), buffers_(size_t(ranks)), values_(size_t(ranks)) {}

  class Rank final : public Communicator {
   public:
    Rank(ThreadRanks& world, int rank) : world_(world), rank_(rank) {}
    int rank() const override { return rank_; }
    int size() const override { return world_.ranks_; }
    void allgatherv(void* buffer, const std::vector<uint64_t>& displacement, const std::vector<uint64_t>& count) override {
      world_.buffers_[size_t(rank_)] = static_cast<unsigned char*>(buffer);
      world_.barrier_.arrive_and_wait();
      for (int r = 0; r < size(); ++r) {
        if (r == rank_ || count[size_t(rank_)] == 0) continue;
        std::memcpy(world_.buffers_[size_t(r)] + displacement[size_t(rank_)],
                    static_cast<unsigned char*>(buffer) + displacement[size_t(rank_)], count[size_t(rank_)]);
      }
      world_.barrier_.arrive_and_wait();
      for (int r = 0; r < size(); ++r)
        if (r != rank_) bytesReceived_ += count[size_t(r)];
      ++exchanges_;
    }
    std::vector<uint64_t> allgather(uint64_t value) override {
      world_.values_[size_t(rank_)] = value;
      world_.barrier_.arrive_and_wait();
      std::vector<uint64_t> all = world_.values_;
      world_.barrier_.arrive_and_wait();
      return all;
    }
    void barrier() override { world_.barrier_.arrive_and_wait(); }
    [[noreturn]] void abort(int) override { std::abort(); }
    std::string name() const override { return "threads"; }

   private:
    ThreadRanks& world_;
    int rank_;
  };

  /// Runs body(communicator) on every rank, each on its own thread; returns when all are done.
  template <typename Body>
  void run(Body body) {
    std::vector<std::thread> threads;
    for (int r = 0; r < ranks_; ++r)
      threads.emplace_back([this, r, &body] {
        Rank rank(*this, r);
        body(rank);
      });
    for (std::thread& t : threads) t.join();
  }

 private:
  int ranks_;
  std::barrier<> barrier_;
  std::vector<unsigned char*> buffers_;
  std::vector<uint64_t> values_;
};

/// Values of a one-process bake and of `ranks` simulated ranks (every rank's), compared bit for
/// bit; returns every rank's result. streamDir: when given, each rank streams its shard of the
/// field from a .plv there (computeVisibilityShard's streamTo) instead of holding it.
std::vector<PropagationResult> expectRanksMatchOneProcess(const Scene& scene, const BakeSettings& settings, int ranks,
                                                          const std::string& streamDir = "") {
  Progress::setEnabled(false);
  const Accel accel(scene);
  const Parameterisation param = buildParameterisation(scene, accel, settings);
  const VisibilityField whole = computeVisibility(scene, accel, param, settings);
  const PropagationResult one = propagate(scene, accel, param, whole, settings);
  const ShardPlan plan = planShards(scene, param, settings, ranks);
  std::vector<PropagationResult> results(static_cast<size_t>(ranks));
  ThreadRanks world(ranks);
  world.run([&](Communicator& comm) {
    const std::vector<TixelRange> held = visibilityRanges(scene, param, plan, comm.rank());
    const std::string streamTo =
        streamDir.empty() ? std::string() : fmt::format("{}/rank{}-of-{}.plv", streamDir, comm.rank(), ranks);
    const VisibilityShard shard = computeVisibilityShard(scene, accel, param, settings, held, false, nullptr, streamTo);
    EXPECT_EQ(shard.streamed(), !streamDir.empty());
    results[size_t(comm.rank())] =
        propagate(scene, accel, param, [&]() -> const VisibilityShard& { return shard; }, settings, comm, plan);
  });
  for (int r = 0; r < ranks; ++r) {
    const PropagationResult& result = results[size_t(r)];
    EXPECT_EQ(result.iterations, one.iterations) << "rank " << r;
    EXPECT_EQ(result.shadowRays, one.shadowRays) << "rank " << r;
    EXPECT_EQ(result.values.size(), one.values.size());
    if (result.values.size() != one.values.size()) continue;
    size_t differing = 0;
    for (size_t v = 0; v < one.values.size(); ++v) differing += std::memcmp(&one.values[v], &result.values[v], sizeof(Rgb)) != 0;
    EXPECT_EQ(differing, 0u) << "values of rank " << r << " of " << ranks << " differ from one process's";
    EXPECT_GT(result.exchangeBytes, 0u);
  }
  return results;
}

TEST(Shards, PlanSplitsEveryBatchIntoContiguousPartsOfEqualCost) {
  const Scene scene = makeCornellBox();
  const BakeSettings settings = smallSettings(16, 64);
  const Parameterisation param = buildParameterisation(scene, settings);
  for (int ranks : {1, 2, 3, 7}) {
    const ShardPlan plan = planShards(scene, param, settings, ranks);
    EXPECT_EQ(plan.batchStart, propagationBatches(param));
    double largestTixel = 0.0;
    for (uint64_t g = 0; g < param.tixelCount; ++g)
      largestTixel = std::max(largestTixel, estimatedTixelCost(scene, param, settings, g));
    std::vector<int> owner(param.tixelCount, -1);
    for (size_t b = 0; b < plan.batches(); ++b) {
      EXPECT_EQ(plan.part(b, 0).begin, plan.batchStart[b]);
      EXPECT_EQ(plan.part(b, ranks - 1).end, plan.batchStart[b + 1]);
      double batchCost = 0.0;
      for (uint64_t g = plan.batchStart[b]; g < plan.batchStart[b + 1]; ++g)
        batchCost += estimatedTixelCost(scene, param, settings, g);
      for (int r = 0; r < ranks; ++r) {
        const TixelRange part = plan.part(b, r);
        if (r > 0) {
          EXPECT_EQ(part.begin, plan.part(b, r - 1).end);
        }
        double cost = 0.0;
        for (uint64_t g = part.begin; g < part.end; ++g) cost += estimatedTixelCost(scene, param, settings, g);
        // Balanced to within one tixel's cost (the parts end on whole tixels).
        EXPECT_NEAR(cost, batchCost / ranks, largestTixel + 1e-9 * batchCost) << "batch " << b << " rank " << r;
      }
    }
    for (int r = 0; r < ranks; ++r)
      for (const TixelRange& range : plan.owned(r))
        for (uint64_t g = range.begin; g < range.end; ++g) {
          EXPECT_EQ(owner[g], -1) << g;
          owner[g] = r;
        }
    EXPECT_EQ(std::count(owner.begin(), owner.end(), -1), 0);
  }
}

TEST(Shards, MirrorTixelsCostNothingAndGlossyOnesMore) {
  // CornellBox-Glossy has glossy charts, CornellBox-Mirror a mirror (specular charts).
  const BakeSettings settings = smallSettings(10, 64);
  double diffuse = 0.0, glossy = 0.0;
  uint64_t specular = 0;
  for (const char* file : {"CornellBox-Glossy.obj", "CornellBox-Mirror.obj"}) {
    const Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/" + file);
    const Parameterisation param = buildParameterisation(scene, settings);
    for (uint64_t g = 0; g < param.tixelCount; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      const double cost = estimatedTixelCost(scene, param, settings, g);
      if (c.kind == ChartKind::Specular) {
        EXPECT_EQ(cost, 0.0);
        ++specular;
      }
      if (c.kind == ChartKind::Diffuse) diffuse = cost;
      if (c.kind == ChartKind::Glossy) glossy = std::max(glossy, cost);
    }
  }
  EXPECT_GT(specular, 0u);   // the mirror was looked at
  EXPECT_GT(diffuse, 64.0);  // its gather rays and more
  EXPECT_GT(glossy, diffuse);
}

class ShardFiles : public test_support::TempDirTest {};

TEST_F(ShardFiles, ShardFieldHoldsTheWholeFieldsEntriesAndRoundTrips) {
  const Scene scene = makeCornellBox();
  const BakeSettings settings = smallSettings(12, 36);
  const Accel accel(scene);
  const Parameterisation param = buildParameterisation(scene, accel, settings);
  const VisibilityField whole = computeVisibility(scene, accel, param, settings);
  const ShardPlan plan = planShards(scene, param, settings, 3);
  const std::vector<TixelRange> held = visibilityRanges(scene, param, plan, 1);
  const VisibilityShard shard = computeVisibilityShard(scene, accel, param, settings, held);
  const VisibilityShard wholeShard = VisibilityShard::whole(whole);
  EXPECT_NE(shard.field.hash, whole.hash);  // a shard is not the whole field
  EXPECT_EQ(visibilityShardHash(whole.hash, {TixelRange{0, param.tixelCount}}, param.tixelCount), whole.hash);
  const uint32_t n = whole.directionsPerTixel();
  std::vector<VisibilityEntry> a(n), b(n);
  uint64_t heldTixels = 0;
  for (const TixelRange& r : held) {
    heldTixels += r.size();
    EXPECT_TRUE(shard.holds(r.begin, r.end));
    for (uint64_t g = r.begin; g < r.end; ++g) {
      ASSERT_EQ(std::memcmp(shard.entries(g, a.data()), wholeShard.entries(g, b.data()), n * sizeof(VisibilityEntry)), 0) << g;
      const uint64_t extras = whole.extraOffset[g + 1] - whole.extraOffset[g];
      ASSERT_EQ(shard.field.extraOffset[shard.local(g) + 1] - shard.field.extraOffset[shard.local(g)], extras) << g;
      if (extras > 0) {
        ASSERT_EQ(std::memcmp(shard.extras(g), wholeShard.extras(g), extras * sizeof(VisibilityExtra)), 0);
      }
    }
  }
  EXPECT_EQ(shard.field.tixelCount, heldTixels);
  EXPECT_LT(heldTixels, param.tixelCount);
  EXPECT_FALSE(shard.holds(0, param.tixelCount));

  const std::string plv = path("s.plv");
  writeVisibility(plv, shard.field);
  VisibilityField read;
  std::string why;
  // Entries point at tixels of the whole scene: the reader must be told how many there are.
  EXPECT_THROW(readVisibility(plv, shard.field.hash, read, &why), Error);
  ASSERT_TRUE(readVisibility(plv, shard.field.hash, read, &why, param.tixelCount)) << why;
  ASSERT_EQ(read.entryCount(), shard.field.entryCount());
  const std::vector<VisibilityEntry> readEntries = read.decodeAll(), shardEntries = shard.field.decodeAll();
  EXPECT_EQ(std::memcmp(readEntries.data(), shardEntries.data(), readEntries.size() * sizeof(VisibilityEntry)), 0);
  EXPECT_FALSE(readVisibility(plv, whole.hash, read, &why, param.tixelCount));  // another partition's hash
}

template <typename T>
size_t differingEntries(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return std::max(a.size(), b.size());
  size_t differing = 0;
  for (size_t i = 0; i < a.size(); ++i) differing += std::memcmp(&a[i], &b[i], sizeof(T)) != 0;
  return differing;
}

TEST(Shards, TixelSetupSplitCoversTheRecordsInContiguousRunsOfEqualCost) {
  const Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/CornellBox-Sphere.obj");
  const Parameterisation param = buildCharts(scene, Accel(scene), smallSettings(24, 16));
  for (int ranks : {1, 2, 3, 7}) {
    const std::vector<uint32_t> split = tixelSetupSplit(param, ranks);
    ASSERT_EQ(split.size(), size_t(ranks) + 1);
    EXPECT_EQ(split.front(), 0u);
    EXPECT_EQ(split.back(), param.charts.size());
    // The documented cost: 1 per record plus its tixels, a specular tixel counting 1/4.
    auto cost = [&](uint32_t ci) {
      const Chart& c = param.charts[ci];
      return 1.0 + (c.kind == ChartKind::Specular ? 0.25 : 1.0) * double(c.tixelCount());
    };
    double total = 0.0, largestRecord = 0.0;
    for (uint32_t ci = 0; ci < param.charts.size(); ++ci) {
      total += cost(ci);
      largestRecord = std::max(largestRecord, cost(ci));
    }
    double covered = 0.0;
    for (int r = 0; r < ranks; ++r) {
      ASSERT_LE(split[size_t(r)], split[size_t(r) + 1]);
      double share = 0.0;
      for (uint32_t ci = split[size_t(r)]; ci < split[size_t(r) + 1]; ++ci) share += cost(ci);
      covered += share;
      // Records are not divided: a share exceeds 1/ranks of the total by less than one record.
      EXPECT_LT(share, total / ranks + largestRecord) << "rank " << r << " of " << ranks;
    }
    EXPECT_DOUBLE_EQ(covered, total);
  }
}

TEST(Shards, RanksFillTheOneProcessParameterisationBitForBit) {
  // The sphere box: curved charts (gather normals), buried tixels under the spheres, two-sided
  // records; and a sun, so that sun masks are made (the spheres' shadow edges: partial masks).
  Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/CornellBox-Sphere.obj");
  scene.lights.push_back(DirectionalLight{glm::normalize(Vec3(-0.3f, -0.5f, -1.0f)), Rgb(2.0f)});  // in through the open front
  const BakeSettings settings = smallSettings(24, 16);
  const Accel accel(scene);
  const Parameterisation one = buildParameterisation(scene, accel, settings);
  ASSERT_TRUE(std::any_of(one.charts.begin(), one.charts.end(), [](const Chart& c) { return c.curved; }));
  ASSERT_EQ(one.sunMaskLights.size(), 1u);
  ASSERT_TRUE(std::any_of(one.sunMask.begin(), one.sunMask.end(), [](const SunMaskSlots& m) { return m[0] != 0 && m[0] != 0xffff; }));
  // 2 and 3 ranks; with 3, also in windows of 1000 bytes (as a field over 1 GiB per array is
  // exchanged), whose boundaries fall inside ranks' runs.
  for (const auto& [ranks, windowBytes] : {std::pair{2, uint64_t(1) << 30}, std::pair{3, uint64_t(1) << 30},
                                          std::pair{3, uint64_t(1000)}}) {
    std::vector<Parameterisation> results(static_cast<size_t>(ranks));
    std::vector<TixelSetupTiming> timings(static_cast<size_t>(ranks));
    ThreadRanks world(ranks);
    world.run([&](Communicator& comm) {
      Parameterisation p = buildCharts(scene, accel, settings);
      timings[size_t(comm.rank())] = fillTixelsDistributed(scene, accel, p, comm, windowBytes);
      results[size_t(comm.rank())] = std::move(p);
    });
    for (int r = 0; r < ranks; ++r) {
      const Parameterisation& p = results[size_t(r)];
      EXPECT_EQ(differingEntries(p.gatherPoint, one.gatherPoint), 0u) << "rank " << r << " of " << ranks;
      EXPECT_EQ(differingEntries(p.gatherNormal, one.gatherNormal), 0u) << "rank " << r << " of " << ranks;
      EXPECT_EQ(differingEntries(p.coverage, one.coverage), 0u) << "rank " << r << " of " << ranks;
      EXPECT_EQ(differingEntries(p.transportAlbedo, one.transportAlbedo), 0u) << "rank " << r << " of " << ranks;
      EXPECT_EQ(differingEntries(p.sunMask, one.sunMask), 0u) << "rank " << r << " of " << ranks;
      EXPECT_EQ(visibilityHash(scene, p, settings), visibilityHash(scene, one, settings));
      EXPECT_GT(timings[size_t(r)].seconds, 0.0);
    }
  }
  // A rank that filled only its own records (no exchange) holds zeros elsewhere: what the
  // exchange above supplies, so the comparison could fail.
  Parameterisation part = buildCharts(scene, accel, settings);
  const std::vector<uint32_t> split = tixelSetupSplit(part, 2);
  fillTixels(scene, accel, part, split[0], split[1]);
  EXPECT_GT(differingEntries(part.gatherPoint, one.gatherPoint), 0u);
  // Records outside the parameterisation are refused, not written past the arrays.
  const uint32_t records = uint32_t(part.charts.size());
  EXPECT_THROW(fillTixels(scene, accel, part, 0, records + 1), Error);
  EXPECT_THROW(fillTixels(scene, accel, part, 2, 1), Error);
}

TEST_F(ShardFiles, RanksFillEveryTixelSetupArrayOfTheOneProcess) {
  // Normal-mapped walls (tilt weights) and a textured lamp (emission means, emitting
  // triangles): every array forEachTixelSetupArray names reaches every rank, not only the
  // three the sphere box above uses.
  namespace fs = std::filesystem;
  for (const char* file : {"normal_tilt.png", "checker.png"})
    fs::copy_file(std::string(PLENOPTIC_TEST_DATA_DIR) + "/scene/" + file, path(file));
  const std::string json = path("detail.json");
  std::ofstream(json) << R"({"meshes": [{"file": ")" << PLENOPTIC_TEST_DATA_DIR
                      << R"(/cornell-mcguire/CornellBox-Original.obj"}], "materials": {)"
                      << R"("backWall": {"type": "lambert", "albedo": 0.7, "normal_texture": "normal_tilt.png"},)"
                      << R"("light": {"type": "lambert", "albedo": 0.78, "emission": [17, 12, 4], "emission_texture": "checker.png"}}})";
  const Scene scene = loadScene(json);
  const BakeSettings settings = smallSettings(16, 16);
  const Accel accel(scene);
  const Parameterisation one = buildParameterisation(scene, accel, settings);
  ASSERT_FALSE(one.transportTiltWeights.empty());
  ASSERT_FALSE(one.emissionModulation.empty());
  ASSERT_FALSE(one.emitterTriangle.empty());
  std::vector<Parameterisation> results(2);
  ThreadRanks world(2);
  world.run([&](Communicator& comm) {
    Parameterisation p = buildCharts(scene, accel, settings);
    fillTixelsDistributed(scene, accel, p, comm, uint64_t(1) << 30);
    results[size_t(comm.rank())] = std::move(p);
  });
  for (int r = 0; r < 2; ++r) {
    size_t index = 0;
    forEachTixelSetupArray(one, [&](const char* tag, const auto& expected) {
      using Array = std::decay_t<decltype(expected)>;
      const Array* got = nullptr;
      size_t at = 0;
      forEachTixelSetupArray(results[size_t(r)], [&](const char*, const auto& array) {
        if constexpr (std::is_same_v<std::decay_t<decltype(array)>, Array>)
          if (at == index) got = &array;
        ++at;
      });
      ASSERT_NE(got, nullptr) << tag;
      EXPECT_EQ(differingEntries(*got, expected), 0u) << "array " << tag << ", rank " << r;
      ++index;
    });
    EXPECT_EQ(differingEntries(results[size_t(r)].sunMask, one.sunMask), 0u) << "rank " << r;
  }
}

TEST(Shards, ShardFileNames) {
  EXPECT_EQ(shardVisibilityPath("out/a.plv", 0, 1), "out/a.plv");
  EXPECT_EQ(shardVisibilityPath("out/a.plv", 2, 3), "out/a.rank2-of-3.plv");
  EXPECT_EQ(shardVisibilityPath("", 1, 2), "");
}

TEST(Shards, RanksGetTheOneProcessLightFieldBitForBit) {
  const Scene scene = makeCornellBox();
  for (int ranks : {2, 3, 5}) expectRanksMatchOneProcess(scene, smallSettings(12, 64), ranks);
}

TEST(Shards, RanksGetTheOneProcessLightFieldWithGlossyCharts) {
  const Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/CornellBox-Glossy.obj");
  expectRanksMatchOneProcess(scene, smallSettings(10, 36), 3);
}

TEST_F(ShardFiles, RanksGetTheOneProcessLightFieldWithRoughGlass) {
  // McGuire's sphere box with its right sphere made rough glass (bench/scenes has the same):
  // every rough-glass record's update gathers its twin's light, which may live on another rank.
  const std::string json = path("rough.json");
  std::ofstream(json) << R"({"meshes": [{"file": ")" << PLENOPTIC_TEST_DATA_DIR
                      << R"(/cornell-mcguire/CornellBox-Sphere.obj"}], "materials": {"rightSphere": )"
                      << R"({"type": "dielectric", "ior": 1.6, "transmittance": 0.95, "roughness": 0.5}}})";
  const Scene scene = loadScene(json);
  const BakeSettings settings = smallSettings(6, 16);
  const Parameterisation param = buildParameterisation(scene, settings);
  // The split must hand some rank a rough-glass tixel whose twin another rank owns.
  const ShardPlan plan = planShards(scene, param, settings, 3);
  bool twinElsewhere = false;
  for (int r = 0; r < 3; ++r) {
    const std::vector<TixelRange> held = visibilityRanges(scene, param, plan, r);
    uint64_t heldTixels = 0, ownTixels = 0;
    for (const TixelRange& range : held) heldTixels += range.size();
    for (const TixelRange& range : plan.owned(r)) ownTixels += range.size();
    twinElsewhere = twinElsewhere || heldTixels > ownTixels;
  }
  ASSERT_TRUE(twinElsewhere);
  expectRanksMatchOneProcess(scene, settings, 3);
  // Each rank's shard streamed from its .plv (several ranges, twins read from other blocks): the same bits.
  expectRanksMatchOneProcess(scene, settings, 3, dir_);
}

TEST(Shards, RanksGetTheOneProcessLightFieldWithSubsurface) {
  // The sphere-and-slab box (bench/scenes/sss-cornell.json): each rank walks its share of the
  // subsurface records, the walks are exchanged, and the irradiance each subsurface tixel's
  // owner gathered is exchanged before the operator is applied every iteration.
  const Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/../../bench/scenes/sss-cornell.json");
  for (int ranks : {2, 3}) {
    const std::vector<PropagationResult> results = expectRanksMatchOneProcess(scene, smallSettings(8, 16), ranks);
    uint64_t walked = 0;
    for (const PropagationResult& result : results) {
      EXPECT_EQ(result.subsurfaceWalks, results[0].subsurfaceWalks);
      EXPECT_EQ(result.subsurfaceEntries, results[0].subsurfaceEntries);
      EXPECT_LT(result.subsurfaceWalkedHere, result.subsurfaceWalks);  // split, not repeated
      walked += result.subsurfaceWalkedHere;
    }
    EXPECT_GT(results[0].subsurfaceWalks, 0u);
    EXPECT_EQ(walked, results[0].subsurfaceWalks);
  }
}

}  // namespace
}  // namespace pl
