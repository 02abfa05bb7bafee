#pragma once
// HDR images, their files, tone mapping and comparison.
//
// An Image holds linear Rec.709 RGB floats, row-major, row 0 at the *top*. In a rendered
// image a pixel value is scene radiance (W·sr⁻¹·m⁻²) times the camera's exposure scale
// (1 when no exposure was given): an EXR written with no exposure flags holds radiance.
//
// File formats (chosen by extension, case-insensitive):
//   .exr  OpenEXR, half or float RGB(A)       read + write (linear)
//   .hdr  Radiance RGBE                        read + write (linear)
//   .pfm  Portable float map                   read + write (linear)
//   .png  8-bit sRGB                           read (decoded to linear) + write (tone-mapped)
// Writes are atomic: a temporary file beside the target is renamed over it on success, so a
// failed write never leaves a half-written file.
#include "core/math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pl {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<Rgb> pixels;  ///< width * height, row-major, top row first

  Image() = default;
  Image(int w, int h, Rgb fill = Rgb(0.0f)) : width(w), height(h), pixels(size_t(w) * size_t(h), fill) {}
  Rgb& at(int x, int y) { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  const Rgb& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  bool empty() const { return pixels.empty(); }
};

/// 8-bit RGB pixels (sRGB-encoded), row-major, top row first.
struct Image8 {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;  ///< width * height * 3
};

/// sRGB transfer function (IEC 61966-2-1) and its inverse, per channel.
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

/// Reads an HDR image (.exr, .hdr, .pfm) or an 8-bit one (.png, .jpg: sRGB-decoded to linear).
/// Throws pl::Error naming the file and the problem.
Image readImage(const std::string& path);

/// Writes linear pixels to .exr/.hdr/.pfm as they are. Throws pl::Error on failure.
void writeHdrImage(const std::string& path, const Image& image);
/// Writes an already tone-mapped 8-bit image as PNG.
void writePng(const std::string& path, const Image8& image);
/// True for the extensions writeHdrImage accepts.
bool isHdrExtension(const std::string& path);

}  // namespace pl
