#pragma once
// A progress bar with ETA on stderr for anything that takes more than a second or two.
// On a terminal it redraws one line; otherwise (CI logs, pipes) it prints a line every 10 %.
// Thread-safe: advance() may be called from any worker thread.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace pl {

class Progress {
 public:
  /// total: number of work units; label: what is being done ("tracing", "visibility").
  Progress(std::string label, uint64_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(uint64_t units = 1);
  /// Prints the final state (100 %, elapsed time) once; called by the destructor otherwise.
  void finish();

  /// Globally silences every progress bar (tests, --quiet).
  static void setEnabled(bool enabled);

 private:
  void draw(bool final);

  std::string label_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point lastDraw_;
  int lastDecile_ = -1;
  bool finished_ = false;
  bool tty_ = false;
  std::mutex mutex_;
};

}  // namespace pl
