// The compact visibility field (plf/plv_file.h, "Compact entries"): bytes per entry held in
// memory and how fast the gather's decoder turns a tixel's encoding back into 8-byte entries.
//
// Fields (each built once, at the first benchmark that needs it; the time is printed, not measured):
//   cornell   the built-in Cornell box's field at the default preset (256 directions), traced here
//   plv       the field in the .plv named by the environment variable PLENOPTIC_BENCH_PLV (read,
//             not traced; registered only when the variable is set): e.g. the .plv of a Sponza
//             bake, whose field is too slow to trace inside a benchmark
// Counters: entries_per_second (items/s, decoded entries), bytes_per_entry (the encoded entries
// alone), held_bytes_per_entry (everything the field holds: encodings, per-tixel offsets, extra
// records), escaped (fraction of entries that see nothing). BM_Copy8 reads the same number of
// 8-byte entries from a plain array (the layout before the compact one), for scale.
// BM_StreamBlocks reads the field as a streamed bake's gather does: every entry block of its
// .plv (written once to the temporary directory) read, decompressed and decoded from its byte
// streams into 8-byte entries (VisibilityBlockFile::readEntries), from the page cache; counter
// plv_bytes_per_entry: the file's bytes.
// Run:  build/bench/visibility_bench
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bake/parameterisation.h"
#include "bake/visibility.h"
#include "core/parallel.h"
#include "plf/plv_file.h"
#include "scene/scene.h"

namespace {

const pl::VisibilityField& field(const std::string& name) {
  static std::map<std::string, pl::VisibilityField> fields;
  auto it = fields.find(name);
  if (it != fields.end()) return it->second;
  const auto start = std::chrono::steady_clock::now();
  pl::VisibilityField f;
  if (name == "cornell") {
    const pl::Scene scene = pl::makeCornellBox();
    const pl::BakeSettings settings = pl::bakePreset("default");
    const pl::Parameterisation param = pl::buildParameterisation(scene, settings);
    f = pl::computeVisibility(scene, pl::Accel(scene), param, settings);
  } else {
    const char* path = std::getenv("PLENOPTIC_BENCH_PLV");
    std::ifstream in(path, std::ios::binary);
    uint64_t hash = 0;
    in.seekg(16);
    in.read(reinterpret_cast<char*>(&hash), 8);  // the header's own hash (plv_file.h): read whatever it holds
    std::string why;
    if (!pl::readVisibility(path, hash, f, &why, pl::VisibilityEntry::kIndexMask)) {
      fmt::print(stderr, "{}\n", why);
      std::exit(1);
    }
  }
  fmt::print(stderr, "{}: {} tixels × {} directions in {:.1f} s\n", name, f.tixelCount, f.directionsPerTixel(),
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return fields.emplace(name, std::move(f)).first->second;
}

void setCounters(benchmark::State& state, const pl::VisibilityField& f, uint64_t escaped) {
  const double entries = double(f.entryCount());
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(f.entryCount()));
  state.counters["bytes_per_entry"] = double(f.entryOffset[f.tixelCount]) / entries;
  state.counters["held_bytes_per_entry"] = double(f.bytes()) / entries;
  state.counters["escaped"] = double(escaped) / entries;
}

/// Decodes every tixel on one thread, as a gather thread does.
void BM_Decode(benchmark::State& state, const std::string& name) {
  const pl::VisibilityField& f = field(name);
  std::vector<pl::VisibilityEntry> scratch(f.directionsPerTixel());
  uint64_t escaped = 0;
  for (auto _ : state) {
    escaped = 0;
    for (uint64_t t = 0; t < f.tixelCount; ++t) {
      f.decode(t, scratch.data());
      for (const pl::VisibilityEntry& e : scratch) escaped += e.escaped() ? 1 : 0;
    }
    benchmark::DoNotOptimize(escaped);
  }
  setCounters(state, f, escaped);
}

/// The same entries read from a plain array of 8-byte entries.
void BM_Copy8(benchmark::State& state, const std::string& name) {
  const pl::VisibilityField& f = field(name);
  const std::vector<pl::VisibilityEntry> all = f.decodeAll();
  const uint32_t n = f.directionsPerTixel();
  std::vector<pl::VisibilityEntry> scratch(n);
  uint64_t escaped = 0;
  for (auto _ : state) {
    escaped = 0;
    for (uint64_t t = 0; t < f.tixelCount; ++t) {
      std::memcpy(scratch.data(), all.data() + t * n, n * sizeof(pl::VisibilityEntry));
      for (const pl::VisibilityEntry& e : scratch) escaped += e.escaped() ? 1 : 0;
    }
    benchmark::DoNotOptimize(escaped);
  }
  setCounters(state, f, escaped);
}

/// Reads every entry block of the field's .plv on one thread, as a streamed gather thread does.
void BM_StreamBlocks(benchmark::State& state, const std::string& name) {
  const pl::VisibilityField& f = field(name);
  const std::string path = (std::filesystem::temp_directory_path() / ("plenoptic_visibility_bench_" + name + ".plv")).string();
  pl::writeVisibility(path, f);
  pl::VisibilityField streamed;
  std::string why;
  if (!pl::readVisibility(path, f.hash, streamed, &why, pl::VisibilityEntry::kIndexMask, nullptr, true)) {
    fmt::print(stderr, "{}\n", why);
    std::exit(1);
  }
  std::vector<unsigned char> frame, stream;
  std::vector<pl::VisibilityEntry> entries;
  uint64_t escaped = 0;
  for (auto _ : state) {
    escaped = 0;
    for (uint64_t b = 0; b < streamed.stream->blocks(); ++b) {
      streamed.stream->readEntries(b, frame, stream, entries);
      for (const pl::VisibilityEntry& e : entries) escaped += e.escaped() ? 1 : 0;
    }
    benchmark::DoNotOptimize(escaped);
  }
  setCounters(state, f, escaped);
  state.counters["plv_bytes_per_entry"] = double(std::filesystem::file_size(path)) / double(f.entryCount());
  std::filesystem::remove(path);
}

}  // namespace

int main(int argc, char** argv) {
  const pl::ThreadPool pool(2);  // tracing the Cornell field; the benchmarks themselves run on one thread
  std::vector<std::string> names = {"cornell"};
  if (std::getenv("PLENOPTIC_BENCH_PLV")) names.push_back("plv");
  for (const std::string& name : names) {
    benchmark::RegisterBenchmark(("BM_Decode/" + name).c_str(), BM_Decode, name)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("BM_Copy8/" + name).c_str(), BM_Copy8, name)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("BM_StreamBlocks/" + name).c_str(), BM_StreamBlocks, name)->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
