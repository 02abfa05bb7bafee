// Memory figures of the process and the system (see memory.h).
#include "core/memory.h"

#include <sys/resource.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <fstream>
#include <string>

#include "core/error.h"

namespace pl {
namespace {

/// The value of "KEY: N kB" in a /proc file, in bytes; nullopt when the key is absent.
std::optional<uint64_t> procKibibytes(const char* file, std::string_view key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() > key.size() && line.compare(0, key.size(), key) == 0 && line[key.size()] == ':') {
      try {
        return uint64_t(std::stoull(line.substr(key.size() + 1))) * 1024u;
      } catch (const std::exception&) {
        return std::nullopt;
      }
    }
  }
  return std::nullopt;
}

/// What is left under resource limit `resource` given `used` bytes (nullopt when unlimited).
std::optional<uint64_t> leftUnderLimit(int resource, std::optional<uint64_t> used) {
  struct rlimit limit {};
  if (::getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
  const uint64_t cap = uint64_t(limit.rlim_cur), taken = used.value_or(0);
  return cap > taken ? cap - taken : 0;
}

std::string gibibytes(uint64_t bytes) { return fmt::format("{:.2f} GiB", double(bytes) / double(1ull << 30)); }

}  // namespace

uint64_t peakRssBytes() { return procKibibytes("/proc/self/status", "VmHWM").value_or(0); }

std::optional<uint64_t> availableMemoryBytes() {
  std::optional<uint64_t> available = procKibibytes("/proc/meminfo", "MemAvailable");
  for (const std::optional<uint64_t> left :
       {leftUnderLimit(RLIMIT_AS, procKibibytes("/proc/self/status", "VmSize")),
        leftUnderLimit(RLIMIT_DATA, procKibibytes("/proc/self/status", "VmData"))})
    if (left) available = available ? std::min(*available, *left) : *left;
  return available;
}

void requireMemory(uint64_t bytes, std::string_view what, std::string_view how) {
  const std::optional<uint64_t> available = availableMemoryBytes();
  if (available && bytes > *available)
    fail("{}: estimated memory {} exceeds the {} available; {}", what, gibibytes(bytes), gibibytes(*available), how);
}

void adviseHugePages(void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHugePage = uintptr_t(1) << 21;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHugePage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

}  // namespace pl
