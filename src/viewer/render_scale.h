#pragma once
// The CPU viewer's frame-rate controller: while the camera moves, the fast renderer draws the
// frame at a reduced internal resolution — scale·width × scale·height, upscaled to the window —
// chosen so that a frame fits the frame-rate target; when the camera stops, the frame is drawn
// at full resolution (scale 1). No SDL and no clock here: the viewer feeds it frame times, so
// its decisions are a pure function of those times (render_scale_test).
//
// The model: a frame's cost is proportional to its pixel count, so a frame of t ms at scale s
// costs t / s² at full resolution. The controller keeps that full-resolution estimate (the
// mean of the last estimate and the new one, which damps the noise of single frames) and picks
// the largest scale on a grid of kStep whose predicted time is within kHeadroom of the frame
// budget: s = √(kHeadroom · budget / estimate), rounded down to the grid, within
// [kMinimumScale, 1]. It steps down at once (a slow frame is felt immediately) and up one step
// per frame (so one fast frame does not overshoot). A fixed cost per frame (the display, the
// upscale) is not proportional to the pixels; the feedback still settles where the whole frame
// time is kHeadroom · budget whenever that fixed cost is below it.
namespace pl {

class RenderScaleController {
 public:
  static constexpr double kMinimumScale = 0.25;  ///< at most 16× fewer pixels
  static constexpr double kStep = 1.0 / 16.0;    ///< the grid of scales (fewer texture re-creations)
  static constexpr double kHeadroom = 0.85;      ///< aim at this share of the budget

  /// targetFps ≤ 0: no target, every frame at full resolution.
  explicit RenderScaleController(double targetFps);

  /// The linear scale of the next frame: 1 when the camera is still (or there is no target or
  /// no frame time yet), else the scale that holds the target.
  double scale(bool moving) const { return moving ? movingScale_ : 1.0; }
  /// Records a frame drawn at `scale` (at the settings' own samples per pixel) that took
  /// `frameMs` milliseconds, render and display; adjusts the moving scale.
  void record(double scale, double frameMs);

  double targetFps() const { return targetFps_; }

 private:
  double targetFps_;
  double fullMsEstimate_ = 0.0;  ///< 0 = no frame yet
  double movingScale_ = 1.0;
};

/// The next moving scale after a frame at `scale` when a full-resolution frame is estimated
/// at `fullMs` ms and the budget is `budgetMs` (RenderScaleController's rule, alone).
double nextRenderScale(double scale, double fullMs, double budgetMs);

/// The internal image size at `scale` of a width × height window (each side at least 1 pixel).
void scaledSize(int width, int height, double scale, int& scaledWidth, int& scaledHeight);

}  // namespace pl
