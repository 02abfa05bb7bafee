#pragma once
// Wall-clock measurements shared by the commands, the walk-through and the viewer: seconds
// since a start, and the median of repeated timings (robust against the odd slow frame).
#include <algorithm>
#include <chrono>
#include <vector>

namespace pl {

using SteadyClock = std::chrono::steady_clock;

/// Seconds of wall-clock time since `start` (monotonic clock, so never negative).
inline double secondsSince(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

/// The median of `values`: the middle one of an odd count, the mean of the two middle ones
/// of an even count, 0 for none.
inline double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace pl
