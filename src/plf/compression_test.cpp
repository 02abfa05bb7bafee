// Tests of the light-field value codecs (compression.h): bit-exact lossless round trips
// (special floats included), the error bounds of the lossy codecs, their ratios on smooth
// data, and corrupt or truncated streams (a pl::Error naming the context, never a crash);
// then the same through .plf files (writeLightField / readLightField / readLightFieldInfo).
#include "plf/compression.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <utility>
#include <cstdlib>

#include "core/error.h"
#include "core/hash.h"
#include "plf/plf_file.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

/// Charts exercising every layout case: a diffuse grid whose sides are not multiples of 4,
/// a glossy chart with dirRes 8 (whole BC1 blocks per direction), a glossy chart with
/// dirRes 3 and a diffuse value after each tixel's map (Chart::diffuseValue), a specular chart (no values) and values that no chart covers (a gap and a tail).
std::vector<Chart> makeCharts(uint64_t& valueCount) {
  Chart diffuse;
  diffuse.kind = ChartKind::Diffuse;
  diffuse.resU = 13;
  diffuse.resV = 7;
  diffuse.dirRes = 1;
  diffuse.firstValue = 0;
  Chart glossy8 = diffuse;
  glossy8.kind = ChartKind::Glossy;
  glossy8.resU = 5;
  glossy8.resV = 6;
  glossy8.dirRes = 8;
  glossy8.firstValue = 13 * 7 + 5;  // a gap of 5 uncovered values
  Chart specular = diffuse;
  specular.kind = ChartKind::Specular;
  specular.dirRes = 0;
  Chart glossy3 = glossy8;
  glossy3.resU = 2;
  glossy3.resV = 9;
  glossy3.dirRes = 3;
  glossy3.diffuseValue = true;  // 9 + 1 values per tixel
  glossy3.firstValue = glossy8.firstValue + 5 * 6 * 64;
  valueCount = glossy3.firstValue + 2 * 9 * 10 + 11;  // an uncovered tail of 11
  return {diffuse, glossy8, specular, glossy3};
}

/// Smooth radiance over 7 decades with 0.3 % multiplicative noise, like a converged bake:
/// value(i) depends smoothly on the value index inside a chart's image layout because the
/// index is a smooth function of (tixel, direction) there.
std::vector<Rgb> makeSmoothValues(const std::vector<Chart>& charts, uint64_t valueCount, double noise = 0.003) {
  std::vector<Rgb> values(valueCount, Rgb(0.25f, 0.5f, 0.125f));
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (const Chart& c : charts) {
    for (uint32_t j = 0; j < c.resV; ++j)
      for (uint32_t i = 0; i < c.resU; ++i)
        for (uint32_t t = 0; t < c.dirRes; ++t)
          for (uint32_t s = 0; s < c.dirRes; ++s) {
            const double u = (i + 0.5) / c.resU, v = (j + 0.5) / c.resV;
            const double lobe = std::exp(-4.0 * (std::pow(s - 0.5 * c.dirRes, 2) + std::pow(t - 0.5 * c.dirRes, 2)) /
                                         double(c.dirRes * c.dirRes + 1));
            const double base = std::pow(10.0, -3.0 + 4.0 * u * v) * (0.2 + lobe);
            auto n = [&] { return 1.0 + noise * gauss(rng); };
            values[c.valueIndex(i, j, s, t)] =
                Rgb(float(base * 0.9 * n()), float(base * 0.7 * n()), float(base * 0.4 * n()));
          }
    if (c.diffuseValue)
      for (uint32_t j = 0; j < c.resV; ++j)
        for (uint32_t i = 0; i < c.resU; ++i)
          values[c.diffuseValueIndex(i, j)] = Rgb(float(2.0 + 0.1 * i), float(1.5 + 0.1 * j), 1.0f);
  }
  values[3] = Rgb(0.0f);  // exact zeros must stay zero in every codec
  return values;
}

uint64_t rawBytes(const std::vector<Rgb>& values) { return values.size() * sizeof(Rgb); }

/// PSNR (dB) of decoded against original values after the tone mapping (x / max)^(1/2.2)
/// with the largest original component as max (peak 1).
double toneMappedPsnr(const std::vector<Rgb>& original, const std::vector<Rgb>& decoded) {
  double maxValue = 0.0, squared = 0.0;
  for (const Rgb& v : original) maxValue = std::max({maxValue, double(v.r), double(v.g), double(v.b)});
  for (size_t i = 0; i < original.size(); ++i) {
    const double o[3] = {original[i].r, original[i].g, original[i].b};
    const double d[3] = {decoded[i].r, decoded[i].g, decoded[i].b};
    for (int c = 0; c < 3; ++c) {
      const double a = std::pow(std::max(o[c], 0.0) / maxValue, 1 / 2.2), b = std::pow(std::max(d[c], 0.0) / maxValue, 1 / 2.2);
      squared += (a - b) * (a - b);
    }
  }
  return -10.0 * std::log10(squared / (3.0 * double(original.size())));
}

TEST(ValuesCodec, NamesRoundTripAndUnknownIsRefused) {
  for (ValuesCodec c : {ValuesCodec::Raw, ValuesCodec::Lossless, ValuesCodec::Bc1, ValuesCodec::Hdr})
    EXPECT_EQ(parseValuesCodec(valuesCodecName(c)), c);
  EXPECT_THROW(parseValuesCodec("dxt5"), Error);
  EXPECT_TRUE(isKnownValuesCodec(3));
  EXPECT_FALSE(isKnownValuesCodec(4));
}

TEST(ValuesCodec, LosslessIsBitExactForEveryFloat) {
  uint64_t count = 0;
  const std::vector<Chart> charts = makeCharts(count);
  std::vector<Rgb> values = makeSmoothValues(charts, count);
  // Special bit patterns anywhere in the layout: signed zeros, denormals, infinities, NaNs
  // with payloads, negative values, the extremes.
  const float specials[] = {-0.0f,
                            std::numeric_limits<float>::denorm_min(),
                            -std::numeric_limits<float>::denorm_min(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            std::bit_cast<float>(0x7fc01234u),
                            std::bit_cast<float>(0xffa00001u),
                            -3.5f,
                            std::numeric_limits<float>::max(),
                            std::numeric_limits<float>::lowest()};
  for (size_t k = 0; k < std::size(specials); ++k) {
    values[k * 97 % count].g = specials[k];
    values[(k * 389 + 5) % count].b = specials[k];
  }
  const std::vector<unsigned char> stored = encodeValues(ValuesCodec::Lossless, charts, values);
  const std::vector<Rgb> decoded = decodeValues(ValuesCodec::Lossless, charts, count, stored, "test");
  ASSERT_EQ(decoded.size(), values.size());
  EXPECT_EQ(std::memcmp(decoded.data(), values.data(), rawBytes(values)), 0);
}

TEST(ValuesCodec, LosslessPredictionPaysOffOnSmoothData) {
  // Noise-free smooth data: the MED residuals of neighbouring textures are small, so the
  // stream must be well under half the raw size (the 2:1 target) — while the same
  // values in random order (no neighbour coherence) must not reach it: the gain comes from
  // the prediction, not from zstd alone.
  uint64_t count = 0;
  const std::vector<Chart> charts = makeCharts(count);
  std::vector<Rgb> values = makeSmoothValues(charts, count, 0.0);
  const double smoothRatio =
      double(rawBytes(values)) / double(encodeValues(ValuesCodec::Lossless, charts, values).size());
  EXPECT_GT(smoothRatio, 2.0);
  std::shuffle(values.begin(), values.end(), std::mt19937(3));
  const double shuffledRatio =
      double(rawBytes(values)) / double(encodeValues(ValuesCodec::Lossless, charts, values).size());
  EXPECT_LT(shuffledRatio, smoothRatio);
}

TEST(ValuesCodec, HdrRelativeErrorIsBoundedByTheStepSize) {
  uint64_t count = 0;
  const std::vector<Chart> charts = makeCharts(count);
  const std::vector<Rgb> values = makeSmoothValues(charts, count);
  size_t previousSize = std::numeric_limits<size_t>::max();
  for (uint32_t steps : {128u, 32u, 8u}) {
    ValuesCodecOptions options;
    options.hdrStepsPerStop = steps;
    const std::vector<unsigned char> stored = encodeValues(ValuesCodec::Hdr, charts, values, options);
    const std::vector<Rgb> decoded = decodeValues(ValuesCodec::Hdr, charts, count, stored, "test");
    // Rounding log2 x to the nearest 1/steps moves x by at most a factor 2^(1/(2·steps));
    // the float32 evaluation of exp2 adds < 1e-6 relative.
    const double bound = std::exp2(0.5 / steps) - 1.0 + 1e-6;
    double worst = 0.0;
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) {
        const float o = c == 0 ? values[i].r : (c == 1 ? values[i].g : values[i].b);
        const float d = c == 0 ? decoded[i].r : (c == 1 ? decoded[i].g : decoded[i].b);
        if (o == 0.0f) {
          EXPECT_EQ(d, 0.0f) << "value " << i;
        } else {
          worst = std::max(worst, std::abs(double(d) - o) / o);
        }
      }
    EXPECT_LE(worst, bound) << steps << " steps per stop";
    EXPECT_GT(worst, 0.5 * bound) << "the quantisation should actually be used";
    // Coarser steps mean smaller residuals: the size must fall with the step count, and
    // even the finest step (128 per stop, 0.27 % max error) beats raw storage by 3:1.
    EXPECT_LT(stored.size(), previousSize) << steps << " steps per stop";
    previousSize = stored.size();
    EXPECT_GT(double(rawBytes(values)) / double(stored.size()), 3.0);
  }
}

TEST(ValuesCodec, Bc1KeepsToneMappedValuesCloseAndRatioAboveSix) {
  uint64_t count = 0;
  const std::vector<Chart> charts = makeCharts(count);
  const std::vector<Rgb> values = makeSmoothValues(charts, count);
  const std::vector<unsigned char> stored = encodeValues(ValuesCodec::Bc1, charts, values);
  const std::vector<Rgb> decoded = decodeValues(ValuesCodec::Bc1, charts, count, stored, "test");
  // 4 bits per value + a 4-byte scale per image and partial blocks: at least 6:1 even on
  // these small, oddly sized charts.
  EXPECT_GT(double(rawBytes(values)) / double(stored.size()), 6.0);
  // Error in the tone-mapped domain of each chart image ((x / max)^(1/2.2), as the codec
  // stores it): smooth data must stay above 35 dB PSNR; this synthetic field spans 4 decades
  // inside one chart, harder than a real bake's images.
  const ValuesError error = measureValuesError(values, decoded);
  EXPECT_LT(error.relativeRmse, 0.5);
  const double psnr = toneMappedPsnr(values, decoded);
  EXPECT_GT(psnr, 35.0);
  EXPECT_EQ(decoded[3].r, 0.0f);
}

TEST(ValuesCodec, LossyCodecsRefuseNonFiniteValues) {
  uint64_t count = 0;
  const std::vector<Chart> charts = makeCharts(count);
  std::vector<Rgb> values = makeSmoothValues(charts, count);
  values[17].g = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(encodeValues(ValuesCodec::Hdr, charts, values), Error);
  EXPECT_THROW(encodeValues(ValuesCodec::Bc1, charts, values), Error);
}

/// Every single-byte corruption and every truncation of a stream must end in pl::Error
/// (whose message starts with the context) or in exactly the values of the intact stream:
/// a few bytes of a zstd frame carry no information (e.g. unused header bits), every other
/// flip inside the frame is caught by zstd's framing or its content checksum or by the
/// exact-size checks. Only the codec parameters in the header (hdr's log2Min and step,
/// bc1's gamma) may stay plausible after a flip and decode to other full-size values.
void expectCorruptionIsCaught(ValuesCodec codec) {
  uint64_t count = 0;
  const std::vector<Chart> charts = makeCharts(count);
  const std::vector<Rgb> values = makeSmoothValues(charts, count);
  const std::vector<unsigned char> stored = encodeValues(codec, charts, values);
  const std::vector<Rgb> intact = decodeValues(codec, charts, count, stored, "intact");
  // magic 4 + codec 4 + counts 16 + parameters + payload size 8: the frame follows.
  const size_t parameters = codec == ValuesCodec::Hdr ? 8 : (codec == ValuesCodec::Bc1 ? 4 : 0);
  const size_t frameStart = 32 + parameters;
  enum Outcome { kError, kIntact, kDifferent };
  auto decode = [&](const std::vector<unsigned char>& bytes) -> Outcome {
    try {
      const std::vector<Rgb> decoded = decodeValues(codec, charts, count, bytes, "corrupt.plf: VALS");
      EXPECT_EQ(decoded.size(), count);
      return std::memcmp(decoded.data(), intact.data(), rawBytes(intact)) == 0 ? kIntact : kDifferent;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("corrupt.plf: VALS: ", 0), 0u) << e.what();
      return kError;
    }
  };
  int silentlyIntact = 0;
  for (size_t at = 0; at < stored.size(); ++at) {
    std::vector<unsigned char> bytes = stored;
    bytes[at] ^= 0x5a;
    const Outcome outcome = decode(bytes);
    const bool plausibleParameter = at >= 24 && at < 24 + parameters;
    if (!plausibleParameter) {
      EXPECT_NE(outcome, kDifferent) << "flip at byte " << at << " of " << stored.size();
    }
    silentlyIntact += outcome == kIntact;
  }
  // Information-free bytes are rare: at most 1 % of the stream.
  EXPECT_LE(silentlyIntact, int(stored.size() / 100) + 1);
  auto decodeOrError = [&](const std::vector<unsigned char>& bytes) { return decode(bytes) == kError ? 1 : 0; };
  for (size_t size = 0; size < stored.size(); ++size) {
    const std::vector<unsigned char> bytes(stored.begin(), stored.begin() + std::ptrdiff_t(size));
    EXPECT_EQ(decodeOrError(bytes), 1) << "truncated to " << size << " bytes";
  }
  std::vector<unsigned char> longer = stored;
  longer.push_back(0);
  EXPECT_EQ(decodeOrError(longer), 1) << "a trailing byte";
  EXPECT_GT(stored.size(), frameStart);
  // A different value count or chart layout than the one encoded is refused too.
  EXPECT_THROW(decodeValues(codec, charts, count + 1, stored, "x"), Error);
  std::vector<Chart> otherCharts = charts;
  otherCharts[1].dirRes = 4;
  EXPECT_THROW(decodeValues(codec, otherCharts, count, stored, "x"), Error);
  const ValuesCodec other = codec == ValuesCodec::Hdr ? ValuesCodec::Lossless : ValuesCodec::Hdr;
  EXPECT_THROW(decodeValues(other, charts, count, stored, "x"), Error);
}

TEST(ValuesCodec, CorruptLosslessStreamsAreRefused) { expectCorruptionIsCaught(ValuesCodec::Lossless); }
TEST(ValuesCodec, CorruptHdrStreamsAreRefused) { expectCorruptionIsCaught(ValuesCodec::Hdr); }
TEST(ValuesCodec, CorruptBc1StreamsAreRefused) { expectCorruptionIsCaught(ValuesCodec::Bc1); }

TEST(ValuesCodec, ChartsOutsideTheValuesAreRefused) {
  uint64_t count = 0;
  const std::vector<Chart> charts = makeCharts(count);
  const std::vector<Rgb> values = makeSmoothValues(charts, count);
  const std::vector<unsigned char> stored = encodeValues(ValuesCodec::Hdr, charts, values);
  EXPECT_THROW(decodeValues(ValuesCodec::Hdr, charts, 100, stored, "x"), Error);
  // An absurd count (as from a hand-made section table) is refused before any allocation.
  EXPECT_THROW(decodeValues(ValuesCodec::Hdr, charts, uint64_t(1) << 60, stored, "x"), Error);
  std::vector<Chart> overlapping = charts;
  overlapping[3].firstValue = overlapping[1].firstValue + 1;
  EXPECT_THROW(encodeValues(ValuesCodec::Hdr, overlapping, values), Error);
}

// --- Through .plf files ----------------------------------------------------------------------

/// A light field with the charts above on a one-quad scene (charts are not tied to
/// geometry by the file format beyond the triangle → chart map).
LightField makeLightField() {
  LightField lf;
  Mesh quad;
  quad.name = "quad";
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  quad.triangles = {{0, 2, 1}, {0, 3, 2}};
  quad.materials = {0, 1};
  lf.scene.meshes = {quad};
  lf.scene.materials = {Material{"white", LambertBsdf{Rgb(0.7f)}, -1, Rgb(0.0f), false},
                        Material{"glossy", BlinnPhongBsdf{Rgb(0.3f), Rgb(0.2f), 50.0f}, -1, Rgb(0.0f), false}};
  uint64_t count = 0;
  lf.charts = makeCharts(count);
  lf.charts[1].material = lf.charts[3].material = 1;
  lf.triangleChart = {{0, 1}};
  lf.values = makeSmoothValues(lf.charts, count);
  return lf;
}

struct TempFile {
  std::string path;
  explicit TempFile(const std::string& name)
      : path((fs::temp_directory_path() / ("pl_compression_" + std::to_string(::getpid()) + "_" + name)).string()) {}
  ~TempFile() { fs::remove(path); }
};

std::vector<unsigned char> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void writeBytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

/// Offset of the VALS entry in the section table.
size_t valuesEntryOffset(const std::vector<unsigned char>& file) {
  uint32_t sections = 0;
  std::memcpy(&sections, file.data() + 12, 4);
  for (size_t i = 0; i < sections; ++i)
    if (std::memcmp(file.data() + kPlfHeaderSize + i * kPlfSectionEntrySize, "VALS", 4) == 0)
      return kPlfHeaderSize + i * kPlfSectionEntrySize;
  ADD_FAILURE() << "no VALS section";
  return 0;
}

/// Re-seals a modified file: recomputes the VALS checksum and the header hash, so that the
/// codec's own checks (not the file's checksums) must catch the damage.
void reseal(std::vector<unsigned char>& file) {
  const size_t entry = valuesEntryOffset(file);
  uint64_t offset = 0, stored = 0;
  std::memcpy(&offset, file.data() + entry + 8, 8);
  std::memcpy(&stored, file.data() + entry + 16, 8);
  const uint64_t checksum = xxh64(file.data() + offset, stored);
  std::memcpy(file.data() + entry + 32, &checksum, 8);
  uint32_t sections = 0;
  std::memcpy(&sections, file.data() + 12, 4);
  std::vector<unsigned char> hashed(file.begin(), file.begin() + 24);
  hashed.insert(hashed.end(), file.begin() + kPlfHeaderSize,
                file.begin() + std::ptrdiff_t(kPlfHeaderSize + sections * kPlfSectionEntrySize));
  const uint64_t hash = xxh64(hashed.data(), hashed.size());
  std::memcpy(file.data() + 24, &hash, 8);
}

TEST(CompressedPlf, EveryModeIsReadBackAndReportedByInfo) {
  const LightField lf = makeLightField();
  for (ValuesCodec encoding : {ValuesCodec::Raw, ValuesCodec::Lossless, ValuesCodec::Bc1, ValuesCodec::Hdr}) {
    TempFile file("modes.plf");
    writeLightField(file.path, lf, encoding);
    const LightField back = readLightField(file.path);
    ASSERT_EQ(back.values.size(), lf.values.size());
    const PlfInfo info = readLightFieldInfo(file.path);
    EXPECT_EQ(info.values, lf.values.size());
    bool found = false;
    for (const PlfSectionInfo& s : info.sections)
      if (s.id == "VALS") {
        found = true;
        EXPECT_EQ(s.encoding, uint32_t(encoding));
        EXPECT_EQ(s.decodedSize, lf.values.size() * sizeof(Rgb));
        if (encoding != ValuesCodec::Raw) { EXPECT_LT(s.storedSize, s.decodedSize); }
      }
    EXPECT_TRUE(found);
    const ValuesError error = measureValuesError(lf.values, back.values);
    if (encoding == ValuesCodec::Raw || encoding == ValuesCodec::Lossless)
      EXPECT_EQ(std::memcmp(back.values.data(), lf.values.data(), rawBytes(lf.values)), 0);
    else
      EXPECT_GT(error.rmse, 0.0);  // lossy, and the decoded values are the ones used
    if (encoding == ValuesCodec::Hdr) { EXPECT_LT(error.maxRelative, 0.022); }  // 2^(1/32) − 1 = 2.19 %
  }
}

TEST(CompressedPlf, CorruptCompressedValuesNameTheFileAndSection) {
  const LightField lf = makeLightField();
  TempFile file("corrupt.plf");
  writeLightField(file.path, lf, ValuesCodec::Lossless);
  const std::vector<unsigned char> good = readBytes(file.path);
  const size_t entry = valuesEntryOffset(good);
  uint64_t offset = 0, stored = 0;
  std::memcpy(&offset, good.data() + entry + 8, 8);
  std::memcpy(&stored, good.data() + entry + 16, 8);
  auto expectError = [&](const std::vector<unsigned char>& bytes, const char* fragment) {
    writeBytes(file.path, bytes);
    try {
      readLightField(file.path);
      ADD_FAILURE() << "no error for " << fragment;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(file.path), std::string::npos) << message;
      EXPECT_NE(message.find(fragment), std::string::npos) << message;
    }
  };
  // A flipped byte in the middle of the zstd frame, checksums re-sealed: zstd's own checks.
  std::vector<unsigned char> flipped = good;
  flipped[offset + stored / 2] ^= 0x10;
  reseal(flipped);
  expectError(flipped, "VALS");
  // Without re-sealing, the section checksum catches it first.
  flipped = good;
  flipped[offset + stored / 2] ^= 0x10;
  expectError(flipped, "checksum");
  // A decoded size that does not match the charts (re-sealed).
  std::vector<unsigned char> wrongSize = good;
  const uint64_t decoded = lf.values.size() * sizeof(Rgb) + sizeof(Rgb);
  std::memcpy(wrongSize.data() + entry + 24, &decoded, 8);
  reseal(wrongSize);
  expectError(wrongSize, "VALS");
  // A decoded size that is not whole RGB triplets.
  std::vector<unsigned char> ragged = good;
  const uint64_t raggedSize = lf.values.size() * sizeof(Rgb) - 1;
  std::memcpy(ragged.data() + entry + 24, &raggedSize, 8);
  reseal(ragged);
  expectError(ragged, "VALS");
  // An unknown encoding.
  std::vector<unsigned char> unknown = good;
  const uint32_t encoding = 77;
  std::memcpy(unknown.data() + entry + 4, &encoding, 4);
  reseal(unknown);
  expectError(unknown, "encoding 77");
  // A truncated compressed section (the file ends inside it).
  std::vector<unsigned char> truncated(good.begin(), good.begin() + std::ptrdiff_t(offset + stored / 2));
  expectError(truncated, "truncated");
}

/// Files written by this version of the codecs (tests/data/compress/{none,lossless,bc1,hdr}.plf,
/// the light field of makeLightField(); regenerate with PLENOPTIC_REGENERATE_COMPRESS_FIXTURES=1
/// only when the format changes on purpose, which also needs a new codec number). Every
/// later build must decode them: lossless bit-exact to none.plf, hdr within its bound.
TEST(CompressedPlf, FilesOfEarlierBuildsStillDecode) {
  const std::string dir = std::string(PLENOPTIC_TEST_DATA_DIR) + "/compress/";
  const std::pair<const char*, ValuesCodec> modes[] = {{"none.plf", ValuesCodec::Raw},
                                                       {"lossless.plf", ValuesCodec::Lossless},
                                                       {"bc1.plf", ValuesCodec::Bc1},
                                                       {"hdr.plf", ValuesCodec::Hdr}};
  if (std::getenv("PLENOPTIC_REGENERATE_COMPRESS_FIXTURES")) {
    const LightField lf = makeLightField();
    for (const auto& [name, encoding] : modes) writeLightField(dir + name, lf, encoding);
  }
  const LightField raw = readLightField(dir + "none.plf");
  const LightField lossless = readLightField(dir + "lossless.plf");
  ASSERT_EQ(lossless.values.size(), raw.values.size());
  EXPECT_EQ(std::memcmp(lossless.values.data(), raw.values.data(), rawBytes(raw.values)), 0);
  const LightField hdr = readLightField(dir + "hdr.plf");
  // Written at 16 steps per stop (the default then): ≤ 2^(1/32) − 1 relative, + float32 rounding.
  EXPECT_LE(measureValuesError(raw.values, hdr.values).maxRelative, std::exp2(1.0 / 32) - 1.0 + 1e-6);
  const LightField bc1 = readLightField(dir + "bc1.plf");
  // The same tone-mapped PSNR bound as for freshly encoded BC1 (Bc1KeepsToneMappedValues…).
  EXPECT_GT(toneMappedPsnr(raw.values, bc1.values), 35.0);
  for (const auto& [name, encoding] : modes)
    EXPECT_EQ(readLightFieldInfo(dir + name).sections[3].encoding, uint32_t(encoding)) << name;
}

}  // namespace
}  // namespace pl
