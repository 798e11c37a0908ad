// include/phnn/sweep/search.h — successive halving over settings ([search]
// in a sweep file, docs/METHOD.md "Search"): which runs the rungs have asked
// for, decided from finished results alone. Pure functions over a Grid and
// its runs' statuses and best validation losses; no HDF5, no MPI: the sweep
// and the reducer call them on what the results file holds.
#pragma once

#include <string>
#include <vector>

#include "phnn/config/run_result.h"
#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {

/// One configuration at one rung of one group (a study's configurations on
/// one system): its cell, the median over its finished seeds of the
/// criterion (best validation loss; a diverged seed +inf, a failed one left
/// out; +inf when none is left) and of the inference MSE (NaN before the
/// last rung, which has no inference), and whether it went on to the next
/// rung.
struct SearchEntry {
  int cell = -1;
  std::string label;  // the cell's table row and column: "PHNN-S-DG small/learning_rate=0.001"
  double criterion = 0.0, mse = 0.0;
  bool kept = false;
};

/// A group's rungs as far as they were decided: rungs[r] lists the
/// configurations that trained to spec.search.rungs[r], best criterion first.
struct SearchGroup {
  std::string study, system;
  std::vector<std::vector<SearchEntry>> rungs;
};

struct SearchReplay {
  /// As for adaptive sweeps: active runs, the round (rung) in progress or
  /// the last, complete, and per finished rung the configurations kept.
  AdaptiveState state;
  std::vector<SearchGroup> groups;
};

/// Replays the rungs on the results so far (status[i], criterion[i] =
/// best validation loss and mse[i] of grid.runs[i]): rung 0 asks for every
/// configuration's runs at rungs[0] steps; when every run asked for has
/// finished, each group keeps its best ceil(n / eta) configurations (ties
/// by grid order) and asks for their runs at the next rung; stops at the
/// first rung with a pending run, after the last rung, or after rung
/// `last_round` (>= 0). The same whichever ranks trained which runs, and
/// after any kill. Throws std::invalid_argument unless spec.search.enabled
/// and the sizes match.
SearchReplay replay_search(const SweepSpec& spec, const Grid& grid,
                           const std::vector<RunStatus>& status,
                           const std::vector<double>& criterion, const std::vector<double>& mse,
                           int last_round = -1);

/// What idle ranks may train ahead while rung `rung` (the one in progress,
/// SearchReplay::state.round) drains (docs/METHOD.md, "Speculation"): per
/// cell, the pending runs of the next rung of every configuration that
/// trains at `rung` (the form plan_work() takes); empty (no elements) at the
/// last rung, so also when the search is complete (its state's round is the
/// last rung).
std::vector<std::vector<int>> search_runs_ahead(const SweepSpec& spec, const Grid& grid, int rung,
                                                const std::vector<RunStatus>& status,
                                                const std::vector<double>& criterion,
                                                const std::vector<double>& mse);

/// While rung `rung` drains: the next-rung cells of the configurations that
/// the groups already complete keep. A group ranks only its own
/// configurations, so once none of its runs of the rung is pending its
/// survivors are those replay_search() keeps at the rung's end. Reads each
/// group newly complete (marks it in `decided`, resized to the groups and
/// kept by the caller for the rung); returns their survivors' next-rung
/// cells, ascending. Empty at the last rung.
std::vector<int> search_cells_known_early(const SweepSpec& spec, const Grid& grid, int rung,
                                          const std::vector<RunStatus>& status,
                                          const std::vector<double>& criterion,
                                          const std::vector<double>& mse,
                                          std::vector<char>* decided);

/// The cost model's estimate of a search: per rung the configurations that
/// train (summed over groups, each keeping ceil(n / eta)), the core-seconds
/// of halving (a configuration at rung r > 0 pays its steps and validations
/// from the rung before, going on from its state, and its own inference)
/// and of every configuration trained to the last rung.
struct SearchCost {
  std::vector<int> configurations;
  double halving_s = 0.0, full_s = 0.0;
  /// Per rung, the estimated cost of each configuration's item (a group's
  /// mean, going on from the rung before), for schedules with a barrier
  /// after each rung.
  std::vector<std::vector<double>> items_s;
};
SearchCost estimate_search_cost(const SweepSpec& spec, const Grid& grid);

/// The key of the configuration of `run`: its cell key at step budget 0,
/// with inference (the same at every rung).
std::string configuration_key(const RunConfig& run);

/// The Markdown report of a replay: per group and rung, each configuration's
/// criterion and MSE medians and whether it went on; the winner (the best
/// criterion at the last rung).
std::string search_report(const SweepSpec& spec, const SearchReplay& replay);

}  // namespace phnn
