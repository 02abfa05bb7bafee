// OpenEXR reading and writing: the only file that includes OpenEXR.
//
// Reading accepts scan-line or tiled single-part files with R, G, B channels (half, float or
// uint; A and any other channels are ignored) or a single luminance channel Y (replicated to
// grey), and any data window: the image covers the data window, so a file whose data window
// starts at (−10, 5) gives an image of the data window's size. Writing stores R, G, B as
// 32-bit float (exact) or 16-bit half, ZIP-compressed, data window = display window.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfTestFile.h>
#include <Imath/half.h>

#include <algorithm>
#include <cstdint>
#include <exception>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "image/image_io.h"

namespace pl::detail {

namespace {

/// OpenEXR trusts the sizes in a file's header: an attribute of unknown type claiming 2 GB is
/// allocated before the read finds that the file ends (found by fuzzing: a 209-byte file), and
/// so is a preview image of the size it declares. So the headers are walked first, the way
/// OpenEXR 3.1's Header::readFrom walks them — name, type, 32-bit declared size, value, until
/// an empty name; a multi-part file has one header per part and an empty one at the end — and
/// every allocation it would make is checked against the bytes that remain. OpenEXR reads the
/// value of a known fixed-size type by that size and a channel list up to its empty name,
/// whatever the declared size; everything else (strings, vectors, unknown types) by the
/// declared size. Nothing is allocated here.
void checkHeaderAllocations(const std::string& path, bool multiPart) {
  static const std::map<std::string, int> kFixedSizes = {
      {"box2i", 16}, {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
      {"double", 8}, {"envmap", 1}, {"float", 4}, {"int", 4}, {"keycode", 28}, {"lineOrder", 1},
      {"m33f", 36}, {"m33d", 72}, {"m44f", 64}, {"m44d", 128}, {"rational", 8}, {"tiledesc", 9},
      {"timecode", 8}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16}, {"v3i", 12}, {"v3f", 12}, {"v3d", 24}};
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const long long fileBytes = in.tellg();
  in.seekg(8);  // magic and version flags
  auto remaining = [&] { return fileBytes - (long long)in.tellg(); };
  auto readName = [&](std::string& name) {
    name.clear();
    for (char c; in.get(c) && c != '\0';)
      if (name.size() < 256) name += c;  // OpenEXR's longest names are 255 characters
    return bool(in);
  };
  auto tooBig = [&](const std::string& name, long long bytes) {
    fail("{}: corrupt OpenEXR header: attribute '{}' needs {} bytes, the file has {}", path, name, bytes, fileBytes);
  };
  std::string name, type, channel;
  for (size_t attributes = 1; attributes > 0 && in;) {
    attributes = 0;
    while (readName(name) && !name.empty()) {
      int32_t size = 0;
      if (!readName(type) || !in.read(reinterpret_cast<char*>(&size), 4))
        fail("{}: truncated OpenEXR header (attribute '{}')", path, name);
      if (size < 0) tooBig(name, size);
      if (const auto fixed = kFixedSizes.find(type); fixed != kFixedSizes.end()) {
        in.seekg(fixed->second, std::ios::cur);
      } else if (type == "chlist") {
        while (readName(channel) && !channel.empty()) in.seekg(16, std::ios::cur);  // type, pLinear, 3 reserved, x/y sampling
      } else if (type == "preview") {
        uint32_t dimensions[2] = {0, 0};
        in.read(reinterpret_cast<char*>(dimensions), 8);
        // RGBA8: 4·w·h bytes. w·h < 2⁶⁴ always, 4·w·h may not be: compare w·h with a quarter
        // of what remains instead (fuzzing found the overflow).
        const unsigned long long pixels = static_cast<unsigned long long>(dimensions[0]) * dimensions[1];
        if (pixels > static_cast<unsigned long long>(std::max(0LL, remaining())) / 4)
          tooBig(name, pixels > (1ULL << 61) ? std::numeric_limits<long long>::max() : static_cast<long long>(4 * pixels));
        in.seekg(static_cast<std::streamoff>(4 * pixels), std::ios::cur);
      } else {
        if (size > remaining()) tooBig(name, size);
        in.seekg(size, std::ios::cur);
      }
      ++attributes;
    }
    if (!multiPart) break;
  }
}

}  // namespace

Image readExr(const std::string& path) {
  bool tiled = false, deep = false, multiPart = false;
  if (!Imf::isOpenExrFile(path.c_str(), tiled, deep, multiPart))
    fail("{}: not an OpenEXR file (bad magic number or unreadable header)", path);
  if (deep) fail("{}: deep OpenEXR images are not supported", path);
  checkHeaderAllocations(path, multiPart);
  // Header::sanityCheck then refuses larger data windows and tiles before anything is
  // allocated for them (line-offset tables, tile buffers).
  static const bool limitsSet = [] {
    Imf::Header::setMaxImageSize(kMaxImageDimension, kMaxImageDimension);
    Imf::Header::setMaxTileSize(kMaxImageDimension, kMaxImageDimension);
    return true;
  }();
  (void)limitsSet;
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    const long long width = (long long)window.max.x - window.min.x + 1;
    const long long height = (long long)window.max.y - window.min.y + 1;
    checkImageSize(path, width, height);

    const Imf::ChannelList& channels = file.header().channels();
    const bool hasRgb = channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
    const bool hasY = channels.findChannel("Y") != nullptr;
    if (!hasRgb && !hasY) {
      std::string names;
      for (auto it = channels.begin(); it != channels.end(); ++it) names += std::string(names.empty() ? "" : ", ") + it.name();
      fail("{}: no R, G, B (or Y) channels; the file has: {}", path, names.empty() ? "none" : names);
    }
    for (const char* name : {"R", "G", "B", "Y"}) {
      const Imf::Channel* c = channels.findChannel(name);
      if (c && (c->xSampling != 1 || c->ySampling != 1))
        fail("{}: channel {} is subsampled ({}x{}); only full-resolution channels are supported", path, name,
             c->xSampling, c->ySampling);
    }

    // Before the pixels are allocated: a few hundred bytes may declare a data window of
    // 2^28 pixels (3 GB), but cannot also hold every chunk of it.
    if (!file.isComplete()) fail("{}: truncated OpenEXR file (pixel data incomplete)", path);
    Image image(static_cast<int>(width), static_cast<int>(height));
    const size_t xStride = sizeof(Rgb), yStride = sizeof(Rgb) * size_t(width);
    Imf::FrameBuffer frame;
    float* base = &image.pixels[0].r;
    if (hasRgb) {
      frame.insert("R", Imf::Slice::Make(Imf::FLOAT, base + 0, window, xStride, yStride));
      frame.insert("G", Imf::Slice::Make(Imf::FLOAT, base + 1, window, xStride, yStride));
      frame.insert("B", Imf::Slice::Make(Imf::FLOAT, base + 2, window, xStride, yStride));
    } else {
      frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, base + 0, window, xStride, yStride));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    if (!hasRgb)
      for (Rgb& p : image.pixels) p = Rgb(p.r);
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    fail("{}: corrupt or unreadable OpenEXR file: {}", path, e.what());
  }
}

void writeExr(const std::string& path, const Image& image, bool half) {
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
    for (const char* name : {"R", "G", "B"}) header.channels().insert(name, Imf::Channel(type));

    Imf::FrameBuffer frame;
    std::vector<Imath::half> halves;
    if (half) {
      // Values beyond the half range (±65504) become ±infinity, as OpenEXR's own conversion does.
      halves.resize(image.pixels.size() * 3);
      for (size_t i = 0; i < image.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) halves[3 * i + size_t(c)] = Imath::half(image.pixels[i][c]);
      const size_t xStride = 3 * sizeof(Imath::half), yStride = xStride * size_t(image.width);
      char* base = reinterpret_cast<char*>(halves.data());
      frame.insert("R", Imf::Slice(Imf::HALF, base + 0 * sizeof(Imath::half), xStride, yStride));
      frame.insert("G", Imf::Slice(Imf::HALF, base + 1 * sizeof(Imath::half), xStride, yStride));
      frame.insert("B", Imf::Slice(Imf::HALF, base + 2 * sizeof(Imath::half), xStride, yStride));
    } else {
      const size_t xStride = sizeof(Rgb), yStride = xStride * size_t(image.width);
      // OpenEXR's Slice takes a non-const pointer even for writing; it only reads through it.
      char* base = const_cast<char*>(reinterpret_cast<const char*>(image.pixels.data()));
      frame.insert("R", Imf::Slice(Imf::FLOAT, base + 0 * sizeof(float), xStride, yStride));
      frame.insert("G", Imf::Slice(Imf::FLOAT, base + 1 * sizeof(float), xStride, yStride));
      frame.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xStride, yStride));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    fail("OpenEXR: {}", e.what());
  }
}

}  // namespace pl::detail
