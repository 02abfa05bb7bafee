#pragma once
// Errors that reach the user. Every message says what was wrong and where (file, line,
// element), e.g. "scene.obj:12: face index 40 out of range (30 vertices)". The command-line
// front end prints "plenoptic: error: " + what() to stderr and exits with one of the
// statuses below (the same for every command; docs/user-guide.md, Errors and exit statuses).
#include <fmt/format.h>

#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace pl {

/// Exit statuses of the `plenoptic` program.
enum ExitStatus : int {
  kExitSuccess = 0,
  kExitFailure = 1,  ///< the command ran into a problem: bad input file, output not writable, not enough memory, internal error
  kExitUsage = 2,    ///< the command line is wrong: unknown flag, missing or malformed value, out of range, bad combination
  // Interrupted by signal S: 128 + S (SIGINT 130, SIGTERM 143), as shells report it (core/interrupt.h).
};

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An Error in how the program was called (flags, their values and combinations), found
/// before any work is done: exit status kExitUsage instead of kExitFailure.
class UsageError : public Error {
 public:
  using Error::Error;
};

/// An Error opening, reading or writing a file (missing, not readable, directory not
/// writable), as opposed to what a file contains or how the program was called. Same exit
/// status as Error; the Python module raises it as an OSError carrying path() as its
/// filename. The message still names the file itself, as every message does.
class FileError : public Error {
 public:
  FileError(std::string path, const std::string& message) : Error(message), path_(std::move(path)) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Throws pl::Error with a fmt-formatted message.
template <typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
  throw Error(fmt::format(format, std::forward<Args>(args)...));
}

/// Throws pl::FileError about `path` with a fmt-formatted message.
template <typename... Args>
[[noreturn]] void failFile(const std::string& path, fmt::format_string<Args...> format, Args&&... args) {
  throw FileError(path, fmt::format(format, std::forward<Args>(args)...));
}

/// Throws pl::UsageError with a fmt-formatted message.
template <typename... Args>
[[noreturn]] void failUsage(fmt::format_string<Args...> format, Args&&... args) {
  throw UsageError(fmt::format(format, std::forward<Args>(args)...));
}

/// The choices of a message as "a, b or c" ("a" alone, "a or b"), in the order given: how
/// every message lists what it would have accepted (presets, file extensions).
template <typename Range>
std::string alternatives(const Range& choices) {
  std::string list;
  const size_t count = size_t(std::size(choices));
  size_t i = 0;
  for (const auto& choice : choices) {
    list += i == 0 ? "" : i + 1 == count ? " or " : ", ";
    list += std::string_view(choice);
    ++i;
  }
  return list;
}

}  // namespace pl
