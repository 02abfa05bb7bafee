// The viewer's core-sharing policy (core_share.h): the split while the relighter works, the
// switch back when it is done, and the renderer's thread limit as a real one.
#include "viewer/core_share.h"

#include <gtest/gtest.h>

#include <mutex>
#include <set>
#include <thread>

#include "core/parallel.h"

namespace pl {
namespace {

TEST(CoreShare, SplitGivesTheRelighterOneCoreAndTheRendererTheRest) {
  const CoreShare s = coreShare(RelightShare::Split, 2, /*relighterBusy=*/true, /*cpuDraws=*/true, 30.0);
  EXPECT_TRUE(s.relighting);
  EXPECT_EQ(s.renderThreads, 1);
  EXPECT_EQ(s.targetFps, kRelightTargetFps);
  EXPECT_EQ(s.minFrameSeconds, 0.0);
  EXPECT_EQ(coreShare(RelightShare::Split, 16, true, true, 30.0).renderThreads, 15);
  EXPECT_EQ(coreShare(RelightShare::Split, 1, true, true, 30.0).renderThreads, 1);  // never none
  // The user's lower target, or none (full resolution), is kept.
  EXPECT_EQ(coreShare(RelightShare::Split, 2, true, true, 10.0).targetFps, 10.0);
  EXPECT_EQ(coreShare(RelightShare::Split, 2, true, true, 0.0).targetFps, 0.0);
}

TEST(CoreShare, TheRendererGetsThePoolBackWhenTheRelighterIsDone) {
  for (RelightShare share : {RelightShare::Split, RelightShare::Cap, RelightShare::Idle, RelightShare::Nice}) {
    const CoreShare s = coreShare(share, 2, /*relighterBusy=*/false, true, 30.0);
    EXPECT_FALSE(s.relighting) << relightShareName(share);
    EXPECT_EQ(s.renderThreads, 0);
    EXPECT_EQ(s.targetFps, 30.0);
    EXPECT_EQ(s.minFrameSeconds, 0.0);
  }
}

TEST(CoreShare, TheGpuDrawingLeavesBothCoresToTheRelighter) {
  const CoreShare s = coreShare(RelightShare::Split, 2, true, /*cpuDraws=*/false, 30.0);
  EXPECT_FALSE(s.relighting);
  EXPECT_EQ(s.renderThreads, 0);
  EXPECT_EQ(s.targetFps, 0.0);  // every GPU frame at full resolution
}

TEST(CoreShare, TheOtherPolicies) {
  const CoreShare cap = coreShare(RelightShare::Cap, 2, true, true, 30.0);
  EXPECT_TRUE(cap.relighting);
  EXPECT_EQ(cap.renderThreads, 0);
  EXPECT_EQ(cap.targetFps, kRelightTargetFps);
  EXPECT_DOUBLE_EQ(cap.minFrameSeconds, 1.0 / kRelightTargetFps);
  for (RelightShare share : {RelightShare::Idle, RelightShare::Nice}) {
    const CoreShare s = coreShare(share, 2, true, true, 30.0);
    EXPECT_FALSE(s.relighting);
    EXPECT_EQ(s.renderThreads, 0);
    EXPECT_EQ(s.targetFps, 30.0);
  }
  for (RelightShare share : {RelightShare::Split, RelightShare::Cap, RelightShare::Idle, RelightShare::Nice}) {
    RelightShare parsed = RelightShare::Nice;
    ASSERT_TRUE(parseRelightShare(relightShareName(share), parsed));
    EXPECT_EQ(parsed, share);
  }
  RelightShare unchanged = RelightShare::Cap;
  EXPECT_FALSE(parseRelightShare("half", unchanged));
  EXPECT_EQ(unchanged, RelightShare::Cap);
}

TEST(CoreShare, EachShareHasItsOwnFrameRateController) {
  ShareScale scales;
  const CoreShare relighting = coreShare(RelightShare::Split, 2, true, true, 30.0);
  const CoreShare alone = coreShare(RelightShare::Split, 2, false, true, 30.0);
  // Slow frames beside the relighter lower its scale only.
  for (int i = 0; i < 4; ++i) scales(relighting).record(1.0, 4000.0 / kRelightTargetFps);
  EXPECT_EQ(scales(relighting).targetFps(), kRelightTargetFps);
  EXPECT_LT(scales(relighting).scale(true), 0.5);
  EXPECT_EQ(scales(alone).targetFps(), 30.0);
  EXPECT_EQ(scales(alone).scale(true), 1.0);  // no frame time yet
  // Either way a still camera gets full resolution.
  EXPECT_EQ(scales(relighting).scale(false), 1.0);
  // A new target starts the controller again.
  EXPECT_EQ(scales(coreShare(RelightShare::Split, 2, true, true, 10.0)).scale(true), 1.0);
}

TEST(CoreShare, TheRenderersThreadLimitIsTheArenas) {
  const ThreadPool pool(2);
  EXPECT_EQ(parallelThreads(), 2);
  // One render thread: every iteration of a parallel loop on the calling thread.
  const CoreShare one = coreShare(RelightShare::Split, parallelThreads(), true, true, 30.0);
  ASSERT_EQ(one.renderThreads, 1);
  std::mutex mutex;
  std::set<std::thread::id> threads;
  drawWithShare(one, [&] {
    parallelFor(4096, [&](uint64_t) {
      volatile double x = 0.0;
      for (int k = 0; k < 200; ++k) x = x + double(k);
      const std::lock_guard lock(mutex);
      threads.insert(std::this_thread::get_id());
    });
  });
  ASSERT_EQ(threads.size(), 1u);
  EXPECT_EQ(*threads.begin(), std::this_thread::get_id());
}

}  // namespace
}  // namespace pl
