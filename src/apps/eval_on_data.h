// src/apps/eval_on_data.h — `phnn eval RESULTS --data FILE`: finished runs
// of a results file rolled out on another data set or recording (their
// stored best-validation weights, the trainer's inference code), the MSE
// per run and the error per inference trajectory as CSV. Reads the two
// files, writes only --errors.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "phnn/config/run_config.h"
#include "phnn/store/results_file.h"

namespace phnn {
namespace apps {

/// The file's runs by id, rebuilt from the sweep text stored in it (parsed
/// and expanded once).
std::map<std::string, RunConfig> stored_run_configs(const ResultsFile& results);

struct EvalOnDataOptions {
  std::string data_path;  // a data-set file (`phnn data`, `phnn import`)
  /// Rows of the results file to evaluate; empty: every finished run whose
  /// system has the data set's states and inputs.
  std::vector<int> rows;
  std::string errors_path;  // CSV of per-trajectory errors ("" = none)
};

/// Prints one line per run (its MSE on the data) and writes the CSV;
/// returns the exit status (0; bad input throws cli::UsageError).
int eval_on_data(const ResultsFile& results, const EvalOnDataOptions& options);

}  // namespace apps
}  // namespace phnn
