// include/phnn/common/number_text.h — doubles as text that reads back as the
// same double: the shortest "%g" spelling (0.9, not 0.90000000000000002;
// 1e-05) where people read them (column labels, system-file text), and the
// fixed 17-digit one where the text is an identity (canonical keys, sweep
// files written for a run). Header-only.
#pragma once

#include <charconv>
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

/// std::to_chars' shortest round-trip text: 100 and 0.0025 (not %g's 1e+02
/// or %.17g's 0.0025000000000000001); "inf", "-inf", "nan" as the C++
/// library spells them. For tables and CSV, never for identities.
inline std::string roundtrip_number(double value) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, value).ptr);
}

/// "%.17g": 17 significant digits, the same text for the same double
/// whatever its shortest spelling (the spelling of canonical keys).
inline std::string exact_number(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

}  // namespace phnn
