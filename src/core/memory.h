#pragma once
// How much memory this process uses and may still use, and the guard every command applies
// before its large allocations (framebuffers, visibility field, light-field values): a run
// that would not fit is refused up front with its estimate and the flag that lowers it,
// instead of being killed by the system part-way (or slowing it down by swapping).
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

/// The 2 MiB transparent-huge-page size of x86-64 Linux.
inline constexpr uint64_t kHugePageBytes = uint64_t(2) << 20;

/// The whole huge pages inside [address, address + bytes): begin rounded up and end rounded
/// down to kHugePageBytes (begin == end when none fits). Pure address arithmetic.
struct AddressRange {
  uint64_t begin = 0, end = 0;
};
AddressRange hugePageInterior(uint64_t address, uint64_t bytes);

/// Asks the kernel to back the whole huge pages inside [data, data + bytes) with 2 MiB pages
/// (madvise MADV_HUGEPAGE, then MADV_COLLAPSE for pages already touched), so that random reads
/// over a large array (the fast renderer's light-field values, chart records and texels) miss
/// the TLB about 512× less often: with 4 KiB pages every lookup in a 50 MB array needs a page
/// walk of its own. Contents are unchanged; best effort (a kernel without transparent huge
/// pages, or memory too fragmented to collapse, leaves the 4 KiB pages). Returns the bytes of
/// the interior the kernel accepted the advice for (0 when it refused or none fits).
uint64_t adviseHugePages(const void* data, uint64_t bytes);

}  // namespace pl
