#pragma once
// Cooperative cancellation, for library callers that must stop a job without ending the
// process (the Python module turns Ctrl-C into KeyboardInterrupt with it). The command line
// does not use it: there, Ctrl-C ends the process at once (core/interrupt.h).
//
// One process-wide flag. requestCancellation() raises it; every cancellation point then
// throws pl::Cancelled, which unwinds the job like any other error: atomic outputs that were
// not committed are removed (core/file_io.h), so nothing half-written remains. The points are
// the start of every sub-range of parallelForRange (core/parallel.h) — all of the path
// tracer's, the bake's and the renderers' long loops run through it, in sub-ranges of a few
// milliseconds, so a job stops within about one sub-range per thread — and the explicit
// throwIfCancelled() calls between a job's serial stages. Work that is not cut into such
// ranges (Embree's BVH build, one codec call, loading a scene) runs to its end first.
// The flag stays raised until clearCancellation(): a request stops every job running in the
// process, and the caller that raised it clears it once its job has stopped.
#include <atomic>

#include "core/error.h"

namespace pl {

/// Thrown at a cancellation point after requestCancellation().
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

namespace detail {
inline std::atomic<bool> cancellationRequested{false};
static_assert(std::atomic<bool>::is_always_lock_free);
}  // namespace detail

/// Raises the flag (async-signal-safe: one lock-free atomic store).
inline void requestCancellation() noexcept { detail::cancellationRequested.store(true, std::memory_order_relaxed); }
/// Lowers it (before starting a job again after a cancellation).
inline void clearCancellation() noexcept { detail::cancellationRequested.store(false, std::memory_order_relaxed); }
inline bool cancellationRequested() noexcept { return detail::cancellationRequested.load(std::memory_order_relaxed); }

/// A cancellation point: throws pl::Cancelled when the flag is raised. Inline, so that the
/// path tracer's per-sample check is one relaxed load and a predicted branch, no call.
inline void throwIfCancelled() {
  if (cancellationRequested()) [[unlikely]]
    throw Cancelled();
}

}  // namespace pl
