// include/phnn/sweep/adaptive.h — adaptive seeds ([adaptive] in a sweep
// file, docs/METHOD.md "Adaptive seeds"): which runs of the grid the rounds
// have asked for, decided from finished results alone. Pure functions over a
// Grid and its runs' statuses and MSEs (the report's statistics); no HDF5,
// no MPI: the sweep and the reducer call them on what the results file holds.
#pragma once

#include <string>
#include <vector>

#include "phnn/config/run_result.h"
#include "phnn/report/statistics.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {

/// Where an adaptive sweep stands.
struct AdaptiveState {
  /// Per grid run: asked for by one of rounds 0 .. round.
  std::vector<char> active;
  /// Per grid cell: how many of its seeds (its smallest) are asked for.
  std::vector<int> cell_seeds;
  /// The round in progress (some run it asked for is pending), or the last
  /// round when complete.
  int round = 0;
  /// Every run asked for has finished and the rule names no cell below
  /// max_seeds: the sweep is done.
  bool complete = false;
  /// Per finished round k: the cells that got more seeds after it.
  std::vector<int> cells_grown;
  /// Runs asked for that are pending (the round in progress) or failed (a
  /// failed run counts as finished and its MSE is left out of the decisions,
  /// as out of the tables).
  int pending = 0, failed = 0;
  /// Finished runs no round asked for: trained ahead by idle ranks
  /// (runs_to_speculate) and not asked for since, or asked for by another
  /// rule (a file grown or replayed under another [adaptive] table). Left
  /// out of every decision and table.
  int trained_ahead = 0;

  /// Runs asked for.
  int active_runs() const;
};

/// Replays the rounds on the results so far (status[i], mse[i] of
/// grid.runs[i]): round 0 asks for every cell's initial seeds; when every run
/// asked for has finished (done, diverged or failed), adaptive_rule_cells()
/// on exactly those runs names cells, and each that is below max_seeds gets
/// its next `batch` seeds (fewer at the cap). Stops at the first round with a
/// pending run, or when no cell grows. A run's result depends only on its
/// configuration and seed, so the state is the same whichever ranks trained
/// which runs, in whatever groups and order, and after any kill. With
/// last_round >= 0 the replay also stops after that round (the runs of rounds
/// 0 .. last_round; complete only if the sweep ended there): the sweep as it
/// stood then, e.g. round 0 = every cell at its initial seeds. Throws
/// std::invalid_argument unless spec.adaptive.enabled and the sizes match.
AdaptiveState replay_adaptive_rounds(const SweepSpec& spec, const Grid& grid,
                                     const std::vector<RunStatus>& status,
                                     const std::vector<double>& mse,
                                     const BootstrapOptions& bootstrap = {},
                                     int last_round = -1);

/// The cells (indices into grid.cells, ascending) that spec.adaptive.rule
/// names when the runs with active[i] != 0 are the results:
///   column-best:  undecided_cells() of the study tables (phnn/report/tables.h):
///                 the (tie) cells, and cells without an interval;
///   comparisons:  for each comparison, the smallest-median cell of each side
///                 (among cells with a finished run; a side without one skips
///                 the comparison); both are named unless the two bootstrap
///                 intervals of the medians are disjoint (a side with fewer
///                 than kMinSeedsForInterval finished runs has none: named);
///                 with futility, a futile comparison names none; with
///                 grow = "one" (AdaptiveSpec::grow_one), a comparison whose
///                 sides both have intervals and unequal medians names one:
///                 the side whose next seeds close more of the gap per
///                 core-second of the grid's cost model (docs/METHOD.md).
std::vector<int> adaptive_rule_cells(const SweepSpec& spec, const Grid& grid,
                                     const std::vector<char>& active,
                                     const std::vector<RunStatus>& status,
                                     const std::vector<double>& mse,
                                     const BootstrapOptions& bootstrap = {});

/// What idle ranks may train ahead while a round drains (docs/METHOD.md,
/// "Speculation"): per candidate cell below max_seeds, its next `batch`
/// seeds (fewer at the cap) that are still pending: element c lists cell c's
/// (ascending; empty for most), the form plan_work() takes. Candidates: with
/// the comparisons rule every cell a comparison selects from — the ones the
/// next round grows become known while the round drains (cells_named_early);
/// with column-best the cells the round in progress grows (a cell with a
/// pending run asked for), on the guess that they stay undecided. Empty (no
/// elements) when none is left or `state` is complete. A run's result
/// depends only on its configuration and seed, so training a run early
/// changes neither what the rule asks for nor a number.
std::vector<std::vector<int>> runs_to_speculate(const SweepSpec& spec, const Grid& grid,
                                                const AdaptiveState& state,
                                                const std::vector<RunStatus>& status);

/// The comparisons rule: per comparison of spec.adaptive.comparisons, the
/// cells below max_seeds it names when the runs with active[i] != 0 are the
/// results (their union is adaptive_rule_cells()'s, less the cells at the
/// cap); only those with read[j] != 0 unless `read` is empty, the others
/// left empty. All empty for the column-best rule.
std::vector<std::vector<int>> comparison_named_cells(const SweepSpec& spec, const Grid& grid,
                                                     const std::vector<char>& active,
                                                     const std::vector<RunStatus>& status,
                                                     const std::vector<double>& mse,
                                                     const std::vector<char>& read = {},
                                                     const BootstrapOptions& bootstrap = {});

/// The comparisons rule while a round drains: the cells its next round is
/// certain to grow, from the runs finished so far. A comparison names cells
/// from the runs of the cells its two sides select from alone, so once none
/// of those has a pending run asked for (`active`, `status`), what it names
/// is what adaptive_rule_cells() names for it at the round's end; a cell any
/// comparison names grows. Evaluates each comparison that is newly complete
/// (marks it in `decided`, resized to the comparisons and kept by the caller
/// for the round) and returns the cells below max_seeds they name,
/// ascending. Empty for the column-best rule, whose columns are not known
/// before the round ends.
std::vector<int> cells_named_early(const SweepSpec& spec, const Grid& grid,
                                   const std::vector<char>& active,
                                   const std::vector<RunStatus>& status,
                                   const std::vector<double>& mse, std::vector<char>* decided,
                                   const BootstrapOptions& bootstrap = {});

/// The sweep of round 0 alone: `spec` without [adaptive], every study's
/// seeds its initial ones (for --dry-run's round-0 cost).
SweepSpec round_zero_spec(const SweepSpec& spec);

}  // namespace phnn
