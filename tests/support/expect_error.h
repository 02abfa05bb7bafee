#pragma once
// Test support (header-only; include as "support/expect_error.h"): expectError runs `load` and
// expects a pl::Error whose message contains every one of `needles` (a file name, a key, …).
#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <string>

#include "core/error.h"

namespace pl::test_support {

inline void expectError(const std::function<void()>& load, std::initializer_list<std::string> needles) {
  try {
    load();
    ADD_FAILURE() << "no pl::Error thrown";
  } catch (const Error& e) {
    const std::string message = e.what();
    for (const std::string& needle : needles)
      EXPECT_NE(message.find(needle), std::string::npos) << "message '" << message << "' lacks '" << needle << "'";
  }
}

}  // namespace pl::test_support
