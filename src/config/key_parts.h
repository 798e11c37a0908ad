// src/config/key_parts.h — the canonical-key parts of a table of settings
// (training_settings.cpp, data_settings.cpp): ";name=value" per part, the
// values of adjacent settings that share a part comma-separated
// ("adam=0.9,0.999,1e-08"). Internal to src/config.
#pragma once

#include <string>
#include <vector>

namespace phnn {
namespace internal {

/// The parts of the settings of `table` (in order) for which `in_key(s)`
/// holds, each value spelled by `text(s)`.
template <class Setting, class InKey, class Text>
std::string key_parts(const std::vector<Setting>& table, InKey in_key, Text text) {
  std::string out;
  std::string part_name;  // the canonical part being written
  for (const Setting& s : table) {
    if (!in_key(s)) continue;
    out += (s.canonical == part_name ? "," : ";" + std::string(s.canonical) + "=") + text(s);
    part_name = s.canonical;
  }
  return out;
}

}  // namespace internal
}  // namespace phnn
