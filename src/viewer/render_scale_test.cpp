// The CPU viewer's frame-rate controller (render_scale.h) driven by modelled frame times: a
// frame at scale s costs fixed + perPixel · s² milliseconds. No clock: the decisions are a
// function of the times fed in.
#include "viewer/render_scale.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pl {
namespace {

struct CostModel {
  double fixedMs, fullMs;  ///< fixed part, and the proportional part at full resolution
  double at(double scale) const { return fixedMs + fullMs * scale * scale; }
};

/// Runs `frames` moving frames on `model` and returns the controller's last scale.
double settle(RenderScaleController& controller, const CostModel& model, int frames = 60) {
  for (int i = 0; i < frames; ++i) {
    const double s = controller.scale(true);
    controller.record(s, model.at(s));
  }
  return controller.scale(true);
}

TEST(RenderScale, CheapFramesStayAtFullResolution) {
  RenderScaleController controller(30.0);
  EXPECT_EQ(controller.scale(true), 1.0);  // no frame time yet
  EXPECT_EQ(settle(controller, {0.0, 5.0}), 1.0);
  EXPECT_EQ(controller.scale(false), 1.0);
}

TEST(RenderScale, ExpensiveFramesSettleOnTheLargestScaleWithinTheBudget) {
  // Sponza on the CPU at 1024×768: ≈ 144 ms per frame, 30 fps wanted.
  RenderScaleController controller(30.0);
  const CostModel model{0.0, 144.0};
  const double s = settle(controller, model);
  const double budget = 1000.0 / 30.0;
  EXPECT_LE(model.at(s), RenderScaleController::kHeadroom * budget + 1e-9);
  EXPECT_GT(model.at(s + RenderScaleController::kStep), RenderScaleController::kHeadroom * budget);
  EXPECT_DOUBLE_EQ(s, 7.0 / 16.0);  // √(0.85 · 33.3 / 144) = 0.444, down to the grid
  // Steady: no oscillation once settled.
  for (int i = 0; i < 20; ++i) {
    controller.record(s, model.at(s));
    EXPECT_EQ(controller.scale(true), s);
  }
}

TEST(RenderScale, FixedCostPerFrameStillMeetsTheBudget) {
  RenderScaleController controller(60.0);
  const CostModel model{4.0, 80.0};
  const double s = settle(controller, model, 200);
  EXPECT_LE(model.at(s), 1000.0 / 60.0);
  EXPECT_GT(model.at(s + RenderScaleController::kStep), RenderScaleController::kHeadroom * 1000.0 / 60.0);
}

TEST(RenderScale, StopsAtTheMinimumScale) {
  RenderScaleController controller(30.0);
  EXPECT_EQ(settle(controller, {0.0, 10000.0}), RenderScaleController::kMinimumScale);
}

TEST(RenderScale, StepsDownAtOnceAndUpOneStepPerFrame) {
  RenderScaleController controller(30.0);
  controller.record(1.0, 144.0);  // a first full-resolution frame
  EXPECT_DOUBLE_EQ(controller.scale(true), 7.0 / 16.0);
  // The scene becomes cheap (the camera turned to a wall): up by one step per frame.
  double previous = controller.scale(true);
  for (int i = 0; i < 30 && previous < 1.0; ++i) {
    controller.record(previous, 1.0 * previous * previous);
    const double next = controller.scale(true);
    EXPECT_LE(next, previous + RenderScaleController::kStep + 1e-12);
    EXPECT_GE(next, previous);
    previous = next;
  }
  EXPECT_EQ(previous, 1.0);
}

TEST(RenderScale, StillCameraIsFullResolutionAndMovingResumesTheLastScale) {
  RenderScaleController controller(30.0);
  settle(controller, {0.0, 144.0});
  const double moving = controller.scale(true);
  EXPECT_LT(moving, 1.0);
  EXPECT_EQ(controller.scale(false), 1.0);
  controller.record(1.0, 144.0);  // the full-resolution frame once stopped
  EXPECT_EQ(controller.scale(true), moving);
}

TEST(RenderScale, NoTargetMeansFullResolution) {
  RenderScaleController controller(0.0);
  EXPECT_EQ(settle(controller, {0.0, 1000.0}), 1.0);
  EXPECT_EQ(nextRenderScale(0.5, 100.0, 0.0), 1.0);
}

TEST(RenderScale, ScaledSizeRoundsAndKeepsAPixel) {
  int w = 0, h = 0;
  scaledSize(1024, 768, 7.0 / 16.0, w, h);
  EXPECT_EQ(w, 448);
  EXPECT_EQ(h, 336);
  scaledSize(3, 1, 0.25, w, h);
  EXPECT_EQ(w, 1);
  EXPECT_EQ(h, 1);
}

}  // namespace
}  // namespace pl
