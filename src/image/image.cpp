// Image basics: the sRGB transfer function, dispatch on the file extension, atomic writes.
#include "image/image.h"

#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "core/error.h"
#include "core/file_io.h"
#include "image/image_io.h"

namespace pl {

// IEC 61966-2-1: a linear segment of slope 12.92 below 0.0031308 (0.04045 encoded), a
// 2.4-power curve with offset 0.055 above; the two pieces meet continuously.
float srgbToLinear(float encoded) {
  if (encoded <= 0.04045f) return encoded / 12.92f;
  return std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float linear) {
  if (!(linear > 0.0f)) return 0.0f;  // also maps NaN to 0 (the caller decides about NaN)
  if (linear >= 1.0f) return 1.0f;
  if (linear <= 0.0031308f) return 12.92f * linear;
  return 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

namespace {
template <size_t N>
bool contains(const std::array<std::string_view, N>& list, const std::string& extension) {
  return std::find(list.begin(), list.end(), extension) != list.end();
}
}  // namespace

bool isHdrExtension(const std::string& path) { return contains(kHdrImageExtensions, fileExtensionLower(path)); }

namespace detail {
std::vector<unsigned char> readFileBytes(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) failFile(path, "{}: cannot open: {}", path, std::strerror(errno));
  std::vector<unsigned char> bytes;
  unsigned char buffer[1 << 16];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, file)) > 0) bytes.insert(bytes.end(), buffer, buffer + n);
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) failFile(path, "{}: read error", path);
  return bytes;
}

void checkImageSize(const std::string& path, long long width, long long height) {
  if (width < 1 || height < 1 || width > kMaxImageDimension || height > kMaxImageDimension ||
      uint64_t(width) * uint64_t(height) > kMaxImagePixels) {
    fail("{}: image size {}x{} is out of range (1..{} per side, at most {} pixels)", path, width, height,
         kMaxImageDimension, kMaxImagePixels);
  }
}
}  // namespace detail

Image decodeTexels(const void* texels, int bitsPerChannel, int width, int height, int channels, ImageDecode decode) {
  if ((bitsPerChannel != 8 && bitsPerChannel != 16) || channels < 1 || channels > 4 || width < 0 || height < 0)
    fail("decodeTexels: unsupported layout ({} bits, {} channels)", bitsPerChannel, channels);
  Image image(width, height);
  const auto* bytes8 = static_cast<const uint8_t*>(texels);
  const auto* values16 = static_cast<const uint16_t*>(texels);
  const float maximum = bitsPerChannel == 8 ? 255.0f : 65535.0f;
  const size_t stride = size_t(channels);
  // Coverage: the last channel of grey + alpha and RGBA, else the first (grey or red).
  const size_t alphaChannel = channels == 2 || channels == 4 ? stride - 1 : 0;
  std::array<float, 256> srgb8;  // the 8-bit sRGB decode as a table (every value occurs)
  if (bitsPerChannel == 8 && decode == ImageDecode::Colour)
    for (int v = 0; v < 256; ++v) srgb8[size_t(v)] = srgbToLinear(float(v) / 255.0f);
  auto value = [&](size_t index) -> float {
    if (bitsPerChannel == 8) {
      if (decode == ImageDecode::Colour) return srgb8[bytes8[index]];
      return float(bytes8[index]) / maximum;
    }
    const float v = float(values16[index]) / maximum;
    return decode == ImageDecode::Colour ? srgbToLinear(v) : v;
  };
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const size_t base = i * stride;
    if (decode == ImageDecode::Coverage) {
      image.pixels[i] = Rgb(value(base + alphaChannel));
    } else {
      // Grey (and grey + alpha) repeat their one colour channel; alpha is not colour.
      for (int c = 0; c < 3; ++c) image.pixels[i][c] = value(base + (channels >= 3 ? size_t(c) : 0));
    }
  }
  return image;
}

namespace {
/// An HDR image read for `decode`: as it is, or (Coverage) its red channel in R, G and B.
Image hdrAs(Image image, ImageDecode decode) {
  if (decode == ImageDecode::Coverage)
    for (Rgb& p : image.pixels) p = Rgb(p.r);
  return image;
}
/// The path names an existing regular file (else pl::Error naming it).
void requireImageFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) failFile(path, "{}: no such file", path);
  if (std::filesystem::is_directory(path, ec)) failFile(path, "{}: is a directory, not an image file", path);
  requireRegularFile(path);
}
}  // namespace

Image readImage(const std::string& path, ImageDecode decode) {
  requireImageFile(path);
  const std::string ext = fileExtensionLower(path);
  if (ext == ".exr") return hdrAs(detail::readExr(path), decode);
  if (ext == ".hdr") return hdrAs(detail::readRadianceHdr(path), decode);
  if (ext == ".pfm") return hdrAs(detail::readPfm(path), decode);
  if (isLdrImageExtension(ext)) return detail::decodeLdr(detail::readFileBytes(path), path, ext == ".png", decode);
  fail("{}: unknown image extension '{}' (readable: {} {})", path, ext, fmt::join(kHdrImageExtensions, " "),
       fmt::join(kLdrImageExtensions, " "));
}

bool isLdrImageExtension(const std::string& extension) { return contains(kLdrImageExtensions, extension); }

ImageFile readImageFile(const std::string& path, ImageDecode decode) {
  const std::string ext = fileExtensionLower(path);
  if (!isLdrImageExtension(ext)) return {readImage(path, decode), {}};
  requireImageFile(path);
  ImageFile file;
  file.ldrBytes = detail::readFileBytes(path);
  file.image = detail::decodeLdr(file.ldrBytes, path, ext == ".png", decode);
  return file;
}

Image decodeLdrImage(std::span<const unsigned char> bytes, const std::string& label, ImageDecode decode) {
  return detail::decodeLdr(bytes, label, false, decode);
}

bool ldrImageHasAlphaChannel(std::span<const unsigned char> bytes) {
  const int channels = detail::ldrChannelCount(bytes);
  return channels == 2 || channels == 4;
}

void writeHdrImage(const std::string& path, const Image& image, const HdrWriteOptions& options) {
  const std::string ext = fileExtensionLower(path);
  if (!isHdrExtension(path))
    fail("{}: cannot write HDR image with extension '{}' (use {})", path, ext, alternatives(kHdrImageExtensions));
  if (image.pixels.size() != size_t(image.width) * size_t(image.height))
    fail("{}: cannot write: pixel buffer holds {} pixels, expected {}x{}", path, image.pixels.size(), image.width,
         image.height);
  detail::checkImageSize(path, image.width, image.height);
  writeFileAtomically(path, [&](const std::string& temp) {
    if (ext == ".exr") detail::writeExr(temp, image, options.exrHalf);
    else if (ext == ".hdr") detail::writeRadianceHdr(temp, image);
    else detail::writePfm(temp, image);
  });
}

void writePng(const std::string& path, const Image8& image) {
  if (fileExtensionLower(path) != ".png") fail("{}: writePng needs a .png file name", path);
  if (image.rgb.size() != size_t(image.width) * size_t(image.height) * 3)
    fail("{}: cannot write: 8-bit buffer holds {} bytes, expected {}x{}x3", path, image.rgb.size(), image.width,
         image.height);
  detail::checkImageSize(path, image.width, image.height);
  writeFileAtomically(path, [&](const std::string& temp) { detail::writePngFile(temp, image); });
}

}  // namespace pl
