#pragma once
// How much memory this process uses and may still use, and the guard every command applies
// before its large allocations (framebuffers, visibility field, light-field values): a run
// that would not fit is refused up front with its estimate and the flag that lowers it,
// instead of being killed by the system part-way (or slowing it down by swapping).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace pl {

/// Peak resident set size of this process in bytes (from /proc/self/status VmHWM; 0 when unknown).
uint64_t peakRssBytes();

/// Bytes this process may still allocate: the system's MemAvailable (/proc/meminfo: free
/// memory plus what the kernel can reclaim without swapping), lowered to what is left under
/// the address-space and data limits (`ulimit -v`, `ulimit -d`) when they are set. nullopt
/// when none of these is known (not Linux).
std::optional<uint64_t> availableMemoryBytes();

/// Fails (pl::Error) with "WHAT: estimated memory X GiB exceeds the Y GiB available; HOW"
/// when `bytes` exceeds availableMemoryBytes(). `how` names the flags that
/// lower the estimate, e.g. "lower --width/--height". Does nothing when the available memory
/// is unknown.
void requireMemory(uint64_t bytes, std::string_view what, std::string_view how);

/// Asks Linux for transparent huge pages (2 MiB) on a large, not yet touched allocation: the
/// tens to hundreds of MB of a visibility field then take a few hundred page faults to fill
/// instead of tens of thousands. A hint only (THP may be off); a no-op elsewhere.
void adviseHugePages(void* data, size_t bytes);

}  // namespace pl
