// include/phnn/common/closest_name.h — the "did you mean" behind unknown
// sweep-file keys and values and unknown command-line options and commands.
#pragma once

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

namespace phnn {

/// Levenshtein distance: insertions, deletions and substitutions of one char.
inline std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// The name of `names` that `value` most likely misspells: equal up to case
/// ("PHNN-JR-DG"), else the nearest within 2 edits (the first of a tie);
/// "" if none is that close.
///
///   closest_name("--sedes", {"--seeds", "--steps"}) == "--seeds"
inline std::string closest_name(const std::string& value, const std::vector<std::string>& names) {
  std::string lower = value;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const std::string& name : names) {
    if (name == lower) return name;
  }
  std::size_t best = 3;
  std::string best_name;
  for (const std::string& name : names) {
    const std::size_t d = edit_distance(value, name);
    if (d < best) {
      best = d;
      best_name = name;
    }
  }
  return best_name;
}

}  // namespace phnn
