// include/phnn/common/counted.h — a count with its noun in the right number
// ("1 input", "2 inputs", "0 ports") for the commands' messages.
#pragma once

#include <string>

namespace phnn {

/// "1 state", "4 states": the noun as given for exactly one, + "s" otherwise.
inline std::string counted(long long n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

}  // namespace phnn
