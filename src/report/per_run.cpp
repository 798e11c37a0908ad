// src/report/per_run.cpp — the per-run CSV export (tidy data).
#include "phnn/report/per_run.h"

#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <stdexcept>

#include "report/csv.h"

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

using internal::csv_field;

// "%.17g"; "inf", "-inf", "nan" spelled the same on every libc (no "-nan").
std::string csv_double(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

// Canonical keys of all records, in order of first appearance.
std::vector<std::string> config_keys(
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

}  // namespace

std::string render_per_run_csv(const std::vector<RunRecord>& records) {
  std::vector<std::vector<std::pair<std::string, std::string>>> configs;
  for (const RunRecord& r : records) configs.push_back(parse_canonical(r.canonical));
  const std::vector<std::string> keys = config_keys(configs);
  std::ostringstream out;
  out << "run_id,studies,model_label";
  for (const std::string& key : keys) out << "," << csv_field(key);
  out << ",status,mse,best_step,best_validation_loss,wall_time_s,steps_taken,parameter_count,"
         "diverged_rollouts,newton_failures,message\n";
  for (std::size_t i = 0; i < records.size(); ++i) {
    const RunRecord& r = records[i];
    out << csv_field(r.id) << "," << csv_field(r.studies) << "," << csv_field(r.model_label);
    for (const std::string& key : keys) {
      out << ",";
      for (const auto& kv : configs[i]) {
        if (kv.first == key) out << csv_field(kv.second);
      }
    }
    out << "," << to_string(r.status) << "," << csv_double(r.mse) << "," << r.best_step << ","
        << csv_double(r.best_validation_loss) << "," << csv_double(r.wall_time_s) << ","
        << r.steps_taken << "," << r.parameter_count << "," << r.diverged_rollouts << ","
        << r.newton_failures << "," << csv_field(r.message) << "\n";
  }
  return out.str();
}

}  // namespace phnn
