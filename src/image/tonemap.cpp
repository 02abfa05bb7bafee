// Global tone-mapping operators; see tonemap.h for the formulas and their sources.
#include "image/tonemap.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"

namespace pl {

ToneMapOperator parseToneMapOperator(const std::string& name) {
  if (name == "reinhard") return ToneMapOperator::Reinhard;
  if (name == "linear") return ToneMapOperator::Linear;
  if (name == "clamp") return ToneMapOperator::Clamp;
  fail("unknown tone-mapping operator '{}' (use reinhard, linear or clamp)", name);
}

const char* toneMapOperatorName(ToneMapOperator op) {
  switch (op) {
    case ToneMapOperator::Reinhard: return "reinhard";
    case ToneMapOperator::Linear: return "linear";
    case ToneMapOperator::Clamp: return "clamp";
  }
  return "?";
}

namespace {

// Rec.709 YUV (analog form, ITU-R BT.709 luma weights): Y is relative luminance,
// U = (B − Y)/1.8556 and V = (R − Y)/1.5748 are the scaled colour differences.
struct Yuv {
  float y, u, v;
};
Yuv rgbToYuv(const Rgb& c) {
  const float y = luminance(c);
  return {y, (c.b - y) / 1.8556f, (c.r - y) / 1.5748f};
}
Rgb yuvToRgb(const Yuv& p) {
  const float r = p.y + 1.5748f * p.v;
  const float b = p.y + 1.8556f * p.u;
  const float g = (p.y - 0.2126f * r - 0.0722f * b) / 0.7152f;
  return {r, g, b};
}

Rgb clip01(const Rgb& c) { return glm::clamp(c, Rgb(0.0f), Rgb(1.0f)); }

/// Finite luminances of the image (non-finite pixels excluded).
std::vector<float> finiteLuminances(const Image& image) {
  std::vector<float> values;
  values.reserve(image.pixels.size());
  for (const Rgb& p : image.pixels)
    if (isFinite(p)) values.push_back(luminance(p));
  return values;
}

}  // namespace

Rgb ToneMapCurve::apply(const Rgb& exposed) const {
  if (!isFinite(exposed)) return Rgb(std::nanf(""));
  switch (op) {
    case ToneMapOperator::Reinhard: {
      const Yuv yuv = rgbToYuv(exposed);
      if (!(yuv.y > 0.0f)) return Rgb(0.0f);
      const float l = luminanceScale * yuv.y;
      const float ld = std::isinf(whiteScaled) ? l / (1.0f + l) : l * (1.0f + l / (whiteScaled * whiteScaled)) / (1.0f + l);
      // Keep the chromaticity: U and V scale with Y (see tonemap.h).
      const float s = ld / yuv.y;
      return clip01(yuvToRgb({ld, yuv.u * s, yuv.v * s}));
    }
    case ToneMapOperator::Linear:
      return clip01(exposed * luminanceScale);
    case ToneMapOperator::Clamp: {
      const Rgb c = glm::max(exposed, Rgb(0.0f));
      const float m = maxComponent(c);
      return m > 1.0f ? c / m : c;
    }
  }
  return exposed;
}

float logAverageLuminance(const Image& image) {
  double sum = 0.0;
  size_t count = 0;
  for (const Rgb& p : image.pixels) {
    if (!isFinite(p)) continue;
    sum += logLuminanceTerm(p);
    ++count;
  }
  return count ? float(std::exp(sum / double(count))) : 0.0f;
}

float automaticKey(const Image& image) {
  std::vector<float> values = finiteLuminances(image);
  std::erase_if(values, [](float y) { return !(y > 0.0f); });
  if (values.empty()) return kDefaultKey;
  auto percentile = [&](double q) {
    const size_t k = std::min(values.size() - 1, size_t(q * double(values.size() - 1) + 0.5));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
    return values[k];
  };
  const double lmin = std::log2(double(percentile(0.01)));
  const double lmax = std::log2(double(percentile(0.99)));
  if (!(lmax - lmin > 1e-6)) return kDefaultKey;
  const double lavg = std::log2(double(logAverageLuminance(image)));
  return float(0.18 * std::pow(4.0, (2.0 * lavg - lmin - lmax) / (lmax - lmin)));
}

ToneMapStatistics toneMapStatistics(const ToneMapSettings& settings) {
  if (settings.op != ToneMapOperator::Reinhard) return ToneMapStatistics::None;
  if (settings.autoKey) return ToneMapStatistics::Percentiles;
  return settings.key ? ToneMapStatistics::LogAverage : ToneMapStatistics::None;
}

namespace {

/// The curve of `settings` with Reinhard's key `key` (unset: none) for an image of
/// log-average luminance `logAverage` (read only with a key).
ToneMapCurve resolveWithKey(std::optional<float> key, float logAverage, const ToneMapSettings& settings) {
  ToneMapCurve curve;
  curve.op = settings.op;
  if (settings.white && !(*settings.white > 0.0f && std::isfinite(*settings.white)))
    fail("tone mapping: white point {} must be a positive number", *settings.white);
  switch (settings.op) {
    case ToneMapOperator::Reinhard:
      if (key) {
        if (!(*key > 0.0f && std::isfinite(*key))) fail("tone mapping: key {} must be a positive number", *key);
        curve.luminanceScale = logAverage > 0.0f ? *key / logAverage : 1.0f;
      }
      if (settings.white) curve.whiteScaled = *settings.white * curve.luminanceScale;
      break;
    case ToneMapOperator::Linear:
      curve.luminanceScale = settings.white ? 1.0f / *settings.white : 1.0f;
      break;
    case ToneMapOperator::Clamp:
      break;
  }
  return curve;
}

}  // namespace

ToneMapCurve resolveToneMap(const Image& exposed, const ToneMapSettings& settings) {
  const ToneMapStatistics statistics = toneMapStatistics(settings);
  const std::optional<float> key =
      statistics == ToneMapStatistics::Percentiles ? std::optional<float>(automaticKey(exposed)) : settings.key;
  return resolveWithKey(key, statistics == ToneMapStatistics::None ? 0.0f : logAverageLuminance(exposed), settings);
}

ToneMapCurve resolveToneMap(float logAverage, const ToneMapSettings& settings) {
  if (toneMapStatistics(settings) == ToneMapStatistics::Percentiles)
    fail("tone mapping: the automatic key needs the image's luminances, not only their log-average");
  return resolveWithKey(settings.key, logAverage, settings);
}

Image8 encodeSrgb8(const Image& display) {
  Image8 out{display.width, display.height, std::vector<uint8_t>(display.pixels.size() * 3)};
  for (size_t i = 0; i < display.pixels.size(); ++i) {
    const Rgb& p = display.pixels[i];
    uint8_t* dst = &out.rgb[3 * i];
    if (!isFinite(p)) {  // visible, not hidden: magenta
      dst[0] = 255, dst[1] = 0, dst[2] = 255;
      continue;
    }
    for (int c = 0; c < 3; ++c) dst[c] = uint8_t(std::lround(linearToSrgb(p[c]) * 255.0f));
  }
  return out;
}

Image8 toneMap(const Image& exposed, const ToneMapSettings& settings) {
  const ToneMapCurve curve = resolveToneMap(exposed, settings);
  Image display(exposed.width, exposed.height);
  for (size_t i = 0; i < exposed.pixels.size(); ++i) display.pixels[i] = curve.apply(exposed.pixels[i]);
  return encodeSrgb8(display);
}

}  // namespace pl
