// Light-field value codecs: see compression.h for the formats and their rationale.
#include "plf/compression.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "plf/codec_backends.h"

namespace pl {
namespace {

static_assert(sizeof(Rgb) == 12, "values are float32 RGB triplets");
static_assert(std::endian::native == std::endian::little, "the stream format is little-endian");

constexpr char kMagic[4] = {'P', 'L', 'V', 'C'};
constexpr float kBc1Gamma = 2.2f;
constexpr uint32_t kMaxHdrStepsPerStop = 200;  // 277 stops of float range · 200 + 1 < 2^16 codes
constexpr uint64_t kMaxValueCount = uint64_t(1) << 36;
constexpr uint64_t kBc1BlocksWorthAProgressBar = 50000;
constexpr uint64_t kMaxRunWidth = uint64_t(1) << 20;  // uncovered values: 1-high images of at most this

// --- Layout -------------------------------------------------------------------------------

/// A 2-D view of some values: pixel (x, y) is values[base + x·strideX + y·strideY].
struct Grid {
  uint64_t base = 0, strideX = 1, strideY = 0;
  uint32_t width = 0, height = 0;
  uint64_t pixels() const { return uint64_t(width) * height; }
  uint64_t at(uint32_t x, uint32_t y) const { return base + x * strideX + y * strideY; }
};

/// The images of compression.h's layout, in a fixed order (charts in order, a glossy chart's
/// tixels row by row; then the uncovered runs in value order). Every value lies in exactly
/// one image.
std::vector<Grid> buildLayout(const std::vector<Chart>& charts, uint64_t valueCount, const std::string& context) {
  std::vector<Grid> images;
  std::vector<std::pair<uint64_t, uint64_t>> covered;  // [begin, end) value ranges of charts
  for (size_t i = 0; i < charts.size(); ++i) {
    const Chart& c = charts[i];
    const uint64_t tixels = c.tixelCount(), perTixel = c.valuesPerTixel();
    if (perTixel == 0 || tixels == 0) continue;
    if (tixels > valueCount / perTixel || c.firstValue > valueCount - tixels * perTixel)
      fail("{}: chart {} needs values [{}, {} + {}·{}) but the section holds {} values", context, i, c.firstValue,
           c.firstValue, tixels, perTixel, valueCount);
    covered.emplace_back(c.firstValue, c.firstValue + tixels * perTixel);
    if (c.dirRes == 1) {
      // Diffuse: the tixel grid (value (i, j) at firstValue + (i + j·resU)·perTixel), then
      // (directionalIrradiance) one tixel-grid image per tilted irradiance.
      for (uint64_t k = 0; k < perTixel; ++k) images.push_back({c.firstValue + k, perTixel, perTixel * c.resU, c.resU, c.resV});
    } else {
      // Glossy: every tixel's dirRes × dirRes paraboloid texture (texel (s, t) at s + t·dirRes),
      // then (diffuseValue) the tixels' diffuse irradiance as one more tixel-grid image, and
      // (directionalIrradiance) one per tilted irradiance.
      for (uint64_t tixel = 0; tixel < tixels; ++tixel)
        images.push_back({c.firstValue + tixel * perTixel, 1, c.dirRes, c.dirRes, c.dirRes});
      for (uint64_t k = c.directionTexels(); k < perTixel; ++k)
        images.push_back({c.firstValue + k, perTixel, perTixel * c.resU, c.resU, c.resV});
    }
  }
  std::sort(covered.begin(), covered.end());
  uint64_t next = 0;
  auto addRun = [&](uint64_t begin, uint64_t end) {
    for (uint64_t at = begin; at < end; at += kMaxRunWidth)
      images.push_back({at, 1, 0, uint32_t(std::min(kMaxRunWidth, end - at)), 1});
  };
  for (const auto& [begin, end] : covered) {
    // Overlapping charts would make decoders write one value twice (from two threads).
    if (begin < next) fail("{}: charts share values (at value {}); cannot lay them out for compression", context, begin);
    addRun(next, begin);
    next = end;
  }
  addRun(next, valueCount);
  return images;
}

/// First pixel index of every image in the concatenation of all images (size images + 1).
std::vector<uint64_t> pixelOffsets(const std::vector<Grid>& images) {
  std::vector<uint64_t> offsets(images.size() + 1, 0);
  for (size_t k = 0; k < images.size(); ++k) offsets[k + 1] = offsets[k] + images[k].pixels();
  return offsets;
}

// --- Prediction helpers ---------------------------------------------------------------------

/// Order-preserving map of IEEE-754 float bits to unsigned integers (a bijection): positive
/// floats get the sign bit set, negative floats are complemented so that they sort below.
uint32_t orderedBits(float f) {
  const uint32_t u = std::bit_cast<uint32_t>(f);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}
float fromOrderedBits(uint32_t o) { return std::bit_cast<float>((o & 0x80000000u) ? (o & 0x7fffffffu) : ~o); }

/// LOCO-I median edge detector from the left (a), upper (b) and upper-left (c) neighbours.
template <typename T>
T medPredict(T a, T b, T c) {
  const T lo = std::min(a, b), hi = std::max(a, b);
  if (c >= hi) return lo;
  if (c <= lo) return hi;
  return T(a + b - c);  // in (lo, hi): no overflow
}

/// The prediction of pixel (x, y) from already known pixels of the same plane.
template <typename T, typename Get>
T predict(uint32_t x, uint32_t y, const Get& get) {
  if (y == 0) return x == 0 ? T(0) : get(x - 1, 0);
  if (x == 0) return get(0, y - 1);
  return medPredict<T>(get(x - 1, y), get(x, y - 1), get(x - 1, y - 1));
}

uint32_t zigzag32(uint32_t difference) {
  const int32_t d = std::bit_cast<int32_t>(difference);
  return (uint32_t(d) << 1) ^ uint32_t(d >> 31);
}
uint32_t unzigzag32(uint32_t z) { return (z >> 1) ^ (0u - (z & 1u)); }
uint16_t zigzag16(uint16_t difference) {
  const int16_t d = std::bit_cast<int16_t>(difference);
  return uint16_t((uint32_t(uint16_t(d)) << 1) ^ uint32_t(uint16_t(d >> 15)));
}
uint16_t unzigzag16(uint16_t z) { return uint16_t((z >> 1) ^ (0u - (z & 1u))); }

/// Splits words into byte planes: plane p holds byte p of every word, planes in order.
template <typename Word>
std::vector<unsigned char> shuffleBytes(const std::vector<Word>& words) {
  constexpr size_t kBytes = sizeof(Word);
  std::vector<unsigned char> planes(words.size() * kBytes);
  const size_t n = words.size();
  parallelForRange(n, 1 << 16, [&](uint64_t begin, uint64_t end) {
    for (uint64_t i = begin; i < end; ++i)
      for (size_t p = 0; p < kBytes; ++p) planes[p * n + i] = (unsigned char)(words[i] >> (8 * p));
  });
  return planes;
}
template <typename Word>
std::vector<Word> unshuffleBytes(const std::vector<unsigned char>& planes) {
  constexpr size_t kBytes = sizeof(Word);
  const size_t n = planes.size() / kBytes;
  std::vector<Word> words(n);
  parallelForRange(n, 1 << 16, [&](uint64_t begin, uint64_t end) {
    for (uint64_t i = begin; i < end; ++i) {
      Word w = 0;
      for (size_t p = 0; p < kBytes; ++p) w = Word(w | (Word(planes[p * n + i]) << (8 * p)));
      words[i] = w;
    }
  });
  return words;
}

float component(const Rgb& v, int c) { return c == 0 ? v.r : (c == 1 ? v.g : v.b); }
float& component(Rgb& v, int c) { return c == 0 ? v.r : (c == 1 ? v.g : v.b); }

// --- Stream header -----------------------------------------------------------------------------

class StreamWriter {
 public:
  template <typename T>
  void put(const T& value) {
    const auto* p = reinterpret_cast<const unsigned char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  std::vector<unsigned char> bytes;
};

class StreamReader {
 public:
  StreamReader(std::span<const unsigned char> bytes, const std::string& context) : bytes_(bytes), context_(context) {}
  template <typename T>
  T get(const char* what) {
    if (bytes_.size() - at_ < sizeof(T))
      fail("{}: truncated: the stream ends inside its header ({}, at byte {} of {})", context_, what, at_,
           bytes_.size());
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::span<const unsigned char> rest() const { return bytes_.subspan(at_); }

 private:
  std::span<const unsigned char> bytes_;
  size_t at_ = 0;
  const std::string& context_;
};

void putHeader(StreamWriter& w, ValuesCodec codec, uint64_t valueCount, uint64_t imageCount) {
  for (char c : kMagic) w.put(c);
  w.put(uint32_t(codec));
  w.put(valueCount);
  w.put(imageCount);
}

void checkHeader(StreamReader& r, ValuesCodec codec, uint64_t valueCount, uint64_t imageCount,
                 const std::string& context) {
  char magic[4];
  for (char& c : magic) c = r.get<char>("magic");
  if (std::memcmp(magic, kMagic, 4) != 0) fail("{}: corrupt compressed values: wrong magic number", context);
  const uint32_t storedCodec = r.get<uint32_t>("codec");
  if (storedCodec != uint32_t(codec))
    fail("{}: corrupt compressed values: the stream says codec {} but the section table says {} ({})", context,
         storedCodec, uint32_t(codec), valuesCodecName(codec));
  const uint64_t storedCount = r.get<uint64_t>("value count");
  if (storedCount != valueCount)
    fail("{}: corrupt compressed values: the stream holds {} values but the section table says {}", context,
         storedCount, valueCount);
  const uint64_t storedImages = r.get<uint64_t>("image count");
  if (storedImages != imageCount)
    fail("{}: corrupt compressed values: {} images stored but the charts lay out {}", context, storedImages,
         imageCount);
}

/// Appends the payload size field and the payload as one zstd frame (read by readPayload).
void putPayload(StreamWriter& w, const std::vector<unsigned char>& payload, int zstdLevel) {
  w.put(uint64_t(payload.size()));
  const std::vector<unsigned char> frame = detail::zstdCompress(payload, zstdLevel);
  w.bytes.insert(w.bytes.end(), frame.begin(), frame.end());
}

/// Reads the payload size field, checks it against the layout's, and decodes the frame.
std::vector<unsigned char> readPayload(StreamReader& r, uint64_t expectedBytes, const std::string& context) {
  const uint64_t payloadBytes = r.get<uint64_t>("payload size");
  if (payloadBytes != expectedBytes)
    fail("{}: corrupt compressed values: payload of {} bytes declared but the layout needs {}", context, payloadBytes,
         expectedBytes);
  return detail::zstdDecompress(r.rest(), expectedBytes, context);
}

// --- Lossless ------------------------------------------------------------------------------------

std::vector<unsigned char> encodeLossless(const std::vector<Grid>& images, std::span<const Rgb> values,
                                          const ValuesCodecOptions& options) {
  const std::vector<uint64_t> offsets = pixelOffsets(images);
  std::vector<uint32_t> residuals(3 * offsets.back());
  parallelFor(images.size(), [&](uint64_t k) {
    const Grid& image = images[k];
    uint32_t* out = residuals.data() + 3 * offsets[k];
    const uint64_t n = image.pixels();
    for (uint32_t y = 0; y < image.height; ++y)
      for (uint32_t x = 0; x < image.width; ++x) {
        uint32_t e[3];
        for (int c = 0; c < 3; ++c) {
          auto get = [&](uint32_t gx, uint32_t gy) { return orderedBits(component(values[image.at(gx, gy)], c)); };
          e[c] = get(x, y) - predict<uint32_t>(x, y, get);
        }
        // The channels of one value share their noise (the same gather rays), so green's
        // and blue's prediction errors are coded relative to red's.
        const uint64_t i = uint64_t(y) * image.width + x;
        out[i] = zigzag32(e[0]);
        out[n + i] = zigzag32(e[1] - e[0]);
        out[2 * n + i] = zigzag32(e[2] - e[0]);
      }
  });
  const std::vector<unsigned char> payload = shuffleBytes(residuals);
  StreamWriter w;
  putHeader(w, ValuesCodec::Lossless, values.size(), images.size());
  putPayload(w, payload, options.zstdLevel);
  return std::move(w.bytes);
}

void decodeLossless(const std::vector<Grid>& images, StreamReader& r, std::vector<Rgb>& values,
                    const std::string& context) {
  const std::vector<uint64_t> offsets = pixelOffsets(images);
  const std::vector<uint32_t> residuals =
      unshuffleBytes<uint32_t>(readPayload(r, 3 * offsets.back() * sizeof(uint32_t), context));
  parallelFor(images.size(), [&](uint64_t k) {
    const Grid& image = images[k];
    const uint32_t* in = residuals.data() + 3 * offsets[k];
    const uint64_t n = image.pixels();
    for (uint32_t y = 0; y < image.height; ++y)
      for (uint32_t x = 0; x < image.width; ++x) {
        const uint64_t i = uint64_t(y) * image.width + x;
        const uint32_t eR = unzigzag32(in[i]);
        const uint32_t e[3] = {eR, unzigzag32(in[n + i]) + eR, unzigzag32(in[2 * n + i]) + eR};
        Rgb& v = values[image.at(x, y)];
        for (int c = 0; c < 3; ++c) {
          // The decoded values themselves are the prediction context (bit exact).
          auto get = [&](uint32_t gx, uint32_t gy) { return orderedBits(component(values[image.at(gx, gy)], c)); };
          component(v, c) = fromOrderedBits(predict<uint32_t>(x, y, get) + e[c]);
        }
      }
  });
}

// --- HDR (logarithmic codes) ------------------------------------------------------------------------

struct HdrParameters {
  float log2Min = 0.0f;
  uint32_t stepsPerStop = 32;
};

uint16_t hdrCode(float x, const HdrParameters& p) {
  if (!(x > 0.0f)) return 0;
  const double q = std::round((std::log2(double(x)) - p.log2Min) * p.stepsPerStop) + 1.0;
  return uint16_t(std::clamp(q, 1.0, 65535.0));
}

std::vector<unsigned char> encodeHdr(const std::vector<Grid>& images, std::span<const Rgb> values,
                                     const ValuesCodecOptions& options) {
  if (options.hdrStepsPerStop < 1 || options.hdrStepsPerStop > kMaxHdrStepsPerStop)
    fail("hdr compression: {} steps per stop is outside [1, {}]", options.hdrStepsPerStop, kMaxHdrStepsPerStop);
  HdrParameters p;
  p.stepsPerStop = options.hdrStepsPerStop;
  float smallest = std::numeric_limits<float>::max();
  for (const Rgb& v : values)
    for (int c = 0; c < 3; ++c)
      if (component(v, c) > 0.0f) smallest = std::min(smallest, component(v, c));
  p.log2Min = std::floor(std::log2(smallest));  // every positive value gets a code ≥ 1

  const std::vector<uint64_t> offsets = pixelOffsets(images);
  std::vector<uint16_t> residuals(3 * offsets.back());
  parallelFor(images.size(), [&](uint64_t k) {
    const Grid& image = images[k];
    uint16_t* out = residuals.data() + 3 * offsets[k];
    const uint64_t n = image.pixels();
    auto get = [&](int c) {
      return [&image, &values, &p, c](uint32_t x, uint32_t y) {
        return int32_t(hdrCode(component(values[image.at(x, y)], c), p));
      };
    };
    const auto getR = get(0), getG = get(1), getB = get(2);
    for (uint32_t y = 0; y < image.height; ++y)
      for (uint32_t x = 0; x < image.width; ++x) {
        const uint64_t i = uint64_t(y) * image.width + x;
        const uint16_t eR = uint16_t(getR(x, y) - predict<int32_t>(x, y, getR));
        const uint16_t eG = uint16_t(getG(x, y) - predict<int32_t>(x, y, getG));
        const uint16_t eB = uint16_t(getB(x, y) - predict<int32_t>(x, y, getB));
        out[i] = zigzag16(eR);
        out[n + i] = zigzag16(uint16_t(eG - eR));
        out[2 * n + i] = zigzag16(uint16_t(eB - eR));
      }
  });
  const std::vector<unsigned char> payload = shuffleBytes(residuals);
  StreamWriter w;
  putHeader(w, ValuesCodec::Hdr, values.size(), images.size());
  w.put(p.log2Min);
  w.put(p.stepsPerStop);
  putPayload(w, payload, options.zstdLevel);
  return std::move(w.bytes);
}

void decodeHdr(const std::vector<Grid>& images, StreamReader& r, std::vector<Rgb>& values,
               const std::string& context) {
  HdrParameters p;
  p.log2Min = r.get<float>("log2 minimum");
  p.stepsPerStop = r.get<uint32_t>("steps per stop");
  // Float magnitudes span 2^-149 … 2^128.
  if (!std::isfinite(p.log2Min) || p.log2Min < -150.0f || p.log2Min > 128.0f || p.log2Min != std::floor(p.log2Min))
    fail("{}: corrupt compressed values: hdr log2 minimum {} is not a whole number in [-150, 128]", context, p.log2Min);
  if (p.stepsPerStop < 1 || p.stepsPerStop > kMaxHdrStepsPerStop)
    fail("{}: corrupt compressed values: {} hdr steps per stop (1 to {} are valid)", context, p.stepsPerStop,
         kMaxHdrStepsPerStop);
  // Code → value table; codes beyond the float range (only in a corrupt stream) saturate.
  std::vector<float> table(65536);
  table[0] = 0.0f;
  for (uint32_t q = 1; q < table.size(); ++q)
    table[q] = float(std::min(std::exp2(double(p.log2Min) + double(q - 1) / p.stepsPerStop),
                              double(std::numeric_limits<float>::max())));

  const std::vector<uint64_t> offsets = pixelOffsets(images);
  const std::vector<uint16_t> residuals =
      unshuffleBytes<uint16_t>(readPayload(r, 3 * offsets.back() * sizeof(uint16_t), context));
  // Images come in ranges so that the row buffers are allocated once per range, not once per
  // image (a glossy chart has one small image per tixel).
  parallelForRange(images.size(), 1, [&](uint64_t firstImage, uint64_t endImage) {
    // Codes of the previous and current row per channel (the prediction context).
    std::vector<int32_t> rows[3][2];
    for (uint64_t k = firstImage; k < endImage; ++k) {
      const Grid& image = images[k];
      const uint16_t* in = residuals.data() + 3 * offsets[k];
      const uint64_t n = image.pixels();
      for (auto& channel : rows)
        for (auto& row : channel) row.assign(image.width, 0);
      for (uint32_t y = 0; y < image.height; ++y) {
        for (int c = 0; c < 3; ++c) std::swap(rows[c][0], rows[c][1]);  // [0] = previous row
        for (uint32_t x = 0; x < image.width; ++x) {
          const uint64_t i = uint64_t(y) * image.width + x;
          const uint16_t eR = unzigzag16(in[i]);
          const uint16_t e[3] = {eR, uint16_t(unzigzag16(in[n + i]) + eR), uint16_t(unzigzag16(in[2 * n + i]) + eR)};
          Rgb& v = values[image.at(x, y)];
          for (int c = 0; c < 3; ++c) {
            auto get = [&](uint32_t gx, uint32_t gy) { return rows[c][gy == y ? 1 : 0][gx]; };
            const uint16_t code = uint16_t(predict<int32_t>(x, y, get) + e[c]);
            rows[c][1][x] = code;
            component(v, c) = table[code];
          }
        }
      }
    }
  });
}

// --- BC1 --------------------------------------------------------------------------------------------

uint64_t blockCount(const Grid& image) { return uint64_t((image.width + 3) / 4) * ((image.height + 3) / 4); }

/// Byte offset of every image's record (scale + blocks) in the payload (size images + 1).
std::vector<uint64_t> bc1Offsets(const std::vector<Grid>& images) {
  std::vector<uint64_t> offsets(images.size() + 1, 0);
  for (size_t k = 0; k < images.size(); ++k) offsets[k + 1] = offsets[k] + sizeof(float) + 8 * blockCount(images[k]);
  return offsets;
}

std::vector<unsigned char> encodeBc1(const std::vector<Grid>& images, std::span<const Rgb> values,
                                     const ValuesCodecOptions& options) {
  const std::vector<uint64_t> offsets = bc1Offsets(images);
  std::vector<unsigned char> payload(offsets.back());
  // libsquish's iterative cluster fit takes ~20 µs per block: show progress from ~1 s on.
  uint64_t blocks = 0;
  for (const Grid& image : images) blocks += blockCount(image);
  std::optional<Progress> progress;
  if (blocks >= kBc1BlocksWorthAProgressBar) progress.emplace("bc1 encoding", blocks);
  parallelFor(images.size(), [&](uint64_t k) {
    const Grid& image = images[k];
    if (progress) progress->advance(blockCount(image));
    float scale = 0.0f;
    for (uint32_t y = 0; y < image.height; ++y)
      for (uint32_t x = 0; x < image.width; ++x) {
        const Rgb& v = values[image.at(x, y)];
        scale = std::max({scale, v.r, v.g, v.b});
      }
    unsigned char* out = payload.data() + offsets[k];
    std::memcpy(out, &scale, sizeof(float));
    out += sizeof(float);
    const float inverse = scale > 0.0f ? 1.0f / scale : 0.0f;
    for (uint32_t by = 0; by < image.height; by += 4)
      for (uint32_t bx = 0; bx < image.width; bx += 4) {
        unsigned char rgb[16][3] = {};
        int mask = 0;
        for (uint32_t dy = 0; dy < 4; ++dy)
          for (uint32_t dx = 0; dx < 4; ++dx) {
            if (bx + dx >= image.width || by + dy >= image.height) continue;
            const int i = int(dx + 4 * dy);
            mask |= 1 << i;
            const Rgb& v = values[image.at(bx + dx, by + dy)];
            for (int c = 0; c < 3; ++c) {
              const float t = std::clamp(component(v, c) * inverse, 0.0f, 1.0f);
              rgb[i][c] = (unsigned char)std::lround(255.0f * std::pow(t, 1.0f / kBc1Gamma));
            }
          }
        detail::bc1EncodeBlock(rgb, mask, out);
        out += 8;
      }
  });
  StreamWriter w;
  putHeader(w, ValuesCodec::Bc1, values.size(), images.size());
  w.put(kBc1Gamma);
  putPayload(w, payload, options.zstdLevel);
  return std::move(w.bytes);
}

void decodeBc1(const std::vector<Grid>& images, StreamReader& r, std::vector<Rgb>& values,
               const std::string& context) {
  const float gamma = r.get<float>("gamma");
  if (!(gamma >= 0.1f && gamma <= 10.0f))
    fail("{}: corrupt compressed values: bc1 tone-mapping gamma {} outside [0.1, 10]", context, gamma);
  const std::vector<uint64_t> offsets = bc1Offsets(images);
  const std::vector<unsigned char> payload = readPayload(r, offsets.back(), context);
  // Scales are checked before any value is written, so an error leaves no partial result.
  for (size_t k = 0; k < images.size(); ++k) {
    float scale;
    std::memcpy(&scale, payload.data() + offsets[k], sizeof(float));
    if (!std::isfinite(scale) || scale < 0.0f)
      fail("{}: corrupt compressed values: image {} has tone-mapping scale {}", context, k, scale);
  }
  parallelFor(images.size(), [&](uint64_t k) {
    const Grid& image = images[k];
    const unsigned char* in = payload.data() + offsets[k];
    float scale;
    std::memcpy(&scale, in, sizeof(float));
    in += sizeof(float);
    std::array<float, 256> inverseToneMap;
    for (int i = 0; i < 256; ++i) inverseToneMap[size_t(i)] = scale * std::pow(float(i) / 255.0f, gamma);
    for (uint32_t by = 0; by < image.height; by += 4)
      for (uint32_t bx = 0; bx < image.width; bx += 4) {
        unsigned char rgb[16][3];
        detail::bc1DecodeBlock(in, rgb);
        in += 8;
        for (uint32_t dy = 0; dy < 4 && by + dy < image.height; ++dy)
          for (uint32_t dx = 0; dx < 4 && bx + dx < image.width; ++dx) {
            const auto& texel = rgb[dx + 4 * dy];
            values[image.at(bx + dx, by + dy)] =
                Rgb(inverseToneMap[texel[0]], inverseToneMap[texel[1]], inverseToneMap[texel[2]]);
          }
      }
  });
}

}  // namespace

std::string_view valuesCodecName(ValuesCodec codec) {
  switch (codec) {
    case ValuesCodec::Raw: return "none";
    case ValuesCodec::Lossless: return "lossless";
    case ValuesCodec::Bc1: return "bc1";
    case ValuesCodec::Hdr: return "hdr";
  }
  return "unknown";
}

ValuesCodec parseValuesCodec(std::string_view name) {
  if (name == "none" || name == "raw") return ValuesCodec::Raw;
  if (name == "lossless") return ValuesCodec::Lossless;
  if (name == "bc1") return ValuesCodec::Bc1;
  if (name == "hdr") return ValuesCodec::Hdr;
  fail("unknown compression mode '{}' (none, lossless, bc1 or hdr)", name);
}

bool isKnownValuesCodec(uint32_t code) { return code <= uint32_t(ValuesCodec::Hdr); }

std::vector<unsigned char> encodeValues(ValuesCodec codec, const std::vector<Chart>& charts,
                                        std::span<const Rgb> values, const ValuesCodecOptions& options) {
  if (codec == ValuesCodec::Raw) {
    const auto* p = reinterpret_cast<const unsigned char*>(values.data());
    return {p, p + values.size_bytes()};
  }
  if (codec != ValuesCodec::Lossless)
    for (size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i].r) || !std::isfinite(values[i].g) || !std::isfinite(values[i].b))
        fail("{} compression: value {} is not finite ({}, {}, {}); only lossless stores it", valuesCodecName(codec), i,
             values[i].r, values[i].g, values[i].b);
  const std::vector<Grid> images = buildLayout(charts, values.size(), "compression");
  switch (codec) {
    case ValuesCodec::Lossless: return encodeLossless(images, values, options);
    case ValuesCodec::Hdr: return encodeHdr(images, values, options);
    case ValuesCodec::Bc1: return encodeBc1(images, values, options);
    case ValuesCodec::Raw: break;
  }
  fail("unknown values codec {}", uint32_t(codec));
}

std::vector<Rgb> decodeValues(ValuesCodec codec, const std::vector<Chart>& charts, uint64_t valueCount,
                              std::span<const unsigned char> stored, const std::string& context) {
  if (codec == ValuesCodec::Raw) {
    if (stored.size() != valueCount * sizeof(Rgb))
      fail("{}: {} bytes stored for {} raw values", context, stored.size(), valueCount);
    std::vector<Rgb> values(valueCount);
    std::memcpy(values.data(), stored.data(), stored.size());
    return values;
  }
  if (!isKnownValuesCodec(uint32_t(codec))) fail("{}: unknown values codec {}", context, uint32_t(codec));
  // A bound far above any real light field (0.8 TB of float values) that keeps a corrupt
  // count from turning into an absurd allocation or layout loop.
  if (valueCount > kMaxValueCount)
    fail("{}: {} values declared; more than {} cannot be a light field", context, valueCount, kMaxValueCount);
  const std::vector<Grid> images = buildLayout(charts, valueCount, context);
  StreamReader r(stored, context);
  checkHeader(r, codec, valueCount, images.size(), context);
  std::vector<Rgb> values(valueCount);
  switch (codec) {
    case ValuesCodec::Lossless: decodeLossless(images, r, values, context); break;
    case ValuesCodec::Hdr: decodeHdr(images, r, values, context); break;
    case ValuesCodec::Bc1: decodeBc1(images, r, values, context); break;
    case ValuesCodec::Raw: break;
  }
  return values;
}

ValuesError measureValuesError(std::span<const Rgb> original, std::span<const Rgb> decoded) {
  if (original.size() != decoded.size())
    fail("measureValuesError: {} original values but {} decoded", original.size(), decoded.size());
  ValuesError e;
  const double n = 3.0 * double(original.size());
  if (original.empty()) return e;
  for (const Rgb& v : original) e.meanOriginal += (double(v.r) + v.g + v.b) / n;
  const double floor2 = 1e-4 * e.meanOriginal * e.meanOriginal, floor1 = 1e-3 * e.meanOriginal;
  double squared = 0, relativeSquared = 0;
  for (size_t i = 0; i < original.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double o = component(original[i], c), d = double(component(decoded[i], c)) - o;
      squared += d * d;
      relativeSquared += d * d / (o * o + floor2);
      e.maxRelative = std::max(e.maxRelative, std::abs(d) / std::max(std::abs(o), floor1));
    }
  e.rmse = std::sqrt(squared / n);
  e.relativeRmse = std::sqrt(relativeSquared / n);
  return e;
}

}  // namespace pl
