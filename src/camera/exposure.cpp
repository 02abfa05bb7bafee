// Photographic exposure (formulas and units in exposure.h).
#include "camera/exposure.h"

#include <cmath>

#include "core/error.h"

namespace pl {

double ev100(const PhotographicExposure& s) {
  auto positive = [](float v) { return v > 0.0f && std::isfinite(v); };
  if (!positive(s.fNumber)) fail("exposure: f-number {} must be positive", s.fNumber);
  if (!positive(s.shutterSeconds)) fail("exposure: shutter time {} s must be positive", s.shutterSeconds);
  if (!positive(s.iso)) fail("exposure: ISO {} must be positive", s.iso);
  const double n = s.fNumber;
  return std::log2(n * n / double(s.shutterSeconds) * 100.0 / double(s.iso));
}

std::optional<PhotographicExposure> photographicExposure(std::optional<float> fNumber,
                                                         std::optional<float> shutterSeconds,
                                                         std::optional<float> iso, std::string_view names) {
  const int given = int(fNumber.has_value()) + int(shutterSeconds.has_value()) + int(iso.has_value());
  if (given == 0) return std::nullopt;
  if (given != 3) failUsage("{}: give all three (photographic exposure) or none", names);
  return PhotographicExposure{*fNumber, *shutterSeconds, *iso};
}

double saturationExposure(double ev100Value) { return 1.0 / (1.2 * std::exp2(ev100Value)); }

float exposureScale(const ExposureSettings& settings) {
  double scale = 1.0;
  if (settings.photographic) scale = saturationExposure(ev100(*settings.photographic));
  if (settings.compensationEv) {
    if (!std::isfinite(*settings.compensationEv)) fail("exposure: compensation {} EV must be finite", *settings.compensationEv);
    scale *= std::exp2(double(*settings.compensationEv));
  }
  return float(scale);
}

}  // namespace pl
