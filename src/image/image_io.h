#pragma once
// Private to the image module: one reader/writer pair per file format, each in the one .cpp
// that includes its third-party library. image.cpp dispatches on the extension and makes
// writes atomic. Readers throw pl::Error naming `path`; writers write to `path` (a temporary
// file) and throw pl::Error describing the problem *without* the path, which image.cpp
// prefixes with the user's target name.
#include <span>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "image/image.h"

namespace pl::detail {

// exr_io.cpp (OpenEXR)
Image readExr(const std::string& path);
void writeExr(const std::string& path, const Image& image, bool half);

// stb_io.cpp (stb_image / stb_image_write) and the Radiance RGBE format
/// PNG/JPEG/TGA/BMP bytes (format recognised from the content) decoded as `decode` asks
/// (decodeTexels: sRGB colour, raw data or coverage, channels as stored); `label` names them in
/// errors. mustBePng: refuse anything without the PNG signature (a file named .png); PNG
/// content is always checked for truncated chunks first.
Image decodeLdr(std::span<const unsigned char> bytes, const std::string& label, bool mustBePng, ImageDecode decode);
/// Channels stored in PNG/JPEG/TGA/BMP bytes (1–4), 0 when they are not such an image.
int ldrChannelCount(std::span<const unsigned char> bytes);
void writePngFile(const std::string& path, const Image8& image);
Image readRadianceHdr(const std::string& path);
void writeRadianceHdr(const std::string& path, const Image& image);

// pfm_io.cpp
Image readPfm(const std::string& path);
void writePfm(const std::string& path, const Image& image);

/// The whole file as bytes; pl::Error "<path>: no such file" / "cannot read: <reason>".
std::vector<unsigned char> readFileBytes(const std::string& path);
// Writing bytes: pl::writeFileBytes (core/file_io.h), called on the temporary of an atomic write.

/// Throws pl::Error "<path>: image size W×H ..." unless 1 ≤ W,H ≤ kMaxImageDimension and
/// W·H ≤ kMaxImagePixels.
void checkImageSize(const std::string& path, long long width, long long height);

}  // namespace pl::detail
