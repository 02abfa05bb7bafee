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

const ToneMapCurve& DisplayEncoder::resolveCurve(const Image& radianceSubsample, float exposureScale,
                                                 const ToneMapSettings& settings) {
  if (statistics_.width != radianceSubsample.width || statistics_.height != radianceSubsample.height)
    statistics_ = Image(radianceSubsample.width, radianceSubsample.height);
  for (size_t i = 0; i < radianceSubsample.pixels.size(); ++i)
    statistics_.pixels[i] = radianceSubsample.pixels[i] * exposureScale;
  curve_ = resolveToneMap(statistics_, settings);
  return curve_;
}

void DisplayEncoder::encode(const Image& radiance, float exposureScale, const ToneMapSettings& settings,
                            uint32_t* pixels, int pitchBytes) {
  const int width = radiance.width, height = radiance.height;
  const int stride = kStatisticsStride;
  const int sw = statisticsSize(width), sh = statisticsSize(height);
  if (subsample_.width != sw || subsample_.height != sh) subsample_ = Image(sw, sh);
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x) subsample_.at(x, y) = radiance.at(x * stride, y * stride);
  const ToneMapCurve& curve = resolveCurve(subsample_, exposureScale, settings);
  parallelForRange(uint64_t(height), 16, [&](uint64_t begin, uint64_t end) {
    for (int y = int(begin); y < int(end); ++y) {
      uint32_t* row = reinterpret_cast<uint32_t*>(reinterpret_cast<uint8_t*>(pixels) + size_t(y) * size_t(pitchBytes));
      const Rgb* in = &radiance.pixels[size_t(y) * size_t(width)];
      for (int x = 0; x < width; ++x) row[x] = word(curve, in[x] * exposureScale);
    }
  });
}

}  // namespace pl
