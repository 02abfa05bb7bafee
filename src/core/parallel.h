#pragma once
// Thread pool control and parallel loops (oneTBB behind this header).
//
// Every worker thread runs with flush-to-zero and denormals-are-zero set, as Embree asks
// for, and so that denormal arithmetic never slows a kernel by 100×. The pool initialises
// itself: the first parallel loop installs the FTZ/DAZ observer (and sets FTZ/DAZ on the
// calling thread), so a library caller (a Python script, a job) needs no set-up; a ThreadPool
// object only limits the number of threads.
#include <cstdint>
#include <functional>
#include <memory>

namespace pl {

/// Limits the number of worker threads for its lifetime (0 = all hardware threads). Optional:
/// without one, parallel loops use every hardware thread.
class ThreadPool {
 public:
  explicit ThreadPool(int threads = 0);
  ~ThreadPool();
  int threads() const { return threads_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int threads_;
};

/// Sets FTZ/DAZ on the calling thread (the observer does it for TBB workers).
void enableFlushDenormals();

/// Runs work() with the parallel loops it starts limited to `threads` threads, the calling
/// thread among them (a task arena of its own), so that loops started by other threads keep
/// the pool: the viewer's background propagation on one thread beside the renderer's loops.
void runWithThreads(int threads, const std::function<void()>& work);

/// How many threads a parallel loop started now may run on: the innermost ThreadPool's limit
/// (else every hardware thread), and inside runWithThreads that arena's.
int parallelThreads();

/// Calls body(begin, end) on disjoint sub-ranges of [0, count), in parallel. grain is the
/// smallest range handed to one task. Each sub-range starts with a cancellation point
/// (core/cancel.h): once cancellation is requested, the loop stops and pl::Cancelled is thrown.
/// An exception from body stops the loop too and is rethrown to the caller.
void parallelForRange(uint64_t count, uint64_t grain, const std::function<void(uint64_t, uint64_t)>& body);

/// Calls body(i) for every i in [0, count), in parallel.
inline void parallelFor(uint64_t count, const std::function<void(uint64_t)>& body, uint64_t grain = 1) {
  parallelForRange(count, grain, [&](uint64_t b, uint64_t e) {
    for (uint64_t i = b; i < e; ++i) body(i);
  });
}

}  // namespace pl
