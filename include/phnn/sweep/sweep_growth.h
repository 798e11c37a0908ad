// include/phnn/sweep/sweep_growth.h — sweeps that grow: a results file's
// identity is its set of runs, not its sweep text. Compares the runs of an
// existing results file with a sweep's runs and, when nothing is changed or
// lost, writes the file's new version (the sweep's runs in the sweep's order,
// every finished run copied bitwise). Serial; rank 0 under the writer lock.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/config/run_result.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {

/// How the runs of a results file (its canonical configurations, one per
/// row) relate to the runs of a sweep. Runs are the same when their
/// canonical configurations are equal; a run is *changed* when the file has a
/// run at the same grid point (system, model, integrator, size, n_train,
/// regularizer, seed) that the sweep no longer has, and the sweep has a new
/// run there (e.g. `steps` or `lr` edited).
struct RunSetComparison {
  /// Per run of the sweep: its row in the file, or -1 for a run to add.
  std::vector<int> file_row_of_run;
  /// Runs of the sweep that the file lacks (new seeds, systems, axis values).
  int added = 0;
  /// File rows that are not in the sweep and hold no result (pending): dropped.
  std::vector<int> dropped_pending_rows;
  /// File rows that are not in the sweep but hold a result (done, diverged,
  /// failed) and are not changed runs: refused, a result would be lost.
  std::vector<int> removed_result_rows;
  /// Changed runs, grouped by what changed, e.g.
  ///   "steps: 50000 -> 25000 (20 runs, e.g. duffing phnn-jr-rk2 small n_train=25 none seed=0)".
  std::vector<std::string> changes;

  /// The file's rows are the sweep's runs, in order: only the text differs.
  bool same_runs_in_order() const;
  /// A change, or a result that the new version would drop.
  bool refused() const { return !changes.empty() || !removed_result_rows.empty(); }
};

/// Compares a file's rows (`file_canonical[row]`, `file_status[row]`) with the
/// sweep's runs. Throws std::invalid_argument if the two file columns differ
/// in length.
RunSetComparison compare_run_sets(const std::vector<std::string>& file_canonical,
                                  const std::vector<RunStatus>& file_status,
                                  const std::vector<RunConfig>& sweep_runs);

/// A sweep that would change a run or lose a result; what() names the
/// results file, each change and the fix.
class RunSetRefused : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Writes the new version of results file `out` (a phnn results file of
/// another sweep text) for `spec`/`grid`: a new file with the grid's runs,
/// the spec's text and hash, the old file's provenance sessions, and every
/// row of the old file that holds a result copied bitwise (verified by
/// reading it back) with its run times. A row whose checksum fails is never
/// copied as it stands: it is written from the journals' record of its run
/// (`out`'s journal directory), or, if they lack the run, left pending to be
/// trained again; both are named in the account. The old rows' runs are
/// read from /runs/canonical checked against the file's own sweep text: a
/// damaged cell is named and its row compared as the text's run (and
/// repaired as damaged); with the text damaged too, RunSetRefused (nothing
/// written). /data is left to the caller (the
/// sweep writes missing data groups on resume). The new file replaces `out`
/// by an atomic rename, so a crash leaves either version whole. Throws
/// RunSetRefused (nothing written) when compare_run_sets() refuses, and
/// std::runtime_error naming the file when I/O fails. Returns a one-line
/// account for the log, e.g.
///   "results/x.h5: the sweep grew by 10 runs; new version with 20 finished runs kept bitwise".
std::string write_grown_results(const std::string& out, const SweepSpec& spec, const Grid& grid,
                                const std::string& program_version);

}  // namespace phnn
