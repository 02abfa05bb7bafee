#include "core/cancel.h"

#include <atomic>

namespace pl {

namespace {
std::atomic<bool> gCancellationRequested{false};
static_assert(std::atomic<bool>::is_always_lock_free);
}  // namespace

void requestCancellation() noexcept { gCancellationRequested.store(true, std::memory_order_relaxed); }
void clearCancellation() noexcept { gCancellationRequested.store(false, std::memory_order_relaxed); }
bool cancellationRequested() noexcept { return gCancellationRequested.load(std::memory_order_relaxed); }

void throwIfCancelled() {
  if (cancellationRequested()) throw Cancelled();
}

}  // namespace pl
