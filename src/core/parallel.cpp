#include "core/parallel.h"

#include "core/cancel.h"

#include <pmmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>
#include <xmmintrin.h>

#include <algorithm>
#include <optional>

namespace pl {

void enableFlushDenormals() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

namespace {
class DenormalObserver : public tbb::task_scheduler_observer {
 public:
  DenormalObserver() { observe(true); }
  ~DenormalObserver() override { observe(false); }
  void on_scheduler_entry(bool) override { enableFlushDenormals(); }
};

/// Installs the observer once per process (thread-safe static initialisation) and sets FTZ/DAZ
/// on the calling thread, which takes part in the loops it starts. The observer is never
/// destroyed: worker threads may outlive any object that owns it (until TBB shuts down).
void ensureDenormalObserver() {
  static DenormalObserver* const observer = new DenormalObserver();
  (void)observer;
  enableFlushDenormals();
}
}  // namespace

struct ThreadPool::Impl {
  std::optional<tbb::global_control> control;
};

ThreadPool::ThreadPool(int threads) : impl_(std::make_unique<Impl>()) {
  const int hardware = tbb::info::default_concurrency();
  threads_ = threads > 0 ? threads : hardware;
  impl_->control.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads_));
  ensureDenormalObserver();
}

ThreadPool::~ThreadPool() = default;

int parallelThreads() {
  const size_t pool = std::min<size_t>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
                                       size_t(tbb::info::default_concurrency()));
  return int(std::min<size_t>(pool, size_t(tbb::this_task_arena::max_concurrency())));
}

void runWithThreads(int threads, const std::function<void()>& work) {
  ensureDenormalObserver();
  tbb::task_arena arena(threads > 0 ? threads : 1);
  arena.execute([&] {
    enableFlushDenormals();
    work();
  });
}

void parallelForRange(uint64_t count, uint64_t grain, const std::function<void(uint64_t, uint64_t)>& body) {
  if (count == 0) return;
  ensureDenormalObserver();
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, count, grain ? grain : 1),
                    [&](const tbb::blocked_range<uint64_t>& r) {
                      throwIfCancelled();  // TBB cancels the other sub-ranges and rethrows in the caller
                      body(r.begin(), r.end());
                    });
}

}  // namespace pl
