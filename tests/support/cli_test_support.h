#pragma once
// Shared by the *_cli_test.cpp files: runs the plenoptic executable (PLENOPTIC_BINARY, a
// compile definition of every pl_add_test target) the way a user does, through the shell,
// and gives each test a fresh temporary directory (support/temp_dir_test.h). Header-only;
// include as "support/cli_test_support.h" (tests/ is on the include path of pl_add_test targets).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "support/temp_dir_test.h"

namespace pl::cli_test {

using test_support::readFileText;

/// The exit code in a std::system / pclose status: the program's exit status, or -1 when it
/// did not exit normally (killed by a signal, i.e. crashed) or could not be started.
inline int exitCode(int status) { return status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

/// Runs `ENVIRONMENT PLENOPTIC_BINARY ARGUMENTS` through the shell (ARGUMENTS are
/// shell words: quote paths that may contain spaces; ENVIRONMENT is an optional
/// "NAME=value ..." prefix). stdout and stderr go to files in `scratchDir` and are read back
/// into *out / *err when given. Returns exitCode() of the run.
inline int runPlenoptic(const std::string& arguments, const std::filesystem::path& scratchDir,
                        std::string* out = nullptr, std::string* err = nullptr, const std::string& environment = "") {
  const std::filesystem::path outFile = scratchDir / "stdout.txt", errFile = scratchDir / "stderr.txt";
  const std::string command = environment + (environment.empty() ? "" : " ") + "\"" + PLENOPTIC_BINARY + "\" " +
                              arguments + " > \"" + outFile.string() + "\" 2> \"" + errFile.string() + "\"";
  const int code = exitCode(std::system(command.c_str()));
  if (out) *out = readFileText(outFile);
  if (err) *err = readFileText(errFile);
  return code;
}

/// The outcome of a run with stdout and stderr interleaved, as a terminal shows them.
struct CommandResult {
  int exitCode = -1;   ///< see exitCode()
  std::string output;  ///< stdout and stderr
};

/// Runs `PLENOPTIC_BINARY --quiet ARGUMENTS 2>&1` (no scratch directory needed).
inline CommandResult runPlenopticCombined(const std::string& arguments) {
  const std::string command = std::string("\"") + PLENOPTIC_BINARY + "\" --quiet " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
  result.exitCode = exitCode(::pclose(pipe));
  return result;
}

/// Fixture: test_support::TempDirTest (a fresh directory per test, path(name)) whose run()
/// keeps the captured stdout/stderr files in that directory.
class CliTest : public test_support::TempDirTest {
 protected:
  /// runPlenoptic() of `ARGUMENTS --quiet` (no progress bars; with quiet_ false, as given)
  /// with this test's directory as scratch space.
  int run(const std::string& arguments, std::string* out = nullptr, std::string* err = nullptr) const {
    return runPlenoptic(quiet_ ? arguments + " --quiet" : arguments, dir_, out, err);
  }

  bool quiet_ = true;
};

}  // namespace pl::cli_test
