// include/phnn/sweep/work_plan.h — the work items of a sweep: cells, or
// contiguous member groups of a cell, chosen from the cost model and the
// number of ranks; the simulated schedule behind `phnn sweep --dry-run`.
#pragma once

#include <string>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/sweep/grid.h"

namespace phnn {

/// How plan_work() may split a cell's runs into member groups. Stacking is
/// exact, so the split changes the wall time and the core-hours, never a
/// result.
struct SplitOptions {
  enum class Mode {
    /// Split where the simulated makespan gains more than min_gain.
    kAuto,
    /// One item per cell (today's behaviour); max_group_size must be 0.
    kOff,
  };
  Mode mode = Mode::kAuto;
  /// If > 0, no group has more than this many runs (forces splitting; for
  /// tests, or to bound the memory of a stack). 0 = no cap.
  int max_group_size = 0;
  /// A split costs core-hours (CostModel::fixed_us per extra group and
  /// step), so kAuto takes the cheapest plan (fewest core-hours) whose
  /// simulated makespan is within (1 + min_gain) of the best plan's. 0.01:
  /// splitting has to save more than 1 % of the wall time.
  double min_gain = 0.01;

  /// Throws std::invalid_argument naming the field, value and constraint.
  void validate() const;
};

inline constexpr EnumNames<SplitOptions::Mode, 2> kSplitModeNames{
    "split mode", {{{SplitOptions::Mode::kAuto, "auto"}, {SplitOptions::Mode::kOff, "off"}}}};
inline std::string to_string(SplitOptions::Mode mode) { return kSplitModeNames.name(mode); }
/// Throws std::invalid_argument listing the modes.
inline SplitOptions::Mode parse_split_mode(const std::string& text) { return kSplitModeNames.parse(text); }

/// A unit of work handed to one rank: some runs of one cell, trained as one
/// stack.
struct WorkItem {
  /// Index into Grid::cells.
  int cell = 0;
  /// Indices into Grid::runs: a contiguous piece of the cell's runs to do,
  /// seeds ascending.
  std::vector<int> runs;
  /// Cell::cost_s(runs.size()).
  double estimated_cost_s = 0.0;
};

/// The items of a sweep and their simulated schedule.
///
///   const WorkPlan plan = plan_work(grid, /*ranks=*/128);
///   WorkQueue queue(comm, plan.items.size(), ScheduleMode::kDynamic);
struct WorkPlan {
  /// Largest estimated cost first; ties by cell index, then first run. Every
  /// run to do is in exactly one item.
  std::vector<WorkItem> items;
  /// Ranks the plan was made for.
  int ranks = 1;
  /// Cells with runs to do, and how many of them are split (> 1 item).
  int cells = 0, split_cells = 0;
  /// Sum of the costs of the cells with their runs to do as one stack each:
  /// the work without splitting [core-seconds].
  double unsplit_cost_s = 0.0;
  /// Sum of the item costs (>= unsplit_cost_s) [core-seconds].
  double cost_s = 0.0;
  /// greedy_makespan_s() of the items on `ranks` ranks [s].
  double makespan_s = 0.0;

  /// unsplit_cost_s / (ranks x makespan_s); 1 for an empty plan.
  double efficiency() const;
};

/// Splits the runs to do into work items for `ranks` ranks. pending[c] lists
/// the runs of grid.cells[c] still to train (a subset of Cell::runs,
/// ascending; empty = nothing to do). Deterministic: the same arguments give
/// the same plan on every rank.
///
/// Policy (kAuto; docs/DECISIONS.md "Member groups"): candidates are (1)
/// the uniform cuts: for a target S, each cell in the fewest near-equal
/// contiguous groups costing <= S (a cell that fits stays whole), at every S
/// where that changes, from the largest cell down to the largest single
/// run; (2) a descent on the group counts from the best uniform cut and from
/// the unsplit plan, moving the count of each class of equal-cost cells by
/// -2..+3 while the (makespan, core-hours) pair improves. Every candidate's
/// schedule is simulated with greedy_makespan_s(); the plan taken is the
/// cheapest whose makespan is within (1 + min_gain) of the shortest. Throws
/// std::invalid_argument if ranks < 1, the options are invalid, or pending
/// does not match the grid.
WorkPlan plan_work(const Grid& grid, const std::vector<std::vector<int>>& pending, int ranks,
                   const SplitOptions& options = SplitOptions());

/// plan_work() with every run of the grid to do.
WorkPlan plan_work(const Grid& grid, int ranks, const SplitOptions& options = SplitOptions());

/// One line for `--dry-run`, e.g. "128 ranks: 171 items (105 whole cells +
/// 66 groups of 15 cells), makespan 9.6 min, 17.4 core-hours, efficiency
/// 82.2 %".
std::string schedule_line(const WorkPlan& plan);

/// The plan of a sweep, for `--dry-run`. First line exactly
/// "N runs in M cells"; then the estimated cost unsplit (core-hours), the
/// largest and smallest cell, one schedule_line() per entry of `ranks`, and
/// runs/cells per study. Throws std::invalid_argument if a rank count is < 1
/// or `ranks` is empty.
std::string dry_run_summary(const Grid& grid, const std::vector<int>& ranks,
                            const SplitOptions& options = SplitOptions());

/// The cost model's estimate of every cell, for `--dry-run --cell-costs`:
/// CSV, header "cell,system,model,size,n_train,regularizer,members,fixed_s,
/// member_s,estimated_s,run_ids", one line per cell in Grid::cells order
/// (largest first), run_ids its runs' RunConfig::id() separated by spaces
/// (to join with `phnn reduce --format csv --per-run`, e.g.
/// analysis/cost_model_check.py).
std::string cell_costs_csv(const Grid& grid);

/// The items of `plan`, for `--dry-run --items`: CSV, header
/// "item,cell,runs,estimated_s,run_ids", one line per item in plan order
/// (the order the ranks take them), cell its index in Grid::cells (as in
/// cell_costs_csv()), runs its size, run_ids its runs' RunConfig::id()
/// separated by spaces (e.g. analysis/schedule_replay.py).
std::string plan_items_csv(const Grid& grid, const WorkPlan& plan);

}  // namespace phnn
