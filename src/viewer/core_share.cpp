// The viewer's core-sharing policy while relighting (core_share.h).
#include "viewer/core_share.h"

#include <algorithm>
#include <cstring>

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "core/parallel.h"

namespace pl {
namespace {
constexpr int kBackgroundNice = 10, kIdleNice = 19;
constexpr const char* kNames[] = {"split", "cap", "idle", "nice"};
}  // namespace

CoreShare coreShare(RelightShare share, int poolThreads, bool relighterBusy, bool cpuDraws, double userTargetFps) {
  CoreShare s;
  if (!cpuDraws) return s;  // the GPU draws: the pool's threads, every frame at full resolution
  s.targetFps = std::max(0.0, userTargetFps);
  if (!relighterBusy || share == RelightShare::Idle || share == RelightShare::Nice) return s;
  s.relighting = true;
  // The user's target when it is lower (0 keeps every frame at full resolution).
  if (s.targetFps > 0.0) s.targetFps = std::min(s.targetFps, kRelightTargetFps);
  if (share == RelightShare::Split) s.renderThreads = std::max(1, poolThreads - 1);
  else s.minFrameSeconds = 1.0 / kRelightTargetFps;
  return s;
}

RenderScaleController& ShareScale::operator()(const CoreShare& share) {
  RenderScaleController& controller = share.relighting ? relighting_ : normal_;
  if (controller.targetFps() != share.targetFps) controller = RenderScaleController(share.targetFps);
  return controller;
}

void drawWithShare(const CoreShare& share, const std::function<void()>& draw) {
  if (share.renderThreads > 0) runWithThreads(share.renderThreads, draw);
  else draw();
}

void applyRelightPriority(RelightShare share) {
#if defined(__linux__)
  // SCHED_IDLE: CFS weight 3 against nice 0's 1024, and preempted at once when an ordinary
  // thread wakes; nice +10: weight 110; nice +19: weight 15.
  if (share == RelightShare::Idle) {
    const sched_param none{};
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &none) == 0) return;
  }
  if (share == RelightShare::Idle || share == RelightShare::Nice)
    setpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)), share == RelightShare::Idle ? kIdleNice : kBackgroundNice);
#else
  (void)share;
#endif
}

const char* relightShareName(RelightShare share) { return kNames[int(share)]; }

bool parseRelightShare(const char* name, RelightShare& share) {
  for (int i = 0; i < int(sizeof(kNames) / sizeof(kNames[0])); ++i)
    if (std::strcmp(name, kNames[i]) == 0) {
      share = RelightShare(i);
      return true;
    }
  return false;
}

}  // namespace pl
