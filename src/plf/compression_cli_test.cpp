// Runs `plenoptic bake --compress`, `compress`, `info` and `render` end to end
// (PLENOPTIC_BINARY): every mode is written, reported and rendered; lossless round trips are
// bit-exact through the whole program; bad modes and corrupt compressed files end in a clear
// error (exit status 1, the file and section named), never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "plf/compression.h"
#include "plf/plf_file.h"
#include "support/cli_test_support.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

class CompressCli : public cli_test::CliTest {
 protected:
  /// A small Cornell-box bake (draft preset, coarse overrides keep it around a second);
  /// `mode` empty: bake's default.
  void bake(const std::string& output, const std::string& mode) const {
    std::string err;
    ASSERT_EQ(run("bake cornell -o \"" + output + "\" --preset draft --tixels-across 16 --directions 64" +
                      (mode.empty() ? "" : " --compress " + mode) + " --quiet",
                  nullptr, &err),
              0)
        << err;
  }
};

/// The exit status of a command that must fail cleanly: it exited (no signal) with 1.
void expectCleanFailure(int status) {
  ASSERT_NE(status, -1) << "terminated by a signal: a crash";
  EXPECT_EQ(status, 1);
}

TEST_F(CompressCli, BakeCompressInfoAndRenderEveryMode) {
  const std::string raw = path("raw.plf");
  bake(raw, "none");
  const LightField original = readLightField(raw);
  for (const std::string mode : {"lossless", "bc1", "hdr"}) {
    SCOPED_TRACE(mode);
    // The same bake written compressed by `bake --compress` (deterministic: same seed).
    const std::string baked = path("baked-" + mode + ".plf");
    bake(baked, mode);
    std::string out, err;
    ASSERT_EQ(run("info --json \"" + baked + "\"", &out, &err), 0) << err;
    const nlohmann::json info = nlohmann::json::parse(out);
    EXPECT_EQ(info["compression"]["mode"], mode);
    EXPECT_EQ(info["compression"]["values_decoded_bytes"], original.values.size() * sizeof(Rgb));
    EXPECT_GT(info["compression"]["ratio"].get<double>(), 1.0);
    EXPECT_TRUE(info["checksums_verified"].get<bool>());

    // `compress` of the raw file gives the same values section as `bake --compress`.
    const std::string recompressed = path("re-" + mode + ".plf"), stats = path("stats-" + mode + ".json");
    ASSERT_EQ(run("compress \"" + raw + "\" -o \"" + recompressed + "\" --mode " + mode + " --stats \"" + stats +
                      "\" --quiet",
                  &out, &err),
              0)
        << err;
    std::ifstream statsFile(stats);
    const nlohmann::json json = nlohmann::json::parse(statsFile);
    EXPECT_EQ(json["mode"], mode);
    EXPECT_EQ(json["input_mode"], "none");
    EXPECT_EQ(json["bit_exact"].get<bool>(), mode == "lossless");
    for (const char* key : {"file_bytes", "values_ratio", "encode_write_seconds", "decode_read_seconds",
                            "values_relative_rmse", "values_max_relative_error"})
      EXPECT_TRUE(json.contains(key)) << key;
    const LightField a = readLightField(baked), b = readLightField(recompressed);
    ASSERT_EQ(a.values.size(), b.values.size());
    EXPECT_EQ(std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(Rgb)), 0);

    // Every renderer path reads it (decoding happens in readLightField).
    ASSERT_EQ(run("render \"" + baked + "\" -o \"" + path("r-" + mode + ".pfm") + "\" --width 64 --height 48 --quiet",
                  nullptr, &err),
              0)
        << err;
  }
}

// A bake writes hdr values (64 steps per stop) and zstd sections unless told otherwise: every
// value within the codes' bound of the float32 bake's, zeros exact, and the renders within the
// relMSE bound the default was chosen under (1e-5; measured about 1e-6 and below,
// docs/benchmarks.md "Light-field compression").
TEST_F(CompressCli, DefaultBakeIsHdrWithinItsBoundAndZstdSections) {
  const std::string raw = path("raw.plf"), plain = path("default.plf");
  bake(raw, "none");
  bake(plain, "");
  const PlfInfo info = readLightFieldInfo(plain);
  for (const PlfSectionInfo& s : info.sections) {
    const uint32_t expected = s.id == "VALS" ? uint32_t(kDefaultValuesCodec) : s.id == "META" ? 0u : kPlfSectionZstd;
    EXPECT_EQ(s.encoding, expected) << s.id;
  }
  for (const PlfSectionInfo& s : readLightFieldInfo(raw).sections) EXPECT_EQ(s.encoding, 0u) << s.id;
  EXPECT_LT(fs::file_size(plain) * 3, fs::file_size(raw));
  const LightField a = readLightField(plain), b = readLightField(raw);
  ASSERT_EQ(a.values.size(), b.values.size());
  const double bound = std::exp2(1.0 / (2.0 * ValuesCodecOptions{}.hdrStepsPerStop)) - 1.0;
  double worst = 0.0;
  for (size_t i = 0; i < a.values.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float x = (&b.values[i].r)[c], y = (&a.values[i].r)[c];
      if (x == 0.0f) EXPECT_EQ(y, 0.0f);
      else worst = std::max(worst, std::abs(double(y) - x) / std::abs(double(x)));
    }
  EXPECT_GT(worst, 0.0);
  EXPECT_LE(worst, bound + 1e-6);
  std::string err;
  for (const auto& [file, image] : {std::pair{raw, path("raw.pfm")}, std::pair{plain, path("default.pfm")}})
    ASSERT_EQ(run("render \"" + file + "\" -o \"" + image + "\" --width 64 --height 48 --spp 4 --quiet", nullptr, &err), 0)
        << err;
  EXPECT_EQ(run("compare \"" + path("default.pfm") + "\" \"" + path("raw.pfm") + "\" --max-relmse 1e-5 --quiet", nullptr,
                &err),
            0)
      << err;
}

TEST_F(CompressCli, LosslessRoundTripsThroughTheProgramAndInPlace) {
  const std::string raw = path("raw.plf"), hdr = path("hdr.plf");
  bake(raw, "none");
  std::string err;
  ASSERT_EQ(run("compress \"" + raw + "\" -o \"" + hdr + "\" --mode hdr --quiet", nullptr, &err), 0) << err;
  const LightField hdrValues = readLightField(hdr);
  // hdr → lossless in place (atomic rename over the input) → none: the hdr-decoded values
  // survive both steps bit for bit.
  ASSERT_EQ(run("compress \"" + hdr + "\" -o \"" + hdr + "\" --mode lossless --quiet", nullptr, &err), 0) << err;
  EXPECT_EQ(readLightFieldInfo(hdr).sections[3].encoding, uint32_t(ValuesCodec::Lossless));
  const std::string back = path("back.plf");
  ASSERT_EQ(run("compress \"" + hdr + "\" -o \"" + back + "\" --mode none --quiet", nullptr, &err), 0) << err;
  const LightField final = readLightField(back);
  ASSERT_EQ(final.values.size(), hdrValues.values.size());
  EXPECT_EQ(std::memcmp(final.values.data(), hdrValues.values.data(), final.values.size() * sizeof(Rgb)), 0);
  EXPECT_EQ(fs::file_size(back), fs::file_size(raw));  // raw again: same layout, same size
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << "left behind: " << entry.path();
}

TEST_F(CompressCli, BadModesAndCorruptFilesFailCleanly) {
  const std::string raw = path("raw.plf"), out = path("out.plf");
  bake(raw, "none");
  std::string err;
  const int badMode = run("compress \"" + raw + "\" -o \"" + out + "\" --mode dxt5", nullptr, &err);
  ASSERT_NE(badMode, -1) << "terminated by a signal: a crash";
  EXPECT_NE(badMode, 0);
  EXPECT_NE(err.find("dxt5"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(out));
  const int badBake = run("bake cornell -o \"" + out + "\" --compress zip --quiet", nullptr, &err);
  ASSERT_NE(badBake, -1) << "terminated by a signal: a crash";
  EXPECT_NE(badBake, 0);
  EXPECT_FALSE(fs::exists(out));
  // --stats into a missing directory: refused before any work, nothing written.
  expectCleanFailure(run("compress \"" + raw + "\" -o \"" + out + "\" --stats \"" + path("no/such/dir/s.json") + "\"",
                         nullptr, &err));
  EXPECT_NE(err.find("--stats"), std::string::npos) << err;
  EXPECT_NE(err.find("does not exist"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(out));

  // A compressed file with damaged values (checksums re-sealed by hand would be the
  // codec's job, tested in compression_test; here the file's own checksum names it) and a
  // truncated one: render and info fail with the file and the values section named.
  const std::string lossless = path("lossless.plf");
  ASSERT_EQ(run("compress \"" + raw + "\" -o \"" + lossless + "\" --mode lossless --quiet", nullptr, &err), 0) << err;
  const PlfInfo info = readLightFieldInfo(lossless);
  const PlfSectionInfo& values = info.sections[3];
  ASSERT_EQ(values.id, "VALS");
  std::string bytes;
  {
    std::ifstream in(lossless, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::string flipped = bytes;
  flipped[values.offset + values.storedSize / 2] ^= 0x40;
  std::string truncated = bytes.substr(0, values.offset + values.storedSize / 3);
  for (const auto& [name, content] : {std::pair{"flipped.plf", flipped}, std::pair{"truncated.plf", truncated}}) {
    const std::string file = path(name);
    std::ofstream(file, std::ios::binary) << content;
    for (const std::string& command : {"render \"" + file + "\" -o \"" + path("x.png") + "\" --width 8 --height 8",
                                      "info \"" + file + "\""}) {
      const int status = run(command, nullptr, &err);
      expectCleanFailure(status);
      EXPECT_NE(err.find(file), std::string::npos) << err;
      EXPECT_NE(err.find("VALS"), std::string::npos) << err;
    }
  }
}

}  // namespace
}  // namespace pl
