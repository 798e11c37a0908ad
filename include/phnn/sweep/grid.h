// include/phnn/sweep/grid.h — a sweep file expanded into runs and cells
// (the Grid itself, which the report reads too, is in phnn/config/run_grid.h)
// and the cost model that orders the cells.
#pragma once

#include <string>
#include <vector>

#include "phnn/config/run_config.h"
#include "phnn/config/run_grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {

/// Cost model of a stack of E runs of one cell (a work item), in seconds on
/// one core. Every constant of the model lives in this struct: to refit it,
/// time `train_cell` at E = 1 and E = 10 per model-integrator (small, no
/// regularizer) and per size, and solve the line below for fixed and member.
///
///   step_us(E)     = fixed_us[model][integrator] * fixed_size_factor[size]
///                      * (regularizer != none ? regularizer_fixed_factor : 1)
///                    + E * member_us_all
///   member_us_all  = member_us[model][integrator] * member_size_factor[size]
///                    * (regularizer != none ? regularizer_factor : 1)
///
///   cost_s(E)      = steps * step_us(E) * prec * 1e-6                (training)
///                  + E * (validation * prec + inference) * member_us_all * 1e-6
///
///   validation     = evaluations * num_validation / reference_batch
///   inference      = num_inference * num_inference_steps
///                      / reference_batch / rollout_speedup
///                      * (integrator == DG ? dg_newton_factor : 1)
///   prec           = precision == float32 ? float32_factor : 1
///
/// with evaluations = 1 + floor(steps / eval_every) (+ 1 when steps is not a
/// multiple of eval_every): step 0, every eval_every steps and the last step
/// (docs/METHOD.md §4). The fixed part is the per-step cost that does not shrink
/// with fewer members (operator dispatch, autograd bookkeeping, Adam's calls):
/// it is why a stack of E members is cheaper than E single runs, and why
/// splitting a cell into groups costs core-hours. Validation (2500 pairs) and
/// inference (100 trajectories) run on large batches, where that overhead is
/// amortized, so they are charged per member only. The training cost does
/// not depend on n_train (the batch is <= 64 pairs).
struct CostModel {
  /// Per-step cost of a stack that does not depend on its size E [us], small
  /// size, no regularizer, indexed [ModelKind][IntegratorKind] (NODE-DG does
  /// not exist). Fit to bench/bench_training `stacked` (fused networks, one
  /// quiet core, docs/BENCHMARKS.md, 2026-11-23): t(E) = fixed + E member per
  /// step from the E = 1 and E = 10 timings, e.g. small PHNN-JR-RK2 152 and
  /// 78 us per member-step give fixed 82 and member 70.
  /// RK4 and DG4 are scaled from RK2 and DG by their measured ratio at
  /// E = 10 (bench_training run, one run each on a shared core, small, an
  /// earlier revision): PHNN-JR RK4 246 vs RK2 109 us (2.3x), NODE RK4 2x
  /// NODE-RK2, PHNN-JR-DG4 989 vs DG 131 (7.5x: order-2 jets of both
  /// networks, H at five points), PHNN-S-DG4 560 vs DG 103 (5.4x); the fixed
  /// and member parts by the same factor.
  double fixed_us[3][4] = {
      /*kNode=*/{/*kRk2=*/43.0, /*kDg=*/0.0, /*kRk4=*/86.0, /*kDg4=*/0.0},
      /*kPhnnS=*/{/*kRk2=*/87.0, /*kDg=*/64.0, /*kRk4=*/200.0, /*kDg4=*/346.0},
      /*kPhnnJr=*/{/*kRk2=*/82.0, /*kDg=*/89.0, /*kRk4=*/189.0, /*kDg4=*/668.0},
  };
  /// Per-step cost of each member of a stack [us], same indexing.
  double member_us[3][4] = {
      /*kNode=*/{/*kRk2=*/30.0, /*kDg=*/0.0, /*kRk4=*/60.0, /*kDg4=*/0.0},
      /*kPhnnS=*/{/*kRk2=*/71.0, /*kDg=*/64.0, /*kRk4=*/163.0, /*kDg4=*/346.0},
      /*kPhnnJr=*/{/*kRk2=*/70.0, /*kDg=*/60.0, /*kRk4=*/161.0, /*kDg4=*/450.0},
  };
  /// Indexed by ModelSize: small, medium, large. Assumed independent of the
  /// width (the fixed part is per-operator overhead); not measured.
  double fixed_size_factor[3] = {1.0, 1.0, 1.0};
  /// Indexed by ModelSize. At E = 10 the fused medium models cost 3.0-3.9x
  /// (NODE 104, PHNN 198-244 us per member-step) and the large PHNN-JR-RK2
  /// 14.7x (1 037 us) their small member cost, with fixed_size_factor 1.
  double member_size_factor[3] = {1.0, 3.4, 14.7};
  /// Jacobian (second-order jets for the PHNNs), closed-form SVD /
  /// eigenvalues and their backward in every step (CN, SN, SR), indexed
  /// [ModelKind][IntegratorKind], on the member part (regularizer_factor) and
  /// the fixed part (regularizer_fixed_factor) of a step: from the E = 1 and
  /// E = 10 timings with CN (bench_training stacked), e.g. PHNN-JR-RK2 368 and
  /// 135 us: fixed 259 = 3.2 x 82, member 109 = 1.6 x 70. RK4 and DG4 take
  /// RK2's and DG's (not measured; RK4 shares only one of its four stages with
  /// the Jacobian's evaluation, so it is underestimated a little).
  double regularizer_factor[3][4] = {
      /*kNode=*/{/*kRk2=*/1.7, /*kDg=*/0.0, /*kRk4=*/1.7, /*kDg4=*/0.0},
      /*kPhnnS=*/{/*kRk2=*/1.7, /*kDg=*/2.3, /*kRk4=*/1.7, /*kDg4=*/2.3},
      /*kPhnnJr=*/{/*kRk2=*/1.6, /*kDg=*/2.2, /*kRk4=*/1.6, /*kDg4=*/2.2},
  };
  double regularizer_fixed_factor[3][4] = {
      /*kNode=*/{/*kRk2=*/4.5, /*kDg=*/0.0, /*kRk4=*/4.5, /*kDg4=*/0.0},
      /*kPhnnS=*/{/*kRk2=*/4.2, /*kDg=*/6.4, /*kRk4=*/4.2, /*kDg4=*/6.4},
      /*kPhnnJr=*/{/*kRk2=*/3.2, /*kDg=*/3.5, /*kRk4=*/3.2, /*kDg4=*/3.5},
  };
  /// `[training] precision = "float32"` trains on the op-by-op networks in
  /// float32: training steps and validation cost this factor more (inference
  /// is float64 on the fused path, unchanged). bench_training precision, small,
  /// E = 10: 2.0-3.3x (docs/DECISIONS.md, "Ablation knobs").
  double float32_factor = 2.7;
  /// A training step on a batch smaller than reference_batch (N_train < 64)
  /// costs member_us x (1 - small_batch_saving x (64 - batch) / 64) per
  /// member (validation and inference are not affected).
  double small_batch_saving = 0.85;  // PHNN-JR-RK2 E = 10: 64 us at batch 25, 110 at 64
  /// Runs of a system file cost the built-in path's times
  ///   general_node_factor                                   (NODE)
  ///   general_phnn_base + general_phnn_per_state2 * n_x^2   (PHNNs)
  /// (the same models and steps since kernel set 2; the factor is the
  /// larger networks and heads), fit to `bench_training general`
  /// (docs/BENCHMARKS.md, 2026-11-28, E = 10, chains of masses): PHNN-JR-RK2
  /// 34-36, 43-45, 75-93, 88-111 us per member-step at n_x = 2, 4, 6, 8
  /// against 34-36 for the built-in Duffing; PHNN-S-RK2 37-38, 48-49, 64-69,
  /// 86-105; NODE 16-20 at every n_x. Kernel set 1's n-state path cost
  /// 11.6 + 0.48 n_x^2 times the built-in path.
  double general_node_factor = 1.0;
  double general_phnn_base = 0.9;
  double general_phnn_per_state2 = 0.026;
  /// Pairs per batch-step in the validation and inference terms.
  double reference_batch = 64.0;
  /// A rollout state-step costs 1 / rollout_speedup of a training pair-step
  /// (forward only, no backward; fit to `bench_training inference`: a small
  /// PHNN-JR-RK2 cell's 2 validations and 102 x 500-step rollouts, 0.57 s).
  double rollout_speedup = 1.6;
  /// DG rollouts solve a Newton system per step (simplified Newton, 3-6
  /// residual evaluations; the same cell with DG: 2.4 s).
  double dg_newton_factor = 5.0;
};

/// Estimated cost of a work item: `members` runs of run's cell trained as one
/// stack, on one core [s] (CostModel above). Throws std::invalid_argument if
/// members < 1.
double estimate_group_cost_s(const RunConfig& run, int members,
                             const CostModel& cost_model = CostModel());

/// Expands every study of `spec` and deduplicates the runs. Deterministic:
/// the same spec gives the same runs, ids and cell order.
Grid expand_grid(const SweepSpec& spec, const CostModel& cost_model = CostModel());

/// Per run of grid.runs, the index of its cell in grid.cells.
std::vector<int> cell_of_runs(const Grid& grid);

/// Makespan of items with the given costs on `ranks` ranks when each item
/// goes, largest first, to the rank that becomes free first (LPT list
/// scheduling, what the dynamic WorkQueue does) [s]. Throws
/// std::invalid_argument if ranks < 1.
double greedy_makespan_s(std::vector<double> item_costs_s, int ranks);

}  // namespace phnn
