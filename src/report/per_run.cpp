// src/report/per_run.cpp — the per-run CSV export (tidy data).
#include "phnn/report/per_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "phnn/common/number_text.h"
#include "phnn/config/setting_columns.h"
#include "report/csv.h"

namespace phnn {

namespace {

using internal::csv_field;

// The shortest text that reads back to the same double (std::to_chars:
// 0.0025, not %.17g's 0.0025000000000000001); "inf", "-inf", "nan" spelled
// the same on every libc (no "-nan").
std::string csv_double(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return roundtrip_number(value);
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

// One run's setting columns in the CSV's spelling (numbers re-spelled).
std::vector<std::pair<std::string, std::string>> config_columns(const std::string& canonical) {
  auto columns = setting_columns(canonical);
  for (auto& kv : columns) kv.second = config_value(kv.second);
  return columns;
}

}  // namespace

std::string render_per_run_csv(const std::vector<RunRecord>& records) {
  std::vector<std::vector<std::pair<std::string, std::string>>> configs;
  for (const RunRecord& r : records) configs.push_back(config_columns(r.canonical));
  const std::vector<std::string> keys = setting_keys(configs);
  std::set<std::int64_t> budget_set;
  for (const RunRecord& r : records) budget_set.insert(r.checkpoint_steps.begin(), r.checkpoint_steps.end());
  const std::vector<std::int64_t> budgets(budget_set.begin(), budget_set.end());
  std::ostringstream out;
  out << "run_id,studies,model_label";
  for (const std::string& key : keys) out << "," << csv_field(key);
  out << ",status";
  for (const ResultColumn& c : result_columns()) out << "," << c.csv_name;
  out << ",trace_points,initial_validation_loss,final_train_loss,final_validation_loss,"
         "final_kappa,final_sigma_max,final_rho";
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
    out << "," << to_string(r.result.status);
    for (const ResultColumn& c : result_columns()) {
      out << "," << (c.type == ResultColumn::Type::kInt ? std::to_string(c.get_int(r.result))
                                                        : csv_double(c.get_double(r.result)));
    }
    out << "," << r.trace_points << ","
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
    out << "," << csv_field(r.result.message) << "\n";
  }
  return out.str();
}

}  // namespace phnn
