// src/config/setting_columns.cpp — see include/phnn/config/setting_columns.h.
#include "phnn/config/setting_columns.h"

#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "phnn/config/data_settings.h"
#include "phnn/config/training_settings.h"

namespace phnn {

std::vector<std::pair<std::string, std::string>> parse_canonical(const std::string& canonical) {
  std::vector<std::pair<std::string, std::string>> out;
  std::set<std::string> seen;
  std::stringstream parts(canonical);
  std::string part;
  while (std::getline(parts, part, ';')) {
    const auto eq = part.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw std::invalid_argument("parse_canonical: part \"" + part + "\" of \"" + canonical +
                                  "\" is not key=value; is the results file damaged?");
    }
    std::string key = part.substr(0, eq);
    if (!seen.insert(key).second) {
      throw std::invalid_argument("parse_canonical: key \"" + key + "\" repeats in \"" +
                                  canonical + "\"; is the results file damaged?");
    }
    out.emplace_back(std::move(key), part.substr(eq + 1));
  }
  return out;
}

namespace {

// Canonical keys (RunConfig::canonical(), short) -> sweep-file names
// (sweeps/FORMAT.md); a value of several comma-separated numbers gets one
// name per part. Keys not listed, or with another number of parts, keep their
// canonical name and value. The training settings' come from their table
// (phnn/config/training_settings.h; "lambda" stands for one of three and
// keeps its name), the data and physics ones from theirs
// (phnn/config/data_settings.h).
const std::map<std::string, std::vector<std::string>>& column_names() {
  static const std::map<std::string, std::vector<std::string>> names = [] {
    std::map<std::string, std::vector<std::string>> m;
    for (const PhysicsSetting& s : physics_settings()) {
      m[s.canonical].assign(s.columns.begin(), s.columns.end());
    }
    for (const DataSetting& s : data_settings()) m[s.canonical].push_back(s.column);
    for (const TrainingSetting& s : training_settings()) {
      if (s.in_key != TrainingSetting::InKey::kRegularizer) m[s.canonical].push_back(s.key);
    }
    return m;
  }();
  return names;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) parts.push_back(part);
  if (text.empty() || text.back() == ',') parts.emplace_back();
  return parts;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> setting_columns(const std::string& canonical) {
  const auto pairs = parse_canonical(canonical);
  std::set<std::string> names;
  for (const auto& kv : pairs) names.insert(kv.first);
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [key, value] : pairs) {
    const auto it = column_names().find(key);
    const std::vector<std::string> parts = split_commas(value);
    bool rename = it != column_names().end() && it->second.size() == parts.size();
    for (std::size_t i = 0; rename && i < parts.size(); ++i) {
      rename = !names.count(it->second[i]);
    }
    if (!rename) {
      out.emplace_back(key, value);
      continue;
    }
    for (std::size_t i = 0; i < parts.size(); ++i) {
      names.insert(it->second[i]);
      out.emplace_back(it->second[i], parts[i]);
    }
  }
  return out;
}

std::vector<std::string> setting_keys(
    const std::vector<std::vector<std::pair<std::string, std::string>>>& configs) {
  std::vector<std::string> keys;
  std::set<std::string> seen;
  for (const auto& config : configs) {
    for (const auto& kv : config) {
      if (seen.insert(kv.first).second) keys.push_back(kv.first);
    }
  }
  return keys;
}

}  // namespace phnn
