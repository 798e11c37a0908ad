// tests/systems/toy_system.h — a small valid system file (a damped spring
// with one port and one input) that the system-file tests edit one line at a
// time, and the message its compilation throws.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "phnn/systems/system_file.h"

namespace phnn {
namespace testing_util {

inline const char* kToySystem = R"(name = "toy"
states = ["q", "p"]
inputs = ["u"]
ports = ["w"]
H = "p^2/(2*m) + k*q^2/2"
z = ["c*w"]
S = [[0, 1, 0, 0], [-1, 0, -1, -1], [0, 1, 0, 0], [0, 1, 0, 0]]
[parameters]
m = 1.0
k = 2.0
c = 0.1
[initial]
method = "energy"
energy = [0.1, 1.0]
[control]
design = "constant"
range = [[-1, 1]]
)";

/// kToySystem with the first `from` replaced by `to` (a test failure if absent).
inline std::string toy_with(const std::string& from, const std::string& to) {
  std::string text = kToySystem;
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

/// What compiling `text` as toy.toml throws, or "(no error)".
inline std::string toy_error_of(const std::string& text) {
  try {
    compile_system(text, "toy.toml");
  } catch (const SystemFileError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace testing_util
}  // namespace phnn
