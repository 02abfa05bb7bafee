#pragma once
// How the viewer shares the cores between its CPU renderer and the live relighting's
// background thread (live_relight.h): the one home of that policy. The viewer (viewer.cpp) and
// `relight_bench --live` ask coreShare() before every frame and apply its answer — the
// renderer's thread count (a task arena of that many threads: core/parallel.h runWithThreads),
// the frame rate the render scale holds (render_scale.h), and a frame cap; the relighter's
// thread sets its own priority once (applyRelightPriority). No clock and no SDL here: the
// answers are a pure function of the state (core_share_test).
//
// The policies (RelightShare), while the relighter works (its set-up, or a relight until it
// converges, is cancelled or refused) and the CPU renderer draws:
//   Split (the default): the relighter's one thread at normal priority keeps one core; the
//     renderer gets the pool's threads − 1 (at least 1), and holds kRelightTargetFps (or the
//     user's lower target) by lowering its internal resolution. On two cores: one core each.
//   Cap: the renderer keeps every thread but draws at most kRelightTargetFps frames a second
//     (the rest of each frame's 1/15 s it sleeps), at the scale that holds that rate; the
//     relighter at normal priority takes what the frames leave, and competes for a core during
//     a frame.
//   Idle: the relighter under Linux's SCHED_IDLE (nice +19 where refused), the renderer every
//     thread at the user's target: the relighter runs only on a core no ordinary thread wants,
//     so frames drawn back to back starve it (docs/benchmarks.md, Relighting).
//   Nice: the relighter at nice +10, the renderer as under Idle (for comparison).
// Otherwise — nothing to relight, or the GPU renderer drawing the baked light field — the
// renderer has the whole pool and the user's target (0 = full resolution).
#include <functional>

#include "viewer/render_scale.h"

namespace pl {

/// The core-sharing policy (`relight_bench --share`; the viewer uses Split).
enum class RelightShare { Split, Cap, Idle, Nice };

/// The frame rate held while the relighter works (Split, Cap), unless the user's is lower.
constexpr double kRelightTargetFps = 15.0;

/// What a frame does (see the top of this file).
struct CoreShare {
  int renderThreads = 0;   ///< the renderer's threads: 0 = the pool's (no arena), else that many
  double targetFps = 0.0;  ///< the frame rate the render scale holds (0 = full resolution)
  double minFrameSeconds = 0.0;  ///< a frame lasts at least this long (Cap; 0 = no cap)
  bool relighting = false; ///< the relighter's share applies (its own target and render-scale state)
};

/// The share of the next frame. poolThreads: the pool's thread count (parallelThreads() of
/// core/parallel.h); relighterBusy: the relighter is setting up or relighting (LiveRelight::
/// busy); cpuDraws: the CPU renderer draws the frame; userTargetFps: --target-fps (0 = none).
CoreShare coreShare(RelightShare share, int poolThreads, bool relighterBusy, bool cpuDraws, double userTargetFps);

/// A session's frame-rate controllers (render_scale.h): one for the frames beside the working
/// relighter (CoreShare::relighting), one for the others, each learning its own frame times
/// (the renderer's thread count differs between them), and started again when its target changes.
class ShareScale {
 public:
  RenderScaleController& operator()(const CoreShare& share);

 private:
  RenderScaleController normal_{0.0}, relighting_{0.0};
};

/// Runs draw() (a frame's rendering) on share.renderThreads threads of the pool (a task arena
/// of its own: core/parallel.h runWithThreads), or on the whole pool when that is 0.
void drawWithShare(const CoreShare& share, const std::function<void()>& draw);

/// Sets the calling thread's (the relighter's) priority for `share`: normal for Split and
/// Cap, SCHED_IDLE (else nice +19) for Idle, nice +10 for Nice. Linux only; elsewhere nothing.
void applyRelightPriority(RelightShare share);

/// The policy's name ("split", "cap", "idle", "nice") and back; false for an unknown name.
const char* relightShareName(RelightShare share);
bool parseRelightShare(const char* name, RelightShare& share);

}  // namespace pl
