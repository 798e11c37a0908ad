// src/apps/reduce_rule.h — `phnn reduce FILE --rule SWEEP`: FILE's runs seen
// through another sweep file's grid, so that SWEEP's [adaptive] table can be
// replayed on results another rule trained (docs/METHOD.md, "Adaptive seeds",
// replaying a rule). Reads the results file; writes nothing.
#pragma once

#include <string>
#include <vector>

#include "phnn/store/results_file.h"
#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace apps {

/// SWEEP's grid with, per run, the row of FILE that holds it (by run id), or
/// -1 when FILE lacks it: the replay sees such a run as pending.
struct RuleView {
  SweepSpec spec;
  Grid grid;
  std::vector<int> row;
};

/// Parses `rule_path` (a sweep file with an [adaptive] table; its system
/// files read from disk, relative to it) and maps its runs onto `file`'s
/// rows. Throws cli::UsageError when the file has no [adaptive] table or
/// shares no run with `file` (another grid: a typo, or edited system files).
RuleView rule_view(const ResultsFile& file, const std::string& rule_path);

/// values[row[i]] per run of the view; `missing` where row[i] < 0.
template <class T>
std::vector<T> through_view(const RuleView& view, const std::vector<T>& values, const T& missing) {
  std::vector<T> out(view.row.size(), missing);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (view.row[i] >= 0) out[i] = values[static_cast<std::size_t>(view.row[i])];
  }
  return out;
}

/// `phnn reduce FILE --round K --named`: what each comparison of the
/// [adaptive] table names after round K (state: the replay up to K), one
/// CSV row per named cell: its 1-based index, its line in the sweep file,
/// the cell as a selector ("system/model/n_train/size/regularizer"). For
/// analysis/rounds_replay.py, which replays when each cell of the next round
/// became known as the round drained. Throws cli::UsageError naming `path`
/// for a file that is not an adaptive sweep (state null) or whose rule is
/// not comparisons.
std::string named_cells_csv(const SweepSpec& spec, const Grid& grid, const AdaptiveState* state,
                            const std::vector<RunStatus>& status, const std::vector<double>& mse,
                            const std::string& path);

}  // namespace apps
}  // namespace phnn
