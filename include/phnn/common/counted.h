// include/phnn/common/counted.h — a count with its noun in the right number
// ("1 input", "2 inputs", "0 ports") for the commands' messages.
#pragma once

#include <string>

namespace phnn {

/// "1 state", "4 states": the noun as given for exactly one, + "s" otherwise.
inline std::string counted(long long n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

/// "1 trajectory", "2 trajectories": nouns whose plural is not noun + "s".
inline std::string counted(long long n, const std::string& singular, const std::string& plural) {
  return std::to_string(n) + " " + (n == 1 ? singular : plural);
}

}  // namespace phnn
