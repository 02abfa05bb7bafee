#pragma once
// Errors that reach the user. Every message says what was wrong and where (file, line,
// element), e.g. "scene.obj:12: face index 40 out of range (30 vertices)". The command-line
// front end prints what() to stderr and exits non-zero.
#include <fmt/format.h>

#include <stdexcept>
#include <string>

namespace pl {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws pl::Error with a fmt-formatted message.
template <typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
  throw Error(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace pl
