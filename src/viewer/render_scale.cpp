// The CPU viewer's frame-rate controller (render_scale.h).
#include "viewer/render_scale.h"

#include <algorithm>
#include <cmath>

namespace pl {

double nextRenderScale(double scale, double fullMs, double budgetMs) {
  if (!(budgetMs > 0.0) || !(fullMs > 0.0)) return 1.0;
  const double ideal = std::sqrt(RenderScaleController::kHeadroom * budgetMs / fullMs);
  // Down to the grid (the small epsilon keeps an exact grid value from rounding one step down).
  const double step = RenderScaleController::kStep;
  double next = std::floor(ideal / step + 1e-9) * step;
  next = std::clamp(next, RenderScaleController::kMinimumScale, 1.0);
  if (next > scale) next = std::min(next, scale + step);  // up one step per frame
  return next;
}

RenderScaleController::RenderScaleController(double targetFps) : targetFps_(targetFps) {}

void RenderScaleController::record(double scale, double frameMs) {
  if (!(targetFps_ > 0.0) || !(scale > 0.0) || !(frameMs >= 0.0)) return;
  const double fullMs = frameMs / (scale * scale);
  fullMsEstimate_ = fullMsEstimate_ > 0.0 ? 0.5 * (fullMsEstimate_ + fullMs) : fullMs;
  movingScale_ = nextRenderScale(movingScale_, fullMsEstimate_, 1000.0 / targetFps_);
}

void scaledSize(int width, int height, double scale, int& scaledWidth, int& scaledHeight) {
  scaledWidth = std::max(1, int(std::lround(width * scale)));
  scaledHeight = std::max(1, int(std::lround(height * scale)));
}

}  // namespace pl
