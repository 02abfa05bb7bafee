// Runs `plenoptic bake` end to end (PLENOPTIC_BINARY): the .plf and .plv it writes, --stats,
// --reuse-visibility, and how it refuses bad input.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "plf/plf_file.h"
#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

class BakeCli : public cli_test::CliTest {
 protected:
  // What bake says on stderr (e.g. "reusing" the visibility field) is tested: not --quiet.
  BakeCli() { quiet_ = false; }
};

TEST_F(BakeCli, BakesWritesStatsAndReusesVisibility) {
  const std::string plf = path("cornell.plf"), stats = path("stats.json");
  std::string out, err;
  // Small overrides keep the test fast; the flags are part of the contract.
  const std::string base = "bake cornell -o \"" + plf + "\" --preset draft --tixels-across 12";
  const std::string common = base + " --directions 64";
  ASSERT_EQ(run(common + " --stats \"" + stats + "\"", &out, &err), 0) << err;
  EXPECT_TRUE(fs::exists(plf));
  EXPECT_TRUE(fs::exists(path("cornell.plv")));  // the visibility field beside the .plf
  std::ifstream in(stats);
  const nlohmann::json json = nlohmann::json::parse(in);
  for (const char* key : {"seconds", "visibility_seconds", "propagation_seconds", "iterations", "residual", "tixels",
                          "peak_rss_bytes", "file_bytes"})
    EXPECT_TRUE(json.contains(key)) << key;
  EXPECT_EQ(json["file_bytes"].get<uint64_t>(), fs::file_size(plf));
  EXPECT_GT(json["tixels"].get<uint64_t>(), 0u);
  EXPECT_GT(json["iterations"].get<uint32_t>(), 0u);
  EXPECT_FALSE(json["reused_visibility"].get<bool>());

  const LightField lf = readLightField(plf);
  // 16 charts, 12 of them two-sided (see Parameterisation.CornellBoxCharts): 28 records.
  EXPECT_EQ(lf.charts.size(), 28u);
  EXPECT_EQ(json["two_sided_charts"].get<uint64_t>(), 12u);
  EXPECT_EQ(lf.stats.tixels, json["tixels"].get<uint64_t>());

  // Same scene and settings: the saved field is reused (and said so on stderr); propagated
  // from zero, not warm-started from the .plf at -o (BakeCli.WarmStart...).
  ASSERT_EQ(run(common + " --reuse-visibility --no-warm-start --stats \"" + stats + "\"", &out, &err), 0) << err;
  EXPECT_NE(err.find("reusing"), std::string::npos) << err;
  std::ifstream in2(stats);
  EXPECT_TRUE(nlohmann::json::parse(in2)["reused_visibility"].get<bool>());

  // Different settings: recomputed, and the message says why.
  ASSERT_EQ(run(base + " --directions 100 --reuse-visibility", &out, &err), 0) << err;
  EXPECT_NE(err.find("recomputing"), std::string::npos) << err;
}

// --punctual-highlights on|off is recorded in the light field's bake settings (what the
// renderers go by: lightfield.h "Punctual highlights"); on by default; other values refused.
TEST_F(BakeCli, PunctualHighlightsAreABakeOption) {
  std::string out, err;
  const std::string common = "bake cornell --preset draft --tixels-across 8 --directions 16 --quiet -o \"";
  ASSERT_EQ(run(common + path("on.plf") + "\"", &out, &err), 0) << err;
  EXPECT_TRUE(readLightField(path("on.plf")).settings.punctualHighlights);
  ASSERT_EQ(run(common + path("off.plf") + "\" --punctual-highlights off", &out, &err), 0) << err;
  EXPECT_FALSE(readLightField(path("off.plf")).settings.punctualHighlights);
  EXPECT_EQ(run(common + path("x.plf") + "\" --punctual-highlights maybe", &out, &err), 2);
  EXPECT_NE(err.find("--punctual-highlights"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("x.plf")));
}

// --caustic-photons N is recorded in the bake settings (the preset's count by default); the
// built-in box has no mirror or glass, so no photon is shot whatever N; a negative count is refused.
TEST_F(BakeCli, CausticPhotonsAreABakeOption) {
  std::string out, err;
  const std::string common = "bake cornell --preset draft --tixels-across 8 --directions 16 --quiet -o \"";
  ASSERT_EQ(run(common + path("preset.plf") + "\"", &out, &err), 0) << err;
  EXPECT_EQ(readLightField(path("preset.plf")).settings.causticPhotons, uint64_t(1) << 20);
  ASSERT_EQ(run(common + path("n.plf") + "\" --caustic-photons 1000 --stats \"" + path("n.json") + "\"", &out, &err), 0)
      << err;
  const LightField lf = readLightField(path("n.plf"));
  EXPECT_EQ(lf.settings.causticPhotons, 1000u);
  EXPECT_EQ(lf.stats.causticPhotons, 0u);
  std::ifstream in(path("n.json"));
  EXPECT_EQ(nlohmann::json::parse(in)["caustic_photons"].get<uint64_t>(), 0u);
  EXPECT_EQ(run(common + path("x.plf") + "\" --caustic-photons -1", &out, &err), 2);
  EXPECT_NE(err.find("--caustic-photons"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("x.plf")));
}

// A subsurface scene bakes (the bake says what its operator took), --subsurface-walks N
// overrides the preset's walks per tixel area (recorded in the bake settings), and values
// outside [1, 65536] are refused before anything is written.
TEST_F(BakeCli, BakesSubsurfaceScenesWithSubsurfaceWalks) {
  std::string out, err;
  const std::string scene = std::string(PLENOPTIC_TEST_DATA_DIR) + "/../../bench/scenes/sss-cornell.json";
  const std::string common = "bake \"" + scene + "\" --preset draft --tixels-across 8 --directions 16 -o \"";
  ASSERT_EQ(run(common + path("preset.plf") + "\" --quiet", &out, &err), 0) << err;
  EXPECT_EQ(readLightField(path("preset.plf")).settings.subsurfaceWalks, 128u);
  ASSERT_EQ(run(common + path("n.plf") + "\" --subsurface-walks 8", &out, &err), 0) << err;
  EXPECT_NE(err.find("subsurface: "), std::string::npos) << err;
  EXPECT_EQ(readLightField(path("n.plf")).settings.subsurfaceWalks, 8u);
  EXPECT_EQ(run(common + path("x.plf") + "\" --subsurface-walks 0", &out, &err), 2);
  EXPECT_NE(err.find("--subsurface-walks"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("x.plf")));
}

// --glossy-res N caps the glossy maps at N² texels instead of the preset's (recorded in the
// bake settings); values outside [2, 256] are refused before anything is written.
TEST_F(BakeCli, GlossyResOverridesThePresetsCap) {
  std::string out, err;
  const std::string common = "bake cornell --preset draft --tixels-across 8 --directions 16 --quiet -o \"";
  ASSERT_EQ(run(common + path("g.plf") + "\" --glossy-res 12", &out, &err), 0) << err;
  EXPECT_EQ(readLightField(path("g.plf")).settings.glossyDirRes, 12u);
  ASSERT_EQ(run(common + path("d.plf") + "\"", &out, &err), 0) << err;
  EXPECT_EQ(readLightField(path("d.plf")).settings.glossyDirRes, 8u);
  EXPECT_EQ(run(common + path("x.plf") + "\" --glossy-res 1", &out, &err), 2);
  EXPECT_NE(err.find("--glossy-res"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(path("x.plf")));
}

// bake --reuse-visibility with the previous light field at -o: relit for what changed (said on
// stderr and in --stats); what relighting does not serve, --no-warm-start and a damaged
// --warm-start file fall back to propagating from zero, with the reason.
TEST_F(BakeCli, WarmStartsFromThePreviousLightField) {
  const std::string plf = path("box.plf"), scene = path("box.json"), stats = path("stats.json");
  auto writeScene = [&](const std::string& red) {
    std::ofstream(scene) << "{\"include_cornell\": true, \"materials\": {\"red\": " << red << "}}";
  };
  auto statsJson = [&] {
    std::ifstream in(stats);
    return nlohmann::json::parse(in);
  };
  const std::string bake = "bake \"" + scene + "\" -o \"" + plf + "\" --preset draft --tixels-across 12 --directions 64 --stats \"" + stats + "\"";
  std::string out, err;
  writeScene("{\"type\": \"lambert\", \"albedo\": [0.57, 0.043, 0.044]}");
  ASSERT_EQ(run(bake, &out, &err), 0) << err;
  EXPECT_FALSE(statsJson()["warm_start"].get<bool>());
  EXPECT_NE(statsJson()["warm_start_reason"].get<std::string>().find("--reuse-visibility"), std::string::npos);

  // The red wall's albedo changed: warm-started.
  writeScene("{\"type\": \"lambert\", \"albedo\": [0.2, 0.5, 0.7]}");
  ASSERT_EQ(run(bake + " --reuse-visibility", &out, &err), 0) << err;
  EXPECT_NE(err.find("warm start: relit"), std::string::npos) << err;
  nlohmann::json json = statsJson();
  EXPECT_TRUE(json["warm_start"].get<bool>());
  EXPECT_EQ(json["warm_start_reason"].get<std::string>(), "");
  EXPECT_TRUE(json["reused_visibility"].get<bool>());
  EXPECT_EQ(readLightField(plf).scene.materials[1].name, "red");

  // --no-warm-start: propagated from zero.
  ASSERT_EQ(run(bake + " --reuse-visibility --no-warm-start", &out, &err), 0) << err;
  EXPECT_EQ(statsJson()["warm_start_reason"].get<std::string>(), "--no-warm-start");
  EXPECT_NE(run(bake + " --warm-start \"" + plf + "\" --no-warm-start", &out, &err), 0);
  EXPECT_NE(err.find("contradict"), std::string::npos) << err;

  // A change relighting refuses: the wall turned glossy.
  writeScene("{\"type\": \"ggx\", \"diffuse\": 0.5, \"f0\": 0.04, \"roughness\": 0.5}");
  ASSERT_EQ(run(bake + " --reuse-visibility", &out, &err), 0) << err;
  EXPECT_NE(err.find("warm start: not used, because"), std::string::npos) << err;
  json = statsJson();
  EXPECT_FALSE(json["warm_start"].get<bool>());
  EXPECT_NE(json["warm_start_reason"].get<std::string>().find("cannot relight"), std::string::npos) << json.dump();

  // A damaged previous light field named by --warm-start (which implies --reuse-visibility).
  std::ofstream(path("damaged.plf"), std::ios::binary) << "PLF not really";
  ASSERT_EQ(run(bake + " --warm-start \"" + path("damaged.plf") + "\"", &out, &err), 0) << err;
  json = statsJson();
  EXPECT_FALSE(json["warm_start"].get<bool>());
  EXPECT_TRUE(json["reused_visibility"].get<bool>());
  EXPECT_NE(json["warm_start_reason"].get<std::string>().find("damaged.plf"), std::string::npos) << json.dump();
}

TEST_F(BakeCli, RefusesBadInput) {
  std::string out, err;
  EXPECT_NE(run("bake \"" + path("missing.obj") + "\" -o \"" + path("x.plf") + "\"", &out, &err), 0);
  EXPECT_NE(err.find("missing.obj"), std::string::npos) << err;
  EXPECT_NE(run("bake cornell -o \"" + path("no/such/dir/x.plf") + "\"", &out, &err), 0);
  EXPECT_NE(err.find("does not exist"), std::string::npos) << err;
  EXPECT_NE(run("bake cornell -o \"" + path("x.plf") + "\" --preset ultra", &out, &err), 0);
  EXPECT_FALSE(fs::exists(path("x.plf")));
  // A corrupt visibility field is an error, not a silent recompute.
  const std::string plf = path("c.plf");
  const std::string common = "bake cornell -o \"" + plf + "\" --preset draft --tixels-across 8 --directions 16 --quiet";
  ASSERT_EQ(run(common, &out, &err), 0) << err;
  fs::resize_file(path("c.plv"), fs::file_size(path("c.plv")) - 3);
  EXPECT_NE(run(common + " --reuse-visibility", &out, &err), 0);
  EXPECT_NE(err.find("c.plv"), std::string::npos) << err;
}

TEST_F(BakeCli, InfoShowsAVisibilityFieldsBytesPerEntry) {
  std::string out, err;
  const std::string plv = path("v.plv");
  ASSERT_EQ(run("bake cornell -o \"" + path("v.plf") + "\" --preset draft --tixels-across 8 --directions 16 --quiet", &out, &err), 0)
      << err;
  ASSERT_EQ(run("info \"" + plv + "\"", &out, &err), 0) << err;
  EXPECT_NE(out.find("plenoptic visibility field, format version 6"), std::string::npos) << out;
  EXPECT_NE(out.find("fractions    2 bits each (compact, quantised)"), std::string::npos) << out;
  EXPECT_NE(out.find("× 16 gather directions"), std::string::npos) << out;
  EXPECT_NE(out.find(" bytes per entry; the encoded entries alone "), std::string::npos) << out;
  ASSERT_EQ(run("info --json \"" + plv + "\"", &out, &err), 0) << err;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["gather_directions"], 16);
  EXPECT_GT(j["memory_bytes_per_entry"].get<double>(), 0.25);  // at least the tags
  EXPECT_LT(j["memory_bytes_per_entry"].get<double>(), 8.0);
  EXPECT_EQ(j["entries"].get<uint64_t>(), j["tixels"].get<uint64_t>() * 16);
  EXPECT_EQ(j["fraction_bits"], 2);  // the default, compact
  // An older version is named as such; damage is an error naming the file.
  std::string bytes;
  {
    std::ifstream in(plv, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  bytes[8] = 3;
  {
    std::ofstream o(path("old.plv"), std::ios::binary);
    o << bytes;
  }
  ASSERT_EQ(run("info \"" + path("old.plv") + "\"", &out, &err), 0) << err;
  EXPECT_NE(out.find("format       older than this program's version 6: a bake traces the field again"), std::string::npos)
      << out;
  fs::resize_file(plv, fs::file_size(plv) - 3);
  EXPECT_EQ(run("info \"" + plv + "\"", &out, &err), 1);
  EXPECT_NE(err.find("v.plv: corrupt or truncated visibility field"), std::string::npos) << err;
}

// The light field of a .plf, bit for bit (VALS; the bakes write float32 values, --compress none).
bool sameValues(const std::string& a, const std::string& b) {
  const LightField x = readLightField(a), y = readLightField(b);
  return x.values.size() == y.values.size() &&
         std::memcmp(x.values.data(), y.values.data(), x.values.size() * sizeof(Rgb)) == 0;
}

// A bake stopped after a few traced blocks, or after a few iterations (the test hooks end the
// process at once, as a kill would), resumes automatically where it stopped, says so, and
// writes the uninterrupted bake's light field; the scratch files go once it is written.
// --fresh ignores them; other settings are not resumed, and the reason is given.
TEST_F(BakeCli, ResumesABakeStoppedWhileTracingOrPropagating) {
  std::string out, err;
  const std::string settings = " --preset draft --tixels-across 12 --directions 64 --compress none";
  ASSERT_EQ(run("bake cornell -o \"" + path("ref.plf") + "\"" + settings + " --quiet", &out, &err), 0) << err;
  const std::string plf = path("a.plf"), plv = path("a.plv");
  const std::string partial = plv + ".partial", checkpoint = plv + ".checkpoint";
  const std::string bake = "bake cornell -o \"" + plf + "\"" + settings;
  auto stopped = [&](const std::string& hook, const std::string& extra = "") {
    return cli_test::runPlenoptic(bake + extra + " --quiet", dir_, &out, &err, hook);
  };

  // Stopped while tracing: only the partial field is left; the next bake resumes it.
  EXPECT_EQ(stopped("PLENOPTIC_TEST_STOP_AFTER_BLOCKS=3"), 1) << err;
  EXPECT_FALSE(fs::exists(plf));
  EXPECT_FALSE(fs::exists(plv));
  EXPECT_TRUE(fs::exists(partial));
  ASSERT_EQ(run(bake, &out, &err), 0) << err;
  EXPECT_NE(err.find("visibility: resuming the interrupted trace in " + partial + ": "), std::string::npos) << err;
  EXPECT_TRUE(sameValues(plf, path("ref.plf")));
  EXPECT_FALSE(fs::exists(partial));
  EXPECT_FALSE(fs::exists(checkpoint));

  // Stopped while propagating: the field is complete, the checkpoint holds iteration 2.
  fs::remove(plf);
  EXPECT_EQ(stopped("PLENOPTIC_TEST_STOP_AFTER_ITERATIONS=2"), 1) << err;
  EXPECT_FALSE(fs::exists(plf));
  EXPECT_TRUE(fs::exists(checkpoint));
  ASSERT_EQ(run(bake, &out, &err), 0) << err;
  EXPECT_NE(err.find("propagation: resuming the interrupted bake from " + checkpoint + " after iteration 2"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("visibility: "), std::string::npos) << err;  // nothing traced
  EXPECT_TRUE(sameValues(plf, path("ref.plf")));
  EXPECT_FALSE(fs::exists(checkpoint));

  // --fresh: the checkpoint is ignored (and said so), the bake is the same.
  EXPECT_EQ(stopped("PLENOPTIC_TEST_STOP_AFTER_ITERATIONS=1"), 1) << err;
  ASSERT_EQ(run(bake + " --fresh", &out, &err), 0) << err;
  EXPECT_NE(err.find("propagation: ignoring the checkpoint " + checkpoint + " (--fresh)"), std::string::npos) << err;
  EXPECT_TRUE(sameValues(plf, path("ref.plf")));
  EXPECT_FALSE(fs::exists(checkpoint));

  // Other settings: neither the partial field nor the checkpoint is resumed, and the log says why.
  EXPECT_EQ(stopped("PLENOPTIC_TEST_STOP_AFTER_BLOCKS=2", " --visibility \"" + path("b.plv") + "\""), 1) << err;
  const std::string otherDirections = "bake cornell -o \"" + plf + "\" --preset draft --tixels-across 12 --directions 100";
  ASSERT_EQ(run(otherDirections + " --visibility \"" + path("b.plv") + "\"", &out, &err), 0) << err;
  EXPECT_NE(err.find("visibility: tracing afresh, because " + path("b.plv") + ".partial was traced for different "
                     "geometry, parameterisation or settings"),
            std::string::npos)
      << err;
  EXPECT_EQ(stopped("PLENOPTIC_TEST_STOP_AFTER_ITERATIONS=1"), 1) << err;
  ASSERT_EQ(run(bake + " --tolerance 0.01", &out, &err), 0) << err;
  EXPECT_NE(err.find("propagation: not resuming from " + checkpoint + ", because"), std::string::npos) << err;
  EXPECT_NE(err.find("another scene, other settings"), std::string::npos) << err;
}

// A real SIGKILL (fork + exec, killed once the bake has saved some of its work, while it
// traces or propagates): the next bake resumes and writes the uninterrupted light field.
TEST_F(BakeCli, ResumesAfterSigkill) {
  std::string out, err;
  const std::string settings = " --preset draft --tixels-across 20 --directions 144 --compress none";
  ASSERT_EQ(run("bake cornell -o \"" + path("ref.plf") + "\"" + settings + " --quiet", &out, &err), 0) << err;
  const std::string plf = path("k.plf"), partial = path("k.plv.partial"), checkpoint = path("k.plv.checkpoint");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execl(PLENOPTIC_BINARY, "plenoptic", "bake", "cornell", "-o", plf.c_str(), "--preset", "draft", "--tixels-across",
            "20", "--directions", "144", "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  bool killed = false;
  for (int polls = 0; polls < 120000 && !killed; ++polls) {
    std::error_code ec;
    if ((fs::exists(partial, ec) && fs::file_size(partial, ec) > 20000) || fs::exists(checkpoint, ec)) {
      killed = ::kill(pid, SIGKILL) == 0;
      break;
    }
    if (::waitpid(pid, &status, WNOHANG) == pid) break;  // finished before any work was saved
    ::usleep(500);
  }
  if (killed) {
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status) || WIFEXITED(status));
  }
  ASSERT_TRUE(killed) << "the bake ended before it could be killed";
  EXPECT_FALSE(fs::exists(plf));
  ASSERT_EQ(run("bake cornell -o \"" + plf + "\"" + settings, &out, &err), 0) << err;
  EXPECT_NE(err.find("resuming the interrupted"), std::string::npos) << err;
  EXPECT_TRUE(sameValues(plf, path("ref.plf")));
}

// --visibility-memory streamed: the field is written to the .plv as it is traced and the
// propagation reads it from there, a block at a time; the .plv and the light field are the held
// bake's bit for bit, also when the bake resumes a stopped trace or reuses the saved field.
// auto streams when holding the field does not fit --max-memory (and a bake that cannot even
// stream is refused); --stats says which mode ran.
TEST_F(BakeCli, StreamedVisibilityFieldGivesTheHeldBakesBits) {
  std::string out, err;
  // 256 directions: 256 tixels per .plv block, so the field spans some thirty blocks.
  const std::string settings = " --preset draft --directions 256 --compress none --threads 2";
  const std::string held = path("held.plf"), streamed = path("streamed.plf");
  auto mode = [&](const std::string& stats) {
    std::ifstream in(stats);
    return nlohmann::json::parse(in)["visibility_memory"].get<std::string>();
  };
  auto bytes = [](const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  ASSERT_EQ(run("bake cornell -o \"" + held + "\"" + settings + " --stats \"" + path("h.json") + "\"", &out, &err), 0)
      << err;
  EXPECT_EQ(mode(path("h.json")), "held");
  const std::string bake = "bake cornell -o \"" + streamed + "\"" + settings;
  ASSERT_EQ(run(bake + " --visibility-memory streamed --stats \"" + path("s.json") + "\"", &out, &err), 0) << err;
  EXPECT_NE(err.find("visibility: streamed from " + path("streamed.plv")), std::string::npos) << err;
  EXPECT_EQ(mode(path("s.json")), "streamed");
  EXPECT_TRUE(sameValues(streamed, held));
  EXPECT_EQ(bytes(path("streamed.plv")), bytes(path("held.plv")));

  // Reused, streamed: read from the .plv without holding its entries (propagated from zero, not
  // warm-started from the light field at -o, so that the field is read).
  ASSERT_EQ(run(bake + " --visibility-memory streamed --reuse-visibility --no-warm-start", &out, &err), 0) << err;
  EXPECT_NE(err.find("visibility: reusing " + path("streamed.plv")), std::string::npos) << err;
  EXPECT_TRUE(sameValues(streamed, held));

  // A trace stopped after a few blocks resumes streamed: the restored blocks are written first.
  fs::remove(path("streamed.plv"));
  EXPECT_EQ(cli_test::runPlenoptic(bake + " --visibility-memory streamed --quiet", dir_, &out, &err,
                                   "PLENOPTIC_TEST_STOP_AFTER_BLOCKS=5"),
            1)
      << err;
  EXPECT_FALSE(fs::exists(path("streamed.plv")));  // no half-written .plv
  ASSERT_EQ(run(bake + " --visibility-memory streamed", &out, &err), 0) << err;
  EXPECT_NE(err.find("visibility: resuming the interrupted trace"), std::string::npos) << err;
  EXPECT_TRUE(sameValues(streamed, held));
  EXPECT_EQ(bytes(path("streamed.plv")), bytes(path("held.plv")));

  // auto: a --max-memory that the held field's estimate exceeds but the streamed one's does
  // not (the held estimate counts the .plv writer's batch of 16 blocks) streams; held is refused.
  ASSERT_EQ(run(bake + " --max-memory 20M --stats \"" + path("a.json") + "\"", &out, &err), 0) << err;
  EXPECT_NE(err.find("visibility: streamed from " + path("streamed.plv") + ", because holding it would take the bake to"),
            std::string::npos)
      << err;
  EXPECT_EQ(mode(path("a.json")), "streamed");
  EXPECT_TRUE(sameValues(streamed, held));
  EXPECT_EQ(run(bake + " --max-memory 20M --visibility-memory held", &out, &err), 1) << err;
  EXPECT_NE(err.find("exceeds --max-memory 0.02 GiB"), std::string::npos) << err;
  // Streaming needs a .plv: Python's bake without a visibility path cannot (tested there); a bad mode is a usage error.
  EXPECT_NE(run(bake + " --visibility-memory sometimes", &out, &err), 0);
  EXPECT_NE(err.find("--visibility-memory"), std::string::npos) << err;
}

TEST_F(BakeCli, MaxMemoryCapsTheMemoryGuard) {
  std::string out, err;
  const std::string plf = path("m.plf");
  const std::string common = "bake cornell -o \"" + plf + "\" --preset draft --tixels-across 8 --directions 16 --quiet";
  // A cap far below the bake's estimate: refused before any output, naming estimate, cap and flags.
  EXPECT_EQ(run(common + " --max-memory 1M", &out, &err), 1) << err;
  EXPECT_NE(err.find("bake (visibility field and light-field values): estimated memory "), std::string::npos) << err;
  EXPECT_NE(err.find("exceeds --max-memory 0.00 GiB; lower --preset, --tixels-across or --directions"), std::string::npos)
      << err;
  EXPECT_FALSE(fs::exists(plf));
  EXPECT_FALSE(fs::exists(path("m.plv")));
  // A cap above it: baked.
  EXPECT_EQ(run(common + " --max-memory 1G", &out, &err), 0) << err;
  EXPECT_TRUE(fs::exists(plf));
  // Not a size: a usage error naming the flag.
  EXPECT_NE(run(common + " --max-memory lots", &out, &err), 0);
  EXPECT_NE(err.find("--max-memory: 'lots' is not a memory size"), std::string::npos) << err;
}

}  // namespace
}  // namespace pl
