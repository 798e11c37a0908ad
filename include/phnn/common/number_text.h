// include/phnn/common/number_text.h — the shortest "%g" spelling of a double
// that reads back as the same double (0.9, not 0.90000000000000002; 1e-05).
// Header-only; used where numbers are written for people and read back
// (column labels, system-file text).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace phnn {

/// The fewest significant digits d (1..17) of "%.*g" whose text strtod reads
/// back as `value` (17 always does).
inline std::string shortest_number(double value) {
  char buf[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  return buf;
}

}  // namespace phnn
