#pragma once
// Exposure: the factor from scene radiance to pixel value.
//
//   pixel value = exposureScale · vignetting(θ) · L      (camera.h for vignetting and L)
//
// exposureScale is
//   * 1 when no exposure is given: an image then holds radiance itself (W·sr⁻¹·m⁻²);
//   * 2^EV for a plain exposure compensation --exposure EV (EV = +1 doubles pixel values);
//   * the saturation-based exposure of ISO 12232 for photographic settings (f-number N,
//     shutter time t in seconds, ISO speed S):
//         EV100 = log2(N²/t · 100/S)
//         H     = 1 / L_max,   L_max = (78 / (q·S)) · N²/t = 1.2 · 2^EV100   (q = 0.65)
//     L_max is the scene luminance (cd/m²) that just saturates the sensor, so a pixel value
//     of 1 means "saturated": pixel = L / L_max. A longer shutter or a higher ISO raises H in
//     proportion; one stop of N (×√2) halves it (the aperture area is ∝ 1/N², the tri-Ace
//     talk's "brightness ∝ aperture area / (sensor–aperture distance)²").
//     Radiometric RGB radiance is used as if its luminance Y were in cd/m² (no 683 lm/W
//     factor), as real-time engines do.
//   * both: H · 2^EV (the compensation applies on top of the photographic exposure).
#include <optional>
#include <string_view>

namespace pl {

struct PhotographicExposure {
  float fNumber = 16.0f;          ///< N
  float shutterSeconds = 0.008f;  ///< t
  float iso = 100.0f;             ///< S
};

/// log2(N²/t · 100/S). Throws pl::Error unless N, t, S are positive and finite.
double ev100(const PhotographicExposure& settings);
/// 1 / (1.2 · 2^EV100): the saturation-based exposure H.
double saturationExposure(double ev100Value);

struct ExposureSettings {
  std::optional<float> compensationEv;              ///< --exposure EV
  std::optional<PhotographicExposure> photographic;  ///< --fstop/--shutter/--iso
};

/// The photographic exposure of an f-number, a shutter time and an ISO speed given all three;
/// none when none is given. One or two of them throw pl::UsageError "<names>: give all three
/// (photographic exposure) or none": the one home of that rule, where the command line, the
/// jobs and the Python module each name their own flags or keywords in `names`.
std::optional<PhotographicExposure> photographicExposure(std::optional<float> fNumber,
                                                         std::optional<float> shutterSeconds,
                                                         std::optional<float> iso, std::string_view names);

/// The multiplier from radiance to pixel value described above (1 when nothing is set).
float exposureScale(const ExposureSettings& settings);

}  // namespace pl
