// include/phnn/sweep/grid.h — a sweep file expanded into runs and cells.
#pragma once

#include <string>
#include <vector>

#include "phnn/sweep/run_config.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {

/// Cost model of one run, in seconds on one core. The constants were fit to
/// bench/bench_training and `phnn train` timings on the 2-core development
/// machine (docs/BENCHMARKS.md); all of them live here.
///
///   member_step_us = base_us[model][integrator] * size_factor[size]
///                    * (regularizer != none ? regularizer_factor : 1)
///
///   batch_steps    = steps                                      (training)
///                  + evaluations * num_validation / reference_batch
///                  + num_inference * num_inference_steps
///                      / reference_batch / rollout_speedup
///                      * (integrator == DG ? dg_newton_factor : 1)
///
///   cost_s         = batch_steps * member_step_us * 1e-6
///
/// with evaluations = 1 + floor(steps / eval_every) (+ 1 when steps is not a
/// multiple of eval_every): step 0, every eval_every steps and the last step
/// (SPEC.md §4). A validation pass over num_validation pairs costs
/// num_validation / reference_batch batch-steps (2500 / 64 by default); an
/// inference rollout of num_inference trajectories x num_inference_steps
/// steps (100 x 500) costs 1 / rollout_speedup of a training batch-step per
/// reference_batch state-steps, x dg_newton_factor for DG (Newton). The
/// training cost does not depend on n_train (the batch is <= 64 pairs).
struct CostModel {
  /// Microseconds per member per training step, small size, no regularizer,
  /// indexed [ModelKind][IntegratorKind] (NODE-DG does not exist). Measured
  /// with bench/bench_training (docs/BENCHMARKS.md): one thread, float64,
  /// batch 64, 10 members stacked (a paper cell), OpenBLAS + jemalloc.
  double base_us[3][2] = {
      /*kNode=*/{/*kRk2=*/80.0, /*kDg=*/0.0},
      /*kPhnnS=*/{/*kRk2=*/275.0, /*kDg=*/295.0},
      /*kPhnnJr=*/{/*kRk2=*/319.0, /*kDg=*/319.0},
  };
  /// Indexed by ModelSize: small, medium, large (PHNN-JR-RK2, E = 10,
  /// measured with `phnn train`: 272, 660 and 4186 us per member-step).
  double size_factor[3] = {1.0, 2.4, 15.0};
  /// Jacobian, closed-form SVD / eigenvalues and their backward in every
  /// step (CN, SN, SR): measured 2.6-2.7x.
  double regularizer_factor = 2.7;
  /// Pairs per batch-step in the validation and inference terms.
  double reference_batch = 64.0;
  /// A rollout state-step costs 1 / rollout_speedup of a training pair-step
  /// (forward only, no backward; measured ~0.08 s per small RK2 run).
  double rollout_speedup = 3.0;
  /// DG rollouts solve a Newton system per step (3-5 batched residual
  /// evaluations; measured ~0.85 s per small DG run).
  double dg_newton_factor = 10.0;
};

/// Estimated wall time of one run on one core [s] (CostModel above).
double estimate_run_cost_s(const RunConfig& run, const CostModel& cost_model = CostModel());

/// Runs of one cell: the same configuration but the seed (equal
/// RunConfig::cell_key()); the unit of work handed to a rank.
struct Cell {
  /// RunConfig::cell_key() of its runs.
  std::string key;
  /// Indices into Grid::runs, sorted by seed.
  std::vector<int> runs;
  /// Sum of estimate_run_cost_s() over the runs.
  double estimated_cost_s = 0.0;
};

/// What one study's tables are made of (paper Appendix F; SPEC.md §6): one
/// table per system, rows = models, columns = values of the varied axis.
struct StudyTable {
  /// StudySpec::name and title.
  std::string name, title;
  /// The axis with more than one value, other than seeds, systems and
  /// models: "size", "n_train" or "regularizer"; "" if none varies (then
  /// there is one column, "MSE"). If several vary, their names joined by "/"
  /// in nesting order (e.g. "size/n_train") and columns are their product.
  std::string varied_axis;
  /// Column labels in file order: "25", "100"; "small"; "none", "cn" (the
  /// sweep-file spelling of the values).
  std::vector<std::string> columns;
  /// Model labels in file order, e.g. "NODE-RK2", "PHNN-JR-DG".
  std::vector<std::string> rows;
  /// StudySpec::systems.
  std::vector<SystemKind> systems;
  /// Indices into Grid::runs of every run of the study (shared runs too), in
  /// expansion order.
  std::vector<int> runs;
  /// Column label of runs[i] (parallel to runs).
  std::vector<std::string> run_columns;
};

/// A sweep expanded into distinct runs.
///
///   const Grid grid = expand_grid(parse_sweep_file("sweeps/paper.toml"));
///   std::cout << dry_run_summary(grid, /*ranks=*/64);  // "1200 runs in 120 cells" ...
struct Grid {
  /// Distinct runs (by RunConfig::canonical()), in order of first appearance:
  /// studies in file order, then axes nested system, model, size, n_train,
  /// regularizer, seed (seed fastest).
  std::vector<RunConfig> runs;
  /// Names of the studies containing runs[i], in study order.
  std::vector<std::vector<std::string>> run_studies;
  /// Cells sorted by estimated cost, largest first, ties by key: the order
  /// in which work is handed out (largest-first scheduling).
  std::vector<Cell> cells;
  /// One per study, in file order.
  std::vector<StudyTable> studies;
  /// Sum over cells [core-seconds].
  double estimated_cost_s = 0.0;
};

/// Expands every study of `spec` and deduplicates the runs. Deterministic:
/// the same spec gives the same runs, ids and cell order.
Grid expand_grid(const SweepSpec& spec, const CostModel& cost_model = CostModel());

/// Makespan of cells with the given costs on `ranks` ranks when each cell
/// goes, largest first, to the rank that becomes free first (LPT greedy) [s].
double greedy_makespan_s(std::vector<double> cell_costs_s, int ranks);

/// The plan of a sweep, for `--dry-run`. First line exactly
/// "N runs in M cells"; then the estimated cost (core-hours, and wall time
/// on `ranks` ranks with the largest-first greedy schedule of cells), and
/// runs/cells per study. Throws std::invalid_argument if ranks < 1.
std::string dry_run_summary(const Grid& grid, int ranks);

}  // namespace phnn
