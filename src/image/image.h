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
//   .jpg/.jpeg/.tga/.bmp  8-bit sRGB           read only (decoded to linear)
// Writes are atomic: a temporary file beside the target is renamed over it on success, so a
// failed write never leaves a half-written file.
//
// Tone mapping (Image → Image8) is in image/tonemap.h, error metrics in image/compare.h, and
// picture output (a rendered frame to a file, image sequences, MP4 video, the per-frame display
// encoding) in image/frame_output.h and image/display.h.
#include "core/file_io.h"  // fileExtensionLower
#include "core/math.h"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
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

/// Limits on the size of an image file we accept (reading) or produce (writing): a header
/// claiming more is treated as corrupt rather than allocating gigabytes.
inline constexpr int kMaxImageDimension = 65536;          ///< pixels per side
inline constexpr uint64_t kMaxImagePixels = 1ull << 28;  ///< 268 M pixels = 3.2 GB of floats

/// sRGB transfer function (IEC 61966-2-1) and its inverse, per channel. linearToSrgb clamps
/// its input to [0, 1] (NaN gives 0); srgbToLinear expects [0, 1].
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

/// What the channels of an 8-bit (or 16-bit PNG) image become in an Image's RGB. The value
/// is stored in .plf files: never renumber.
enum class ImageDecode : uint8_t {
  Colour = 0,    ///< sRGB-encoded colour decoded to linear (albedo textures, photographs)
  Data = 1,      ///< value / maximum as stored, no transfer function (normal maps)
  Coverage = 2,  ///< the alpha channel (grey + alpha, RGBA) or, in an image without one, the
                 ///< first channel, value / maximum, repeated in R, G and B (alpha masks)
};

/// The image file types by extension (lower case, with the dot; the table at the top): the one
/// list readImage, writeHdrImage, writeFrame (frame_output.h), the commands' output checks and
/// the cube-face search of env/ follow. HDR formats hold linear floats and are read and
/// written as they are; 8-bit formats are read (decoded as ImageDecode says), and of them
/// only PNG is written (tone-mapped).
inline constexpr std::array<std::string_view, 3> kHdrImageExtensions = {".exr", ".hdr", ".pfm"};
inline constexpr std::array<std::string_view, 5> kLdrImageExtensions = {".png", ".jpg", ".jpeg", ".tga", ".bmp"};
/// What a rendered image may be written as (writeFrame): the HDR formats and PNG.
inline constexpr std::array<std::string_view, 4> kWrittenImageExtensions = {
    kHdrImageExtensions[0], kHdrImageExtensions[1], kHdrImageExtensions[2], kLdrImageExtensions[0]};

/// Reads an HDR image (.exr, .hdr, .pfm) or an 8-bit one (.png, .jpg, .tga, .bmp: decoded as
/// `decode` says; grey images repeat their channel). HDR files are linear already: Colour and
/// Data read them as they are, Coverage takes their red channel. Throws pl::Error naming the
/// file and the problem (missing, truncated, corrupt, unsupported variant, absurd size,
/// unknown extension).
Image readImage(const std::string& path, ImageDecode decode = ImageDecode::Colour);

/// Interleaved texels as an Image: `channels` values per pixel (1 grey, 2 grey + alpha, 3 RGB,
/// 4 RGBA) of 8 or 16 bits (native byte order), row-major, top row first, decoded as `decode`
/// says. The one conversion every 8/16-bit image reader (stb, glTF buffers) uses.
Image decodeTexels(const void* texels, int bitsPerChannel, int width, int height, int channels, ImageDecode decode);

/// True for the extensions (lower case, with the dot) of the 8-bit formats (kLdrImageExtensions).
bool isLdrImageExtension(const std::string& extension);

/// An image file as a texture keeps it: the decoded pixels (as readImage gives them) and, for
/// the 8-bit formats, the file's own bytes (else empty: HDR files are kept decoded only), so
/// that a light-field file can embed the compact encoded file instead of float pixels.
struct ImageFile {
  Image image;
  std::vector<unsigned char> ldrBytes;
};
ImageFile readImageFile(const std::string& path, ImageDecode decode = ImageDecode::Colour);

/// Decodes an 8-bit-format image held in memory (PNG, JPEG, TGA, BMP, recognised from the
/// content; a file's bytes, a glTF buffer, a .plf's embedded texture) as `decode` asks (sRGB
/// colour to linear, raw data, or coverage): the same pixels readImage gives for the same
/// bytes in a file. The size is checked
/// (kMaxImagePixels) before decoding. Throws pl::Error starting with `label` when the bytes are
/// corrupt, truncated or not an image.
Image decodeLdrImage(std::span<const unsigned char> bytes, const std::string& label,
                     ImageDecode decode = ImageDecode::Colour);
/// Whether 8-bit-format image bytes hold an alpha channel (grey + alpha or RGBA); false for
/// bytes that are not a recognisable image (decodeLdrImage reports those).
bool ldrImageHasAlphaChannel(std::span<const unsigned char> bytes);

/// How writeHdrImage stores pixels where the format offers a choice.
struct HdrWriteOptions {
  bool exrHalf = false;  ///< EXR: 16-bit half floats instead of 32-bit floats
};

/// Writes linear pixels to .exr/.hdr/.pfm as they are (atomic). Throws pl::Error on failure,
/// including an unknown extension, an empty image, and non-finite pixels for .hdr (RGBE
/// cannot store them; EXR and PFM keep NaN/Inf). RGBE clamps negative values to 0.
void writeHdrImage(const std::string& path, const Image& image, const HdrWriteOptions& options = {});
/// Writes an already tone-mapped 8-bit image as PNG (atomic).
void writePng(const std::string& path, const Image8& image);
/// True for the extensions writeHdrImage accepts (kHdrImageExtensions; case-insensitive).
bool isHdrExtension(const std::string& path);

}  // namespace pl
