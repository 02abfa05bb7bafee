#pragma once
// Test support (header-only; include as "support/temp_dir_test.h", tests/ is on the include
// path of pl_add_test targets): a fixture with a fresh empty directory per test, and reading
// a whole file back.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace pl::test_support {

/// The whole content of a file ("" when it cannot be read).
inline std::string readFileText(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Fixture: a fresh empty directory per test (named after the suite, the test and the
/// process, so parallel ctest runs never share one), removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() / ("plenoptic_" + std::string(test->test_suite_name()) + "_" +
                                                     test->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  /// `name` inside the test's directory.
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// How many entries the directory holds (e.g. to see that no temporary file was left).
  size_t fileCount() const {
    return size_t(std::distance(std::filesystem::directory_iterator(dir_), std::filesystem::directory_iterator()));
  }

  std::filesystem::path dir_;
};

}  // namespace pl::test_support
