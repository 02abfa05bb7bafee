// 8-bit images through stb_image / stb_image_write (the only file that includes stb), and
// the Radiance RGBE (.hdr) format.
//
// Radiance .hdr: stb_image's .hdr reader does not detect a truncated file (its byte reader
// returns 0 past the end, so a cut file decodes into black rows without an error) and
// ignores EXPOSURE, so .hdr files are read by the strict reader below. Writing uses
// stb_image_write's RLE encoder into memory, then one checked write.
//
// RGBE decoding follows Radiance's colr_color(): a channel with mantissa m and shared
// exponent byte e is (m + 0.5)·2^(e−136), and e = 0 is black. stb_image_write truncates
// when encoding, so the +0.5 centres the quantisation error: |decoded − original| ≤
// max(r,g,b)/256 per channel.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_HDR  // see above: the strict RGBE reader below is used instead
#define STBI_NO_PSD
#define STBI_NO_GIF
#define STBI_NO_PIC
#define STBI_NO_PNM
#define STBI_NO_LINEAR
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <stb_image.h>
#include <stb_image_write.h>
#pragma GCC diagnostic pop

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/byte_reader.h"
#include "core/error.h"
#include "image/image_io.h"

namespace pl::detail {
namespace {

/// stb_image's PNG decoder may accept a file cut inside its last chunks. Walk the chunk
/// structure first: every chunk's length must fit in the file and the file must end with IEND.
void checkPngStructure(const std::string& path, std::span<const unsigned char> bytes) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSignature, 8) != 0) fail("{}: not a PNG file (bad signature)", path);
  size_t at = 8;
  while (true) {
    if (at + 12 > bytes.size()) fail("{}: truncated PNG file (chunk header at byte {} cut off)", path, at);
    const uint32_t length = uint32_t(bytes[at]) << 24 | uint32_t(bytes[at + 1]) << 16 | uint32_t(bytes[at + 2]) << 8 |
                            uint32_t(bytes[at + 3]);
    const std::string_view type(reinterpret_cast<const char*>(&bytes[at + 4]), 4);
    if (uint64_t(at) + 12 + length > bytes.size())
      fail("{}: truncated PNG file ({} chunk at byte {} needs {} bytes, file has {})", path, type, at, length + 12,
           bytes.size() - at);
    at += 12 + length;
    if (type == "IEND") return;
  }
}

}  // namespace

Image decodeLdr(std::span<const unsigned char> bytes, const std::string& label, bool mustBePng, ImageDecode decode) {
  static const unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.empty()) fail("{}: empty file", label);
  if (bytes.size() > size_t(INT32_MAX)) fail("{}: file too large for the 8-bit image reader", label);
  if (mustBePng || (bytes.size() >= 8 && std::memcmp(bytes.data(), kPngSignature, 8) == 0))
    checkPngStructure(label, bytes);
  const int size = int(bytes.size());
  int width = 0, height = 0, channels = 0;
  if (!stbi_info_from_memory(bytes.data(), size, &width, &height, &channels))
    fail("{}: corrupt or unsupported image: {}", label, stbi_failure_reason());
  checkImageSize(label, width, height);

  // 16-bit PNGs keep their precision; everything else is 8-bit. Channels as stored (grey,
  // grey + alpha, RGB, RGBA), so that an alpha channel survives for ImageDecode::Coverage.
  const bool sixteen = stbi_is_16_bit_from_memory(bytes.data(), size) != 0;
  void* data = sixteen ? static_cast<void*>(stbi_load_16_from_memory(bytes.data(), size, &width, &height, &channels, 0))
                       : static_cast<void*>(stbi_load_from_memory(bytes.data(), size, &width, &height, &channels, 0));
  if (!data) fail("{}: corrupt image: {}", label, stbi_failure_reason());
  const std::unique_ptr<void, void (*)(void*)> owner(data, stbi_image_free);
  return decodeTexels(data, sixteen ? 16 : 8, width, height, channels, decode);
}

int ldrChannelCount(std::span<const unsigned char> bytes) {
  int width = 0, height = 0, channels = 0;
  if (bytes.empty() || bytes.size() > size_t(INT32_MAX)) return 0;
  return stbi_info_from_memory(bytes.data(), int(bytes.size()), &width, &height, &channels) ? channels : 0;
}

namespace {
void appendToVector(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<unsigned char>*>(context);
  const auto* bytes = static_cast<const unsigned char*>(data);
  out->insert(out->end(), bytes, bytes + size);
}
}  // namespace

void writePngFile(const std::string& path, const Image8& image) {
  std::vector<unsigned char> encoded;
  if (!stbi_write_png_to_func(appendToVector, &encoded, image.width, image.height, 3, image.rgb.data(), image.width * 3))
    fail("PNG encoding failed");
  writeFileBytes(path, encoded.data(), encoded.size());
}

// ---- Radiance RGBE -----------------------------------------------------------------------

namespace {

/// Longest Radiance header line accepted (the header is a few short lines; anything longer is
/// a corrupt file, not a header to keep reading).
constexpr size_t kMaxHeaderLineBytes = 4096;

/// Reads one scan line of `width` RGBE pixels (new adaptive RLE, old RLE or flat).
void readScanline(ByteReader& in, const std::string& path, int y, int width, unsigned char* rgbe) {
  const unsigned char b0 = in.get<unsigned char>(), b1 = in.get<unsigned char>(), b2 = in.get<unsigned char>(), b3 = in.get<unsigned char>();
  const bool newRle = width >= 8 && width < 0x8000 && b0 == 2 && b1 == 2 && !(b2 & 0x80);
  if (newRle) {
    if ((int(b2) << 8 | int(b3)) != width)
      fail("{}: corrupt Radiance HDR file (scan line {} says width {}, header says {})", path, y, int(b2) << 8 | int(b3),
           width);
    for (int channel = 0; channel < 4; ++channel) {
      int x = 0;
      while (x < width) {
        int count = in.get<unsigned char>();
        const bool run = count > 128;
        if (run) count -= 128;
        if (count == 0 || x + count > width)
          fail("{}: corrupt Radiance HDR file (bad run length {} in scan line {} at byte {})", path, count, y,
               in.offset());
        if (run) {
          const unsigned char value = in.get<unsigned char>();
          for (int i = 0; i < count; ++i) rgbe[4 * (x++) + channel] = value;
        } else {
          for (int i = 0; i < count; ++i) rgbe[4 * (x++) + channel] = in.get<unsigned char>();
        }
      }
    }
    return;
  }
  // Flat pixels, possibly with old-style runs: (1,1,1,n) repeats the previous pixel n << shift
  // times, consecutive run markers shifting by 8 more bits.
  unsigned char pixel[4] = {b0, b1, b2, b3};
  int x = 0, shift = 0;
  while (true) {
    if (pixel[0] == 1 && pixel[1] == 1 && pixel[2] == 1) {
      if (x == 0) fail("{}: corrupt Radiance HDR file (run without a preceding pixel in scan line {})", path, y);
      const long long repeat = (long long)pixel[3] << shift;
      if (x + repeat > width) fail("{}: corrupt Radiance HDR file (run overflows scan line {})", path, y);
      for (long long i = 0; i < repeat; ++i, ++x) std::memcpy(rgbe + 4 * x, rgbe + 4 * (x - 1), 4);
      shift += 8;
    } else {
      std::memcpy(rgbe + 4 * x, pixel, 4);
      ++x;
      shift = 0;
    }
    if (x >= width) return;
    for (unsigned char& b : pixel) b = in.get<unsigned char>();
  }
}

}  // namespace

Image readRadianceHdr(const std::string& path) {
  const std::vector<unsigned char> bytes = readFileBytes(path);
  ByteReader in(bytes, path, "or truncated Radiance HDR file");
  if (bytes.size() < 2 || bytes[0] != '#' || bytes[1] != '?')
    fail("{}: not a Radiance HDR file (does not start with '#?')", path);
  in.getLine(kMaxHeaderLineBytes);
  // Header: VARIABLE=value lines up to an empty line. EXPOSURE multiplies (cumulatively) the
  // values that were stored, so radiance = stored / exposure.
  double exposure = 1.0;
  while (true) {
    const std::string line = in.getLine(kMaxHeaderLineBytes);
    if (line.empty()) break;
    if (line.rfind("FORMAT=", 0) == 0 && line != "FORMAT=32-bit_rle_rgbe")
      fail("{}: unsupported Radiance format '{}' (only 32-bit_rle_rgbe)", path, line.substr(7));
    if (line.rfind("EXPOSURE=", 0) == 0) {
      const double e = std::atof(line.c_str() + 9);
      if (!(e > 0.0) || !std::isfinite(e)) fail("{}: bad EXPOSURE '{}' in Radiance header", path, line.substr(9));
      exposure *= e;
    }
  }
  const std::string resolution = in.getLine(kMaxHeaderLineBytes);
  char ySign = 0, xSign = 0, yAxis = 0, xAxis = 0;
  long long height = 0, width = 0;
  if (std::sscanf(resolution.c_str(), "%c%c %lld %c%c %lld", &ySign, &yAxis, &height, &xSign, &xAxis, &width) != 6 ||
      (ySign != '-' && ySign != '+') || (xSign != '-' && xSign != '+'))
    fail("{}: corrupt Radiance HDR resolution line '{}'", path, resolution);
  if (yAxis != 'Y' || xAxis != 'X')
    fail("{}: unsupported Radiance HDR orientation '{}' (only '±Y H ±X W')", path, resolution);
  checkImageSize(path, width, height);

  // The scan lines are decoded before the image is made: a short file that declares a huge size
  // fails at its end after holding what it decoded, instead of first allocating and clearing
  // width × height pixels (up to kMaxImagePixels × 12 bytes) for a few bytes of input.
  std::vector<Rgb> rows;  // in file order, `width` pixels each
  std::vector<unsigned char> rgbe(size_t(width) * 4);
  const float scale = float(1.0 / exposure);
  for (int row = 0; row < int(height); ++row) {
    readScanline(in, path, row, int(width), rgbe.data());
    for (int i = 0; i < int(width); ++i) {
      const unsigned char* p = &rgbe[size_t(i) * 4];
      Rgb value(0.0f);
      if (p[3] != 0) {
        const float f = std::ldexp(1.0f, int(p[3]) - (128 + 8));
        value = Rgb((float(p[0]) + 0.5f) * f, (float(p[1]) + 0.5f) * f, (float(p[2]) + 0.5f) * f) * scale;
      }
      rows.push_back(value);
    }
  }
  Image image(static_cast<int>(width), static_cast<int>(height));
  for (int row = 0; row < int(height); ++row) {
    // "-Y" stores the top row first; "+Y" the bottom row first. "-X" runs right to left.
    const int y = ySign == '-' ? row : int(height) - 1 - row;
    for (int i = 0; i < int(width); ++i) {
      const int x = xSign == '+' ? i : int(width) - 1 - i;
      image.at(x, y) = rows[size_t(row) * size_t(width) + size_t(i)];
    }
  }
  return image;
}

void writeRadianceHdr(const std::string& path, const Image& image) {
  std::vector<float> data(image.pixels.size() * 3);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const Rgb& p = image.pixels[i];
    if (!isFinite(p))
      fail("pixel ({}, {}) is not finite ({}, {}, {}); Radiance RGBE cannot store it (use .exr or .pfm)",
           i % size_t(image.width), i / size_t(image.width), p.r, p.g, p.b);
    // RGBE has no sign bit: negative values (which radiance never has) are stored as 0.
    for (int c = 0; c < 3; ++c) data[3 * i + size_t(c)] = std::max(0.0f, p[c]);
  }
  std::vector<unsigned char> encoded;
  if (!stbi_write_hdr_to_func(appendToVector, &encoded, image.width, image.height, 3, data.data()))
    fail("Radiance HDR encoding failed");
  writeFileBytes(path, encoded.data(), encoded.size());
}

}  // namespace pl::detail
