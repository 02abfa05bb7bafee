#pragma once
// Fuzz targets: one entry function per file reader, shared by the libFuzzer executables
// (fuzz_main.cpp, built by `make fuzz` with clang and ASan/UBSan) and the regression replay
// test (fuzz_replay_test.cpp, part of the normal build and `make test`), so both run exactly
// the same code on an input.
//
// The contract a reader must keep on any input bytes: return a value or throw pl::Error (a
// clear message naming the file). pl::Error is therefore the expected outcome for bad input;
// any other exception, a crash, a sanitizer report, a hang or an unbounded allocation is a bug.
//
// Readers that take a path get the input written to a file in a private temporary directory
// (under $TMPDIR, removed when the process exits normally); the camera-path target uses the
// in-memory parser that already exists.
#include <cstdint>
#include <span>
#include <string_view>

namespace pl::fuzz {

struct FuzzTarget {
  const char* name;         ///< "obj", "gltf", … (also the regression corpus folder tests/data/fuzz/<name>)
  const char* description;  ///< what is read, for --help style listings
  void (*run)(std::span<const uint8_t> input);
};

/// Every target, in a fixed order.
std::span<const FuzzTarget> fuzzTargets();

/// The target called `name`, or nullptr.
const FuzzTarget* findFuzzTarget(std::string_view name);

/// Runs `target` on `input`. Returns normally when the reader accepted the input or refused
/// it with pl::Error; any other exception propagates (the caller treats it as a bug).
void runFuzzInput(const FuzzTarget& target, std::span<const uint8_t> input);

/// The OBJ target's input holds the OBJ and optionally, after this line, its material library
/// (written as "scene.mtl" beside "scene.obj"; the OBJ refers to it with "mtllib scene.mtl").
inline constexpr std::string_view kObjMtlSeparator = "\n#---mtl---\n";

}  // namespace pl::fuzz
