// Per-frame display encoding (see display.h).
#include "realtime/display.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"

namespace pl {

DisplayEncoder::DisplayEncoder() : srgbTable_(kSrgbTableSize) {
  for (int i = 0; i < kSrgbTableSize; ++i) {
    const float v = float(i) / float(kSrgbTableSize - 1);
    srgbTable_[size_t(i)] = uint8_t(std::lround(std::clamp(linearToSrgb(v), 0.0f, 1.0f) * 255.0f));
  }
}

void DisplayEncoder::encode(const Image& radiance, float exposureScale, const ToneMapSettings& settings,
                            uint32_t* pixels, int pitchBytes) {
  const int width = radiance.width, height = radiance.height;
  if (exposed_.width != width || exposed_.height != height) exposed_ = Image(width, height);
  parallelForRange(uint64_t(height), 16, [&](uint64_t begin, uint64_t end) {
    for (size_t i = size_t(begin) * size_t(width); i < size_t(end) * size_t(width); ++i)
      exposed_.pixels[i] = radiance.pixels[i] * exposureScale;
  });
  curve_ = resolveToneMap(exposed_, settings);
  const uint8_t* table = srgbTable_.data();
  const float scale = float(kSrgbTableSize - 1);
  parallelForRange(uint64_t(height), 16, [&](uint64_t begin, uint64_t end) {
    for (int y = int(begin); y < int(end); ++y) {
      uint32_t* row = reinterpret_cast<uint32_t*>(reinterpret_cast<uint8_t*>(pixels) + size_t(y) * size_t(pitchBytes));
      const Rgb* in = &exposed_.pixels[size_t(y) * size_t(width)];
      for (int x = 0; x < width; ++x) {
        const Rgb d = curve_.apply(in[x]);
        if (!isFinite(d)) {
          row[x] = 0xFFFF00FFu;  // magenta, as encodeSrgb8
          continue;
        }
        auto channel = [&](float v) { return uint32_t(table[size_t(std::clamp(v, 0.0f, 1.0f) * scale + 0.5f)]); };
        row[x] = 0xFF000000u | (channel(d.r) << 16) | (channel(d.g) << 8) | channel(d.b);
      }
    }
  });
}

}  // namespace pl
