// Memory figures of the process and the system (see memory.h).
#include "core/memory.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <sys/resource.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
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

void requireMemory(uint64_t bytes, std::string_view what, std::string_view how, uint64_t limit) {
  const std::optional<uint64_t> available = availableMemoryBytes();
  if (available && bytes > *available && !(limit > 0 && limit < *available))
    fail("{}: estimated memory {} exceeds the {} available; {}", what, gibibytes(bytes), gibibytes(*available), how);
  if (limit > 0 && bytes > limit)
    fail("{}: estimated memory {} exceeds --max-memory {}; {}", what, gibibytes(bytes), gibibytes(limit), how);
}

uint64_t parseMemorySize(std::string_view text, std::string_view option) {
  auto refuse = [&]() -> uint64_t {
    failUsage("{}: '{}' is not a memory size (e.g. 12G, 800M, or bytes; at least 1M)", option, text);
  };
  std::string s(text);
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  for (const char* suffix : {"IB", "B"})
    if (s.size() > std::strlen(suffix) && s.ends_with(suffix) && !std::isdigit(static_cast<unsigned char>(s[s.size() - std::strlen(suffix) - 1])))
      s.resize(s.size() - std::strlen(suffix));
  double scale = 1.0;
  if (!s.empty()) {
    const size_t unit = std::string_view("KMGT").find(s.back());
    if (unit != std::string_view::npos) {
      scale = std::ldexp(1.0, 10 * int(unit + 1));
      s.pop_back();
    }
  }
  if (s.empty() || s.find_first_not_of("0123456789.") != std::string::npos) return refuse();
  char* end = nullptr;
  const double value = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !(value * scale >= double(1 << 20)) || value * scale > 0x1p62) return refuse();
  return uint64_t(value * scale);
}

void releaseFreedMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
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
