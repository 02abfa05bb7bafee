#include "core/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

namespace pl {
namespace {
std::atomic<bool> gEnabled{true};

std::string formatSeconds(double s) {
  if (s < 60.0) return fmt::format("{:.1f}s", s);
  const int total = static_cast<int>(s + 0.5);
  return fmt::format("{}m{:02d}s", total / 60, total % 60);
}
}  // namespace

void Progress::setEnabled(bool enabled) { gEnabled = enabled; }

Progress::Progress(std::string label, uint64_t total)
    : label_(std::move(label)), total_(total ? total : 1), start_(std::chrono::steady_clock::now()),
      lastDraw_(start_), tty_(isatty(STDERR_FILENO) != 0) {}

Progress::~Progress() { finish(); }

void Progress::advance(uint64_t units) {
  const uint64_t done = done_.fetch_add(units) + units;
  if (!gEnabled) return;
  const auto now = std::chrono::steady_clock::now();
  const int decile = static_cast<int>(10 * std::min(done, total_) / total_);
  // Cheap unlocked pre-check; the mutex only guards drawing.
  if (tty_ ? now - lastDraw_ < std::chrono::milliseconds(100) : decile == lastDecile_) return;
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;
  lastDraw_ = now;
  draw(false);
}

void Progress::finish() {
  std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (gEnabled) draw(true);
}

void Progress::draw(bool final) {
  const uint64_t done = std::min<uint64_t>(done_.load(), total_);
  const double fraction = static_cast<double>(done) / static_cast<double>(total_);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const int decile = static_cast<int>(fraction * 10);
  if (!tty_) {
    if (!final && decile == lastDecile_) return;
    lastDecile_ = decile;
  }
  std::string tail;
  if (final) {
    tail = fmt::format("done in {}", formatSeconds(elapsed));
  } else if (fraction > 0.0) {
    tail = fmt::format("{} elapsed, ETA {}", formatSeconds(elapsed), formatSeconds(elapsed * (1.0 - fraction) / fraction));
  }
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  const std::string bar = std::string(filled, '#') + std::string(kWidth - filled, '.');
  fmt::print(stderr, "{}{:<12} [{}] {:5.1f}%  {}{}", tty_ ? "\r" : "", label_, bar, 100.0 * fraction, tail,
             tty_ ? (final ? "\n" : "\x1b[K") : "\n");
  std::fflush(stderr);
}

}  // namespace pl
