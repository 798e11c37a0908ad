// src/report/per_run.cpp — the per-run CSV export (tidy data).
#include "phnn/report/per_run.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
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

// The shortest text that reads back to the same double (std::to_chars:
// 0.0025, not %.17g's 0.0025000000000000001); "inf", "-inf", "nan" spelled
// the same on every libc (no "-nan").
std::string csv_double(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[40];
  const auto end = std::to_chars(buf, buf + sizeof buf, value).ptr;
  return std::string(buf, end);
}

// A configuration value as the canonical key spells it (%.17g numbers): a
// value that is exactly one number is re-spelled by csv_double, the same
// double; anything else (names, lists) is kept.
std::string config_value(const std::string& text) {
  if (text.empty() || text.find_first_not_of("0123456789.eE+-") != std::string::npos) return text;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return text;
  return csv_double(value);
}

// Canonical keys (RunConfig::canonical(), short) -> sweep-file names
// (sweeps/FORMAT.md); a value of several comma-separated numbers gets one
// name per part. Keys not listed, or with another number of parts, keep their
// canonical name and value.
const std::map<std::string, std::vector<std::string>>& column_names() {
  static const std::map<std::string, std::vector<std::string>> names = {
      {"h_gen", {"generation_step"}},
      {"e0", {"energy_min", "energy_max"}},
      {"eeq", {"equilibrium_energy_min", "equilibrium_energy_max"}},
      {"n_traj", {"num_trajectories"}},
      {"splits", {"num_train_max", "num_validation", "num_inference"}},
      {"gen_tol", {"generation_newton_tolerance"}},
      {"lr", {"learning_rate"}},
      {"adam", {"adam_beta1", "adam_beta2", "adam_eps"}},
      {"batch", {"batch_size"}},
      {"jac_eps", {"jacobian_eps"}},
      {"newton", {"newton_tolerance", "newton_max_iterations"}},
      {"tau", {"dg_min_dx_norm"}},
      {"divergence", {"divergence_norm"}},
      {"z", {"z1", "z2", "z3"}},
  };
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

// One run's configuration columns: canonical pairs under sweep-file names.
std::vector<std::pair<std::string, std::string>> config_columns(const std::string& canonical) {
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
      out.emplace_back(key, config_value(value));
      continue;
    }
    for (std::size_t i = 0; i < parts.size(); ++i) {
      names.insert(it->second[i]);
      out.emplace_back(it->second[i], config_value(parts[i]));
    }
  }
  return out;
}

// Configuration columns of all records, in order of first appearance.
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
  for (const RunRecord& r : records) configs.push_back(config_columns(r.canonical));
  const std::vector<std::string> keys = config_keys(configs);
  std::set<std::int64_t> budget_set;
  for (const RunRecord& r : records) budget_set.insert(r.checkpoint_steps.begin(), r.checkpoint_steps.end());
  const std::vector<std::int64_t> budgets(budget_set.begin(), budget_set.end());
  std::ostringstream out;
  out << "run_id,studies,model_label";
  for (const std::string& key : keys) out << "," << csv_field(key);
  out << ",status,mse,best_step,best_validation_loss,wall_time_s,steps_taken,parameter_count,"
         "diverged_rollouts,newton_failures,trace_points,initial_validation_loss,final_train_loss,"
         "final_validation_loss,final_kappa,final_sigma_max,final_rho";
  for (std::int64_t s : budgets) out << ",mse_at_" << s << ",train_s_at_" << s;
  out << ",message\n";
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
        << r.newton_failures << "," << r.trace_points << ","
        << csv_double(r.initial_validation_loss) << "," << csv_double(r.final_train_loss) << ","
        << csv_double(r.final_validation_loss) << "," << csv_double(r.final_kappa) << ","
        << csv_double(r.final_sigma_max) << "," << csv_double(r.final_rho);
    for (std::int64_t s : budgets) {
      out << ",";
      for (std::size_t k = 0; k < r.checkpoint_steps.size(); ++k) {
        if (r.checkpoint_steps[k] == s) {
          out << csv_double(r.checkpoint_mse[k]) << "," << csv_double(r.checkpoint_train_seconds[k]);
        }
      }
      if (std::find(r.checkpoint_steps.begin(), r.checkpoint_steps.end(), s) ==
          r.checkpoint_steps.end()) {
        out << ",";
      }
    }
    out << "," << csv_field(r.message) << "\n";
  }
  return out.str();
}

}  // namespace phnn
