// libFuzzer entry point for one target of fuzz_targets.h, chosen at compile time by
// PL_FUZZ_TARGET (e.g. "obj"); built only with -DPLENOPTIC_FUZZ=ON (see `make fuzz`).
// pl::Error is the expected outcome for bad input; any other exception is reported and
// aborts, so libFuzzer records the input as a crash.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "fuzz/fuzz_targets.h"

namespace {

const pl::fuzz::FuzzTarget& target() {
  static const pl::fuzz::FuzzTarget* found = [] {
    const pl::fuzz::FuzzTarget* t = pl::fuzz::findFuzzTarget(PL_FUZZ_TARGET);
    if (!t) {
      std::fprintf(stderr, "fuzz: unknown target '%s'\n", PL_FUZZ_TARGET);
      std::abort();
    }
    return t;
  }();
  return *found;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    pl::fuzz::runFuzzInput(target(), {data, size});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz %s: internal error (not pl::Error): %s\n", PL_FUZZ_TARGET, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz %s: internal error: unknown exception\n", PL_FUZZ_TARGET);
    std::abort();
  }
  return 0;
}
