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
/// when `bytes` exceeds availableMemoryBytes(), or with "... exceeds --max-memory Y GiB; HOW"
/// when it exceeds `limit` (a user's cap, 0 = none). `how` names the flags that lower the
/// estimate, e.g. "lower --width/--height". Without a limit, does nothing when the available
/// memory is unknown.
void requireMemory(uint64_t bytes, std::string_view what, std::string_view how, uint64_t limit = 0);

/// Bytes of a size written as a number with an optional binary unit: "1073741824", "800M",
/// "12G", "1.5T" (K, M, G, T: 2^10 … 2^40; a trailing "iB" or "B" is allowed, case-insensitive).
/// Throws pl::UsageError naming `option` for anything else, or a size below 1 MiB.
uint64_t parseMemorySize(std::string_view text, std::string_view option);

/// Asks Linux for transparent huge pages (2 MiB) on a large, not yet touched allocation: the
/// tens to hundreds of MB of a visibility field then take a few hundred page faults to fill
/// instead of tens of thousands. A hint only (THP may be off); a no-op elsewhere.
void adviseHugePages(void* data, size_t bytes);

/// Hands memory that the program has freed but the allocator keeps back to the system (glibc's
/// malloc_trim; a no-op elsewhere): for a loop that frees many small blocks while filling a
/// large array from them, so that resident memory does not hold both.
void releaseFreedMemory();

}  // namespace pl
