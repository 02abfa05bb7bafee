// Portable float map (.pfm): text header, then raw 32-bit floats.
//
//   "PF" (RGB) or "Pf" (grey), whitespace, width, whitespace, height, whitespace, scale,
//   exactly one whitespace byte, then width·height·channels floats.
// The sign of `scale` gives the byte order (negative = little endian, positive = big endian);
// its magnitude is informational and ignored. Rows are stored bottom to top.
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "image/image_io.h"

namespace pl::detail {
namespace {

uint32_t byteSwap(uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

/// The next whitespace-separated header token starting at `at`; advances `at` past it.
std::string headerToken(const std::string& path, const std::vector<unsigned char>& bytes, size_t& at) {
  while (at < bytes.size() && std::isspace(bytes[at])) ++at;
  std::string token;
  while (at < bytes.size() && !std::isspace(bytes[at])) {
    if (token.size() > 64) fail("{}: corrupt PFM header (token longer than 64 bytes)", path);
    token.push_back(char(bytes[at++]));
  }
  if (token.empty()) fail("{}: truncated PFM header", path);
  return token;
}

long long parseInteger(const std::string& path, const std::string& token, const char* what) {
  char* end = nullptr;
  const long long value = std::strtoll(token.c_str(), &end, 10);
  if (end == token.c_str() || *end != '\0') fail("{}: corrupt PFM header ({} '{}' is not an integer)", path, what, token);
  return value;
}

}  // namespace

Image readPfm(const std::string& path) {
  const std::vector<unsigned char> bytes = readFileBytes(path);
  size_t at = 0;
  const std::string magic = headerToken(path, bytes, at);
  if (magic != "PF" && magic != "Pf") fail("{}: not a PFM file (magic '{}', expected PF or Pf)", path, magic.substr(0, 8));
  const int channels = magic == "PF" ? 3 : 1;
  const long long width = parseInteger(path, headerToken(path, bytes, at), "width");
  const long long height = parseInteger(path, headerToken(path, bytes, at), "height");
  const std::string scaleToken = headerToken(path, bytes, at);
  char* end = nullptr;
  const double scale = std::strtod(scaleToken.c_str(), &end);
  if (end == scaleToken.c_str() || *end != '\0' || scale == 0.0 || !std::isfinite(scale))
    fail("{}: corrupt PFM header (scale '{}' must be a non-zero number)", path, scaleToken);
  checkImageSize(path, width, height);
  if (at >= bytes.size() || !std::isspace(bytes[at])) fail("{}: truncated PFM header", path);
  // Exactly one whitespace byte ends the header; a "\r\n" (files written on Windows in text
  // mode) is recognised by the pixel data being one byte longer than expected.
  const size_t expectedBytes = size_t(width) * size_t(height) * size_t(magic == "PF" ? 3 : 1) * 4;
  at += (bytes[at] == '\r' && at + 1 < bytes.size() && bytes[at + 1] == '\n' && bytes.size() - at - 2 == expectedBytes) ? 2 : 1;

  const size_t count = size_t(width) * size_t(height) * size_t(channels);
  const size_t expected = count * 4;
  if (bytes.size() - at < expected)
    fail("{}: truncated PFM file ({} bytes of pixel data, {}x{}x{} floats need {})", path, bytes.size() - at, width,
         height, channels, expected);
  const bool fileLittleEndian = scale < 0.0;
  const bool swap = fileLittleEndian != (std::endian::native == std::endian::little);

  Image image(static_cast<int>(width), static_cast<int>(height));
  for (long long row = 0; row < height; ++row) {
    const int y = int(height - 1 - row);  // bottom row first in the file
    for (long long x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int source = channels == 3 ? c : 0;
        const size_t index = (size_t(row) * size_t(width) + size_t(x)) * size_t(channels) + size_t(source);
        uint32_t raw;
        std::memcpy(&raw, &bytes[at + 4 * index], 4);
        if (swap) raw = byteSwap(raw);
        image.at(int(x), y)[c] = std::bit_cast<float>(raw);
      }
    }
  }
  return image;
}

void writePfm(const std::string& path, const Image& image) {
  // Native byte order, announced by the sign of the scale.
  const char* scale = std::endian::native == std::endian::little ? "-1.0" : "1.0";
  const std::string header = fmt::format("PF\n{} {}\n{}\n", image.width, image.height, scale);
  std::vector<unsigned char> bytes(header.begin(), header.end());
  const size_t rowBytes = size_t(image.width) * sizeof(Rgb);
  static_assert(sizeof(Rgb) == 3 * sizeof(float), "Rgb must be three tightly packed floats");
  bytes.reserve(bytes.size() + rowBytes * size_t(image.height));
  for (int y = image.height - 1; y >= 0; --y) {
    const auto* row = reinterpret_cast<const unsigned char*>(&image.at(0, y));
    bytes.insert(bytes.end(), row, row + rowBytes);
  }
  writeFileBytes(path, bytes.data(), bytes.size());
}

}  // namespace pl::detail
