// include/phnn/sweep/grid.h — a sweep file expanded into runs and cells.
#pragma once

#include <string>
#include <vector>

#include "phnn/sweep/run_config.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {

/// Cost model of a stack of E runs of one cell (a work item), in seconds on
/// one core. Every constant of the model lives in this struct: to refit it,
/// time `train_cell` at E = 1 and E = 10 per model-integrator (small, no
/// regularizer) and per size, and solve the line below for fixed and member.
///
///   step_us(E)     = (fixed_us[model][integrator] * fixed_size_factor[size]
///                     + E * member_us[model][integrator] * member_size_factor[size])
///                    * (regularizer != none ? regularizer_factor : 1)
///   member_us_all  = member_us[model][integrator] * member_size_factor[size]
///                    * (regularizer != none ? regularizer_factor : 1)
///
///   cost_s(E)      = steps * step_us(E) * 1e-6                       (training)
///                  + E * eval_steps * member_us_all * 1e-6   (validation, inference)
///
///   eval_steps     = evaluations * num_validation / reference_batch
///                  + num_inference * num_inference_steps
///                      / reference_batch / rollout_speedup
///                      * (integrator == DG ? dg_newton_factor : 1)
///
/// with evaluations = 1 + floor(steps / eval_every) (+ 1 when steps is not a
/// multiple of eval_every): step 0, every eval_every steps and the last step
/// (SPEC.md §4). The fixed part is the per-step cost that does not shrink
/// with fewer members (operator dispatch, autograd bookkeeping, Adam's calls):
/// it is why a stack of E members is cheaper than E single runs, and why
/// splitting a cell into groups costs core-hours. Validation (2500 pairs) and
/// inference (100 trajectories) run on large batches, where that overhead is
/// amortized, so they are charged per member only. The training cost does
/// not depend on n_train (the batch is <= 64 pairs).
struct CostModel {
  /// Per-step cost of a stack that does not depend on its size E [us], small
  /// size, no regularizer, indexed [ModelKind][IntegratorKind] (NODE-DG does
  /// not exist). Placeholders from docs/BENCHMARKS.md's E = 1 and E = 10
  /// timings: small PHNN-JR-RK2 1114 and 3190 us per step give fixed 883 and
  /// member 231; NODE-RK2 198 and 800 give 131 and 67; the PHNN-S rows and
  /// PHNN-JR-DG are PHNN-JR-RK2's split scaled to their E = 10 cost (275,
  /// 295, 319 us per member-step). To be refit after the kernel rework.
  double fixed_us[3][2] = {
      /*kNode=*/{/*kRk2=*/131.0, /*kDg=*/0.0},
      /*kPhnnS=*/{/*kRk2=*/761.0, /*kDg=*/817.0},
      /*kPhnnJr=*/{/*kRk2=*/883.0, /*kDg=*/883.0},
  };
  /// Per-step cost of each member of a stack [us], same indexing.
  double member_us[3][2] = {
      /*kNode=*/{/*kRk2=*/67.0, /*kDg=*/0.0},
      /*kPhnnS=*/{/*kRk2=*/199.0, /*kDg=*/214.0},
      /*kPhnnJr=*/{/*kRk2=*/231.0, /*kDg=*/231.0},
  };
  /// Indexed by ModelSize: small, medium, large. Assumed independent of the
  /// width (the fixed part is per-operator overhead); not measured yet.
  double fixed_size_factor[3] = {1.0, 1.0, 1.0};
  /// Indexed by ModelSize. Chosen so that PHNN-JR-RK2 at E = 10 keeps its
  /// measured 2.4x and 15x (`phnn train`: 272, 660 and 4186 us per
  /// member-step) with fixed_size_factor = 1: (10 x 231 x f + 883) / 3193.
  double member_size_factor[3] = {1.0, 2.9, 20.4};
  /// Jacobian, closed-form SVD / eigenvalues and their backward in every
  /// step (CN, SN, SR): measured 2.6-3.0x, on both parts.
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

/// Estimated cost of a work item: `members` runs of run's cell trained as one
/// stack, on one core [s] (CostModel above). Throws std::invalid_argument if
/// members < 1.
double estimate_group_cost_s(const RunConfig& run, int members,
                             const CostModel& cost_model = CostModel());

/// Runs of one cell: the same configuration but the seed (equal
/// RunConfig::cell_key()). Its runs are trained as one stack, or split into
/// member groups (phnn/sweep/work_plan.h).
struct Cell {
  /// RunConfig::cell_key() of its runs.
  std::string key;
  /// Indices into Grid::runs, sorted by seed.
  std::vector<int> runs;
  /// estimate_group_cost_s(E) = fixed_cost_s + E * member_cost_s: a stack of
  /// E of its runs [s].
  double fixed_cost_s = 0.0, member_cost_s = 0.0;
  /// Cost of all its runs as one stack: cost_s(runs.size()).
  double estimated_cost_s = 0.0;

  /// Cost of a stack of `members` of its runs [s].
  double cost_s(int members) const { return fixed_cost_s + members * member_cost_s; }
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
///   std::cout << grid.runs.size() << " runs in " << grid.cells.size() << " cells\n";
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
  /// Sum of Cell::estimated_cost_s (every cell unsplit) [core-seconds].
  double estimated_cost_s = 0.0;
};

/// Expands every study of `spec` and deduplicates the runs. Deterministic:
/// the same spec gives the same runs, ids and cell order.
Grid expand_grid(const SweepSpec& spec, const CostModel& cost_model = CostModel());

/// Makespan of items with the given costs on `ranks` ranks when each item
/// goes, largest first, to the rank that becomes free first (LPT list
/// scheduling, what the dynamic WorkQueue does) [s]. Throws
/// std::invalid_argument if ranks < 1.
double greedy_makespan_s(std::vector<double> item_costs_s, int ranks);

}  // namespace phnn
