// Replays the fuzzing regression corpus (tests/data/fuzz/<target>/: seeds and every input a
// fuzzing run found to crash or throw something other than pl::Error) through the same
// target functions as the libFuzzer build, in the normal build: each input must be read or
// refused with pl::Error — no other exception, no crash (a crash fails the test binary).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_targets.h"

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> corpusFiles(const std::string& target) {
  std::vector<fs::path> files;
  const fs::path dir = fs::path(PLENOPTIC_TEST_DATA_DIR) / "fuzz" / target;
  if (fs::is_directory(dir))
    for (const fs::directory_entry& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

class FuzzReplay : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzReplay, EveryCorpusInputIsReadOrRefusedWithPlError) {
  const pl::fuzz::FuzzTarget* target = pl::fuzz::findFuzzTarget(GetParam());
  ASSERT_NE(target, nullptr);
  const std::vector<fs::path> files = corpusFiles(GetParam());
  ASSERT_FALSE(files.empty()) << "no regression corpus in tests/data/fuzz/" << GetParam();
  for (const fs::path& file : files) {
    std::ifstream in(file, std::ios::binary);
    ASSERT_TRUE(in) << file;
    const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    try {
      pl::fuzz::runFuzzInput(*target, bytes);
    } catch (const std::exception& e) {
      ADD_FAILURE() << file << ": internal error (not pl::Error): " << e.what();
    }
  }
}

std::vector<std::string> targetNames() {
  std::vector<std::string> names;
  for (const pl::fuzz::FuzzTarget& target : pl::fuzz::fuzzTargets()) names.emplace_back(target.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, ::testing::ValuesIn(targetNames()),
                         [](const ::testing::TestParamInfo<std::string>& param) { return param.param; });

}  // namespace
