// src/apps/sweep_report.h — what `phnn sweep` prints on rank 0: the plan
// line, the per-item lines, the [progress] line with its cost-model ETA, and
// the summary after the file is closed. Reads the results file only for the
// summary.
#pragma once

#include <string>
#include <vector>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/merge.h"  // Shard
#include "phnn/sweep/scheduler.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/sweep/work_plan.h"

namespace phnn {
namespace apps {

/// "45 s", "12.5 min", "3.2 h".
std::string format_duration(double seconds);

// Rank 0's [progress] line: items done, runs per minute, elapsed time, an ETA
// from the cost model (the estimated cost still to do over the estimated
// cost done per elapsed second: items are handed out largest first, so a
// count of items would overestimate), and the UTC time. Under static
// scheduling rank 0 sees only its own items (every size-th): the line counts
// that share and says so.
class ProgressLine {
 public:
  ProgressLine(const std::vector<WorkItem>& work, int ranks, bool static_share);
  void print(int items_done, double elapsed_s) const;

 private:
  bool static_share_;
  std::vector<double> cost_;  // cumulative estimated cost of the items rank 0 counts
  std::vector<long> runs_;    // cumulative runs of the same items
};

/// "harmonic PHNN-JR-RK2 small n_train=25 reg=none".
std::string describe(const RunConfig& run);

/// Rank 0's opening line: what is done, what is left, how it is split.
void print_plan(const SweepSpec& spec, const Grid& grid, const Shard& shard,
                int runs_done_before, int runs_to_do, const WorkPlan& plan, int size,
                ScheduleMode mode, const std::string& out);

/// One per-item line, prefix + text, with the time: e.g. "item 3/8: <cell>, 2 seeds".
void print_item(const std::string& prefix, const std::string& text);

/// Why a sweep ended before its queue was empty.
enum class StopReason { kNone, kSignal, kError };

/// Rank 0's summary line(s) after the file is closed. `adaptive_line`: where
/// an adaptive sweep that ran to its end stands (its pending runs are the
/// seeds no round asked for), said instead of "runs remain".
void print_summary(const std::string& out, int total_runs, double seconds, StopReason stop,
                   const Shard& shard, const std::string& adaptive_line = "");

}  // namespace apps
}  // namespace phnn
