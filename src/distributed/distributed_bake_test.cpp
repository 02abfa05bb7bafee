// The distributed bake end to end (issue #16): `mpirun -np N plenoptic bake` on this machine
// (PLENOPTIC_BINARY, --oversubscribe so that 3 ranks run on 2 cores). Checks that the light
// field is the single-process one bit for bit for 2 and 3 ranks (the built-in Cornell box,
// McGuire's glossy box for the glossy charts' paths, a subsurface scene for its operator),
// that each rank saves and reuses its own .plv shard, that a rank with a different scene file
// is refused before any work, and that a failing rank ends the job with a non-zero status and
// no .plf (the old one intact).
// Skipped, saying so, when mpirun is missing or this build has no MPI.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "distributed/communicator.h"
#include "plf/plf_file.h"
#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

class DistributedBake : public cli_test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    if (!mpiAvailable()) GTEST_SKIP() << "this build has no MPI (install libopenmpi-dev, see scripts/bootstrap.sh)";
    if (std::system("command -v mpirun > /dev/null 2>&1") != 0)
      GTEST_SKIP() << "mpirun not found (install openmpi-bin, see scripts/bootstrap.sh)";
  }

  /// `mpirun ... -np RANKS plenoptic ARGUMENTS --quiet --threads 1` (one thread per rank:
  /// the ranks share this machine's cores).
  int runRanks(int ranks, const std::string& arguments, std::string* err = nullptr) const {
    return mpirun(" -np " + std::to_string(ranks) + " \"" + PLENOPTIC_BINARY + "\" " + arguments + " --quiet --threads 1", err);
  }
  /// mpirun with an explicit application context (MPMD: "-np 1 prog args : -np 1 prog args").
  int mpirun(const std::string& context, std::string* err = nullptr) const {
    const std::string command = "mpirun --oversubscribe --allow-run-as-root" + context + " > \"" +
                                path("mpi_out.txt") + "\" 2> \"" + path("mpi_err.txt") + "\"";
    const int code = cli_test::exitCode(std::system(command.c_str()));
    if (err) *err = cli_test::readFileText(path("mpi_err.txt")) + cli_test::readFileText(path("mpi_out.txt"));
    return code;
  }
  static std::string quoted(const std::string& p) { return "\"" + p + "\""; }
};

/// The values of two light fields are the same bits (bakes with --compress none: float32 values).
void expectSameValues(const std::string& a, const std::string& b) {
  const LightField x = readLightField(a), y = readLightField(b);
  ASSERT_EQ(x.charts.size(), y.charts.size());
  ASSERT_EQ(x.values.size(), y.values.size());
  ASSERT_GT(x.values.size(), 0u);
  EXPECT_EQ(x.stats.iterations, y.stats.iterations);
  size_t differing = 0;
  for (size_t i = 0; i < x.values.size(); ++i)
    differing += std::memcmp(&x.values[i], &y.values[i], sizeof(Rgb)) != 0 ? 1 : 0;
  EXPECT_EQ(differing, 0u) << "of " << x.values.size() << " values differ between " << a << " and " << b;
}

TEST_F(DistributedBake, SameBitsForTwoAndThreeRanksAndReusesShards) {
  const std::string bakeArgs = "--preset draft --tixels-across 12 --directions 64 --compress none";
  std::string err;
  // 2 threads in one process: chunks of the parallel loops differ from the ranks' parts.
  ASSERT_EQ(run("bake cornell -o " + quoted(path("one.plf")) + " " + bakeArgs + " --threads 2", nullptr, &err), 0) << err;
  for (int ranks : {2, 3}) {
    const std::string name = "ranks" + std::to_string(ranks);
    const std::string plf = path(name + ".plf"), stats = path(name + ".json");
    ASSERT_EQ(runRanks(ranks, "bake cornell -o " + quoted(plf) + " " + bakeArgs + " --stats " + quoted(stats), &err), 0)
        << err;
    expectSameValues(path("one.plf"), plf);
    // One .plv per rank, none for the whole field.
    EXPECT_FALSE(fs::exists(path(name + ".plv")));
    for (int r = 0; r < ranks; ++r)
      EXPECT_TRUE(fs::exists(path(name + ".rank" + std::to_string(r) + "-of-" + std::to_string(ranks) + ".plv"))) << r;
    std::ifstream in(stats);
    const nlohmann::json json = nlohmann::json::parse(in);
    EXPECT_EQ(json["ranks"].get<int>(), ranks);
    EXPECT_EQ(json["rank_visibility_rays"].size(), size_t(ranks));
    EXPECT_GT(json["exchange_bytes"].get<uint64_t>(), 0u);
    for (const auto& rays : json["rank_visibility_rays"]) EXPECT_GT(rays.get<uint64_t>(), 0u);
  }
  // Every rank reuses its own shard; the values stay the same bits.
  const std::string again = path("ranks2.plf"), stats = path("again.json");
  ASSERT_EQ(runRanks(2, "bake cornell -o " + quoted(again) + " " + bakeArgs + " --reuse-visibility --stats " + quoted(stats), &err), 0)
      << err;
  std::ifstream in(stats);
  const nlohmann::json json = nlohmann::json::parse(in);
  EXPECT_TRUE(json["reused_visibility"].get<bool>()) << err;
  EXPECT_EQ(json["rank_visibility_rays"][1].get<uint64_t>(), 0u);  // rank 1 traced nothing either
  expectSameValues(path("one.plf"), again);
  // Another rank count's shards do not fit 3 ranks' partition: recomputed, still the same.
  fs::copy_file(path("ranks2.rank0-of-2.plv"), path("ranks3.rank0-of-3.plv"), fs::copy_options::overwrite_existing);
  ASSERT_EQ(runRanks(3, "bake cornell -o " + quoted(path("ranks3.plf")) + " " + bakeArgs + " --reuse-visibility --stats " +
                            quoted(stats), &err), 0)
      << err;
  std::ifstream in3(stats);
  EXPECT_GT(nlohmann::json::parse(in3)["rank_visibility_rays"][0].get<uint64_t>(), 0u);
  expectSameValues(path("one.plf"), path("ranks3.plf"));
}

TEST_F(DistributedBake, GlossyChartsSameBits) {
  // Glossy charts: the partial-batch rule of gatherIteration (glossy values of the batch read
  // at their previous values) and the paraboloid values in the exchange.
  const std::string scene = quoted(std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/CornellBox-Glossy.obj");
  const std::string bakeArgs = "--preset draft --tixels-across 10 --directions 36 --compress none";
  std::string err;
  ASSERT_EQ(run("bake " + scene + " -o " + quoted(path("one.plf")) + " " + bakeArgs, nullptr, &err), 0) << err;
  ASSERT_EQ(runRanks(3, "bake " + scene + " -o " + quoted(path("three.plf")) + " " + bakeArgs, &err), 0) << err;
  expectSameValues(path("one.plf"), path("three.plf"));
}

TEST_F(DistributedBake, SubsurfaceSameBits) {
  // Subsurface charts: the operator's walks split between the ranks and exchanged, and the
  // irradiance entering each object exchanged every iteration.
  const std::string scene = quoted(std::string(PLENOPTIC_TEST_DATA_DIR) + "/../../bench/scenes/sss-cornell.json");
  const std::string bakeArgs = "--preset draft --tixels-across 8 --directions 16 --compress none";
  std::string err;
  ASSERT_EQ(run("bake " + scene + " -o " + quoted(path("one.plf")) + " " + bakeArgs, nullptr, &err), 0) << err;
  ASSERT_EQ(runRanks(2, "bake " + scene + " -o " + quoted(path("two.plf")) + " " + bakeArgs, &err), 0) << err;
  expectSameValues(path("one.plf"), path("two.plf"));
}

TEST_F(DistributedBake, RankWithDifferentSceneIsRefused) {
  // Two copies of McGuire's box, one with a comment appended: the same geometry, but not the
  // same file, so the job is refused before anything is traced.
  const std::string data = std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/";
  for (const char* file : {"CornellBox-Original.obj", "CornellBox-Original.mtl"}) fs::copy_file(data + file, path(file));
  fs::create_directory(path("b"));
  fs::copy_file(data + "CornellBox-Original.obj", path("b/CornellBox-Original.obj"));
  fs::copy_file(data + "CornellBox-Original.mtl", path("b/CornellBox-Original.mtl"));
  std::ofstream(path("b/CornellBox-Original.obj"), std::ios::app) << "# edited\n";
  const std::string plf = path("out.plf");
  const std::string args = " -o " + quoted(plf) + " --preset draft --tixels-across 8 --directions 16 --quiet --threads 1";
  const std::string program = " \"" + std::string(PLENOPTIC_BINARY) + "\" bake ";
  std::string err;
  EXPECT_NE(mpirun(" -np 1" + program + quoted(path("CornellBox-Original.obj")) + args + " : -np 1" + program +
                       quoted(path("b/CornellBox-Original.obj")) + args,
                   &err),
            0);
  EXPECT_NE(err.find("refused"), std::string::npos) << err;
  EXPECT_NE(err.find("rank(s) 1 of 2"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(plf));
  // Nothing traced: no rank wrote its visibility shard (--quiet silences the log, so look at files).
  for (const auto& entry : fs::directory_iterator(dir_)) EXPECT_NE(entry.path().extension(), ".plv") << entry.path();
  // Different flags are refused the same way.
  EXPECT_NE(mpirun(" -np 1" + program + "cornell" + args + " : -np 1" + program + "cornell" + args + " --seed 7", &err), 0);
  EXPECT_NE(err.find("refused"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(plf));
}

TEST_F(DistributedBake, FailingRankEndsTheJobWithoutAPlf) {
  const std::string plf = path("c.plf");
  const std::string args = "bake cornell -o " + quoted(plf) + " --preset draft --tixels-across 8 --directions 16";
  std::string err;
  ASSERT_EQ(runRanks(2, args, &err), 0) << err;
  const std::string before = cli_test::readFileText(fs::path(plf));
  // Rank 1's shard is damaged: it fails while rank 0 is already propagating.
  fs::resize_file(path("c.rank1-of-2.plv"), fs::file_size(path("c.rank1-of-2.plv")) - 3);
  EXPECT_NE(runRanks(2, args + " --reuse-visibility", &err), 0);
  EXPECT_NE(err.find("rank 1 of 2"), std::string::npos) << err;
  EXPECT_NE(err.find("c.rank1-of-2.plv"), std::string::npos) << err;
  EXPECT_EQ(cli_test::readFileText(fs::path(plf)), before);  // the old .plf untouched
}

}  // namespace
}  // namespace pl
