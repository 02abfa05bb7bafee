// The interruption handler and its registry of temporary files (see interrupt.h).
#include "core/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>

namespace pl {
namespace {

/// Registered temporary paths; null = free slot. std::atomic<const char*> is lock-free on
/// every platform we build for (checked below), hence safe to read in a signal handler.
constexpr size_t kSlots = 256;
std::array<std::atomic<const char*>, kSlots> temporaryPaths{};
static_assert(std::atomic<const char*>::is_always_lock_free);

/// On a terminal the message starts on a line of its own (after the "^C" echo or a progress
/// bar); decided when the handler is installed, since isatty is not async-signal-safe.
bool stderrIsTerminal = false;

extern "C" void onInterrupt(int signal) {
  for (std::atomic<const char*>& slot : temporaryPaths)
    if (const char* path = slot.load(std::memory_order_acquire)) ::unlink(path);
  static const char kMessage[] = "\nplenoptic: interrupted\n";
  const size_t skip = stderrIsTerminal ? 0 : 1;
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, kMessage + skip, sizeof kMessage - 1 - skip);
  ::_exit(128 + signal);
}

}  // namespace

void installInterruptHandlers() {
  stderrIsTerminal = ::isatty(STDERR_FILENO) == 1;
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  // Block the other two while cleaning up, so a second Ctrl-C cannot cut the cleanup short.
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&action.sa_mask, s);
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(s, &action, nullptr);
}

size_t registerTemporaryFile(const char* path) noexcept {
  for (size_t i = 0; i < kSlots; ++i) {
    const char* expected = nullptr;
    if (temporaryPaths[i].compare_exchange_strong(expected, path, std::memory_order_acq_rel)) return i;
  }
  return kNoTemporarySlot;
}

void unregisterTemporaryFile(size_t slot) noexcept {
  if (slot < kSlots) temporaryPaths[slot].store(nullptr, std::memory_order_release);
}

}  // namespace pl
