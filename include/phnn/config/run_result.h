// include/phnn/config/run_result.h — what one run produces, no LibTorch.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "phnn/common/enum_names.h"

namespace phnn {

/// Status of a run: a diverged run is a result, not an error (docs/DECISIONS.md).
enum class RunStatus { kPending = 0, kDone = 1, kDiverged = 2, kFailed = 3 };
inline constexpr EnumNames<RunStatus, 4> kRunStatusNames{
    "run status", {{{RunStatus::kPending, "pending"}, {RunStatus::kDone, "done"},
                    {RunStatus::kDiverged, "diverged"}, {RunStatus::kFailed, "failed"}}}};
inline std::string to_string(RunStatus status) { return kRunStatusNames.name(status); }
inline RunStatus parse_run_status(const std::string& name) { return kRunStatusNames.parse(name); }

/// One validation point of the training log (paper Figures 10 and 12).
struct TracePoint {
  int step = 0;
  double elapsed_s = 0.0;     // wall time since the cell started training
  double train_loss = 0.0;    // L_d over the whole training set (no regularizer)
  double validation_loss = 0.0;
  double kappa = 0.0;         // batch-mean condition number of df/dx
  double sigma_max = 0.0;     // batch-mean spectral norm
  double rho = 0.0;           // batch-mean stiffness ratio
};

/// Everything stored for one run (one seed of one cell). The scalar
/// results are columns of config/result_columns.h.
struct RunResult {
  RunStatus status = RunStatus::kPending;
  std::string message;
  /// Eq. 31 over the inference set (+inf if any rollout diverged).
  double mse = 0.0;
  /// Per-trajectory mean squared error (+inf when that rollout diverged).
  std::vector<double> trajectory_errors;
  int diverged_rollouts = 0;
  std::vector<TracePoint> trace;
  int best_step = 0;
  double best_validation_loss = 0.0;
  double wall_time_s = 0.0;
  int steps = 0;
  long parameter_count = 0;
  /// DG inference steps whose Newton did not converge (0 for RK2).
  std::int64_t newton_failures = 0;
  /// TrainerOptions::checkpoints: per budget, the inference MSE (Eq. 31) of
  /// the best-validation weights up to that step and the training wall time
  /// spent to get there (this run's share of the stack, inference excluded).
  std::vector<int> checkpoint_steps;
  std::vector<double> checkpoint_mse, checkpoint_train_seconds;
  /// Two figure trajectories, predicted and true, each [n][n_x] row-major:
  /// for a built-in system those of paper Figures 7 and 9 (from H(x0) =
  /// 0.5 J and 0.75 J, u = 0 (harmonic, Duffing) or a limit-cycle u
  /// (self-sustained)); for a system file inference trajectories 0 and 1.
  std::vector<double> figure_prediction_05, figure_prediction_075;
  std::vector<double> figure_reference_05, figure_reference_075;
  /// The best-validation weights used for inference (DynamicsModel::
  /// parameters() order, each tensor flattened row-major without its member
  /// axis): `phnn eval` reloads them. Empty for a run that failed.
  std::vector<double> weights;
  /// UTC, ISO 8601 ("2026-11-28T08:43:21Z"): when the work item that trained
  /// the run started and finished; "" where unknown (a journal record
  /// written before 2026-11-28, or a file without /runs/started_utc).
  std::string started_utc, finished_utc;
  /// Training wall time of this run's share of its stack, inference and
  /// checkpoint inference excluded (NaN: unknown, e.g. a file written
  /// before 2026-11-28).
  double train_seconds = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace phnn
