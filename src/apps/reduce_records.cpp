// src/apps/reduce_records.cpp — see apps/reduce_records.h. Reads the
// results file only.
#include "apps/reduce_records.h"

#include <algorithm>
#include <limits>

namespace phnn {
namespace apps {
namespace {

// RunRecord's trace summary from /runs/trace ([rows, trace_points, 7]:
// step, elapsed_s, train_loss, validation_loss, kappa, sigma_max, rho) and
// /runs/trace_length.
void add_trace_summaries(const ResultsFile& file, std::vector<RunRecord>& records) {
  constexpr std::size_t kColumns = 7, kTrain = 2, kValidation = 3, kKappa = 4, kSigma = 5,
                        kRho = 6;
  const auto trace = file.read_double_column("trace");
  const auto lengths = file.read_int_column("trace_length");
  const auto points = static_cast<std::size_t>(file.layout().trace_points);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < records.size(); ++i) {
    RunRecord& r = records[i];
    r.trace_points = lengths[i];
    const std::size_t n = std::min(points, static_cast<std::size_t>(std::max<std::int64_t>(
                                               0, lengths[i])));
    const double* first = trace.data() + i * points * kColumns;
    const double* last = first + (n == 0 ? 0 : n - 1) * kColumns;
    r.initial_validation_loss = n > 0 ? first[kValidation] : nan;
    r.final_train_loss = n > 0 ? last[kTrain] : nan;
    r.final_validation_loss = n > 0 ? last[kValidation] : nan;
    r.final_kappa = n > 0 ? last[kKappa] : nan;
    r.final_sigma_max = n > 0 ? last[kSigma] : nan;
    r.final_rho = n > 0 ? last[kRho] : nan;
  }
}

// RunRecord's checkpoints from /runs/checkpoint_* ([rows, K], step 0 =
// padding), when the file has them.
void add_checkpoints(const ResultsFile& file, std::vector<RunRecord>& records) {
  const auto K = static_cast<std::size_t>(file.layout().checkpoints);
  if (K == 0) return;
  const auto steps = file.read_int_column("checkpoint_steps");
  const auto mse = file.read_double_column("checkpoint_mse");
  const auto seconds = file.read_double_column("checkpoint_train_seconds");
  for (std::size_t i = 0; i < records.size(); ++i) {
    for (std::size_t k = 0; k < K; ++k) {
      if (steps[i * K + k] <= 0) continue;
      records[i].checkpoint_steps.push_back(steps[i * K + k]);
      records[i].checkpoint_mse.push_back(mse[i * K + k]);
      records[i].checkpoint_train_seconds.push_back(seconds[i * K + k]);
    }
  }
}

}  // namespace

// The scalar columns of every row of /runs.
std::vector<RunRecord> read_run_records(const ResultsFile& file, const Grid& grid) {
  const auto ids = file.read_run_ids();
  const auto studies = file.read_studies();
  const auto canonical = file.read_canonical();
  std::vector<RunResult> results = file.read_result_columns();
  std::vector<RunRecord> records(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    RunRecord& r = records[i];
    r.id = ids[i];
    r.studies = studies[i];
    r.model_label = model_label(grid.runs[i].model, grid.runs[i].integrator);
    r.canonical = canonical[i];
    r.result = std::move(results.at(i));
  }
  add_trace_summaries(file, records);
  add_checkpoints(file, records);
  return records;
}

}  // namespace apps
}  // namespace phnn
