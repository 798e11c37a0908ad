// src/report/csv.h — CSV quoting shared by the reducer's CSV outputs
// (private to src/report).
#pragma once

#include <string>

namespace phnn {
namespace internal {

/// RFC 4180: a field holding a comma, a double quote, CR or LF is enclosed in
/// double quotes and its double quotes are doubled; any other is unchanged.
inline std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace internal
}  // namespace phnn
