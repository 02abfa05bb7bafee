// Per-frame display encoding (see display.h).
#include "image/display.h"

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
  const int stride = kStatisticsStride;
  const int sw = (width + stride - 1) / stride, sh = (height + stride - 1) / stride;
  if (statistics_.width != sw || statistics_.height != sh) statistics_ = Image(sw, sh);
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x) statistics_.at(x, y) = radiance.at(x * stride, y * stride) * exposureScale;
  curve_ = resolveToneMap(statistics_, settings);
  const uint8_t* table = srgbTable_.data();
  const float scale = float(kSrgbTableSize - 1);
  parallelForRange(uint64_t(height), 16, [&](uint64_t begin, uint64_t end) {
    for (int y = int(begin); y < int(end); ++y) {
      uint32_t* row = reinterpret_cast<uint32_t*>(reinterpret_cast<uint8_t*>(pixels) + size_t(y) * size_t(pitchBytes));
      const Rgb* in = &radiance.pixels[size_t(y) * size_t(width)];
      for (int x = 0; x < width; ++x) {
        const Rgb d = curve_.apply(in[x] * exposureScale);
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
