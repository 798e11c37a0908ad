// src/sweep/work_plan.cpp — cells split into member groups by the cost model;
// the LPT schedule simulation behind `--dry-run`.
// Size: the split decision and the schedule it is judged by belong together.
#include "phnn/sweep/work_plan.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "phnn/config/model_config.h"

namespace phnn {

void SplitOptions::validate() const {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("Invalid SplitOptions: " + what);
  };
  if (max_group_size < 0) {
    fail("max_group_size = " + std::to_string(max_group_size) +
         "; violated constraint: max_group_size >= 0 (0 = no cap).");
  }
  if (mode == Mode::kOff && max_group_size > 0) {
    fail("max_group_size = " + std::to_string(max_group_size) +
         " with mode off; a cap splits cells, so it needs mode auto.");
  }
  if (!(min_gain >= 0.0)) {
    fail("min_gain = " + std::to_string(min_gain) + "; violated constraint: min_gain >= 0.");
  }
}

double WorkPlan::efficiency() const {
  return makespan_s > 0.0 ? unsplit_cost_s / (ranks * makespan_s) : 1.0;
}

namespace {

using Pending = std::vector<std::vector<int>>;

void check_pending(const Grid& grid, const Pending& pending) {
  if (pending.size() != grid.cells.size()) {
    throw std::invalid_argument("plan_work: pending has " + std::to_string(pending.size()) +
                                " entries for " + std::to_string(grid.cells.size()) +
                                " cells; give one (possibly empty) list per cell");
  }
  for (std::size_t c = 0; c < pending.size(); ++c) {
    const std::set<int> runs(grid.cells[c].runs.begin(), grid.cells[c].runs.end());
    for (int run : pending[c]) {
      if (runs.count(run) == 0) {
        throw std::invalid_argument("plan_work: run " + std::to_string(run) +
                                    " is not a run of cell " + std::to_string(c));
      }
    }
  }
}

// Size of the largest of g near-equal groups of n runs.
int largest_group(int n, int g) { return (n + g - 1) / g; }

// Fewest groups for n runs of `cell` with every group's cost <= target and
// at most `cap` runs (0 = no cap); n groups (single runs) if none fits.
int group_count(const Cell& cell, int n, double target, int cap) {
  const int first = cap > 0 ? largest_group(n, cap) : 1;
  for (int g = first; g < n; ++g) {
    if (cell.cost_s(largest_group(n, g)) <= target) return g;
  }
  return std::max(1, n);
}

std::vector<int> group_counts(const Grid& grid, const Pending& pending, double target, int cap) {
  std::vector<int> counts(pending.size(), 0);
  for (std::size_t c = 0; c < pending.size(); ++c) {
    const int n = static_cast<int>(pending[c].size());
    if (n > 0) counts[c] = group_count(grid.cells[c], n, target, cap);
  }
  return counts;
}

// Items of cell c: its pending runs in counts near-equal contiguous groups,
// the larger groups first.
void append_items(const Grid& grid, int c, const std::vector<int>& runs, int count,
                  std::vector<WorkItem>* items) {
  const int n = static_cast<int>(runs.size());
  int begin = 0;
  for (int g = 0; g < count; ++g) {
    const int size = n / count + (g < n % count ? 1 : 0);
    WorkItem item;
    item.cell = c;
    item.runs.assign(runs.begin() + begin, runs.begin() + begin + size);
    item.estimated_cost_s = grid.cells[c].cost_s(size);
    items->push_back(std::move(item));
    begin += size;
  }
}

WorkPlan make_plan(const Grid& grid, const Pending& pending, const std::vector<int>& counts,
                   int ranks) {
  WorkPlan plan;
  plan.ranks = ranks;
  for (std::size_t c = 0; c < pending.size(); ++c) {
    if (pending[c].empty()) continue;
    ++plan.cells;
    if (counts[c] > 1) ++plan.split_cells;
    plan.unsplit_cost_s += grid.cells[c].cost_s(static_cast<int>(pending[c].size()));
    append_items(grid, static_cast<int>(c), pending[c], counts[c], &plan.items);
  }
  std::stable_sort(plan.items.begin(), plan.items.end(), [](const WorkItem& a, const WorkItem& b) {
    return a.estimated_cost_s > b.estimated_cost_s;
  });
  std::vector<double> costs;
  for (const WorkItem& item : plan.items) {
    costs.push_back(item.estimated_cost_s);
    plan.cost_s += item.estimated_cost_s;
  }
  plan.makespan_s = greedy_makespan_s(costs, ranks);
  return plan;
}

// Every target at which group_counts() changes, largest first: the cost of
// a group of k runs of each cell, from the largest cell (or capped group)
// down to the largest single run, below which nothing changes.
std::vector<double> candidate_targets(const Grid& grid, const Pending& pending, int cap) {
  double floor = 0.0;
  for (std::size_t c = 0; c < pending.size(); ++c) {
    if (!pending[c].empty()) floor = std::max(floor, grid.cells[c].cost_s(1));
  }
  std::set<double, std::greater<double>> targets;
  for (std::size_t c = 0; c < pending.size(); ++c) {
    const int n = static_cast<int>(pending[c].size());
    const int largest = cap > 0 ? std::min(n, cap) : n;
    for (int k = 1; k <= largest; ++k) {
      const double cost = grid.cells[c].cost_s(k);
      if (cost >= floor) targets.insert(cost);
    }
  }
  return std::vector<double>(targets.begin(), targets.end());
}

// Cells whose pending runs cost the same (count, fixed and member cost), in
// the order of their first cell (largest first): the refinement below
// changes their group counts together. The paper grid's 120 cells form 40
// classes (a configuration in its three systems).
std::vector<std::vector<int>> equal_cost_classes(const Grid& grid, const Pending& pending) {
  std::map<std::tuple<std::size_t, double, double>, std::size_t> index;
  std::vector<std::vector<int>> classes;
  for (std::size_t c = 0; c < pending.size(); ++c) {
    if (pending[c].empty()) continue;
    const auto key =
        std::make_tuple(pending[c].size(), grid.cells[c].fixed_cost_s, grid.cells[c].member_cost_s);
    const auto [it, added] = index.emplace(key, classes.size());
    if (added) classes.emplace_back();
    classes[it->second].push_back(static_cast<int>(c));
  }
  return classes;
}

// A plan's group counts and what its simulation gives (without its items,
// so that the hundreds of candidates of a large grid stay small).
struct Candidate {
  std::vector<int> counts;
  double makespan_s = 0.0, cost_s = 0.0;
};

Candidate simulate(const Grid& grid, const Pending& pending, std::vector<int> counts, int ranks) {
  const WorkPlan plan = make_plan(grid, pending, counts, ranks);
  return {std::move(counts), plan.makespan_s, plan.cost_s};
}

// Plans compare by simulated makespan, then by core-hours (a split that does
// not shorten the schedule only costs).
bool better(const Candidate& a, const Candidate& b) {
  constexpr double kRelative = 1e-12;  // sums of <= ~10^4 costs: round-off far below
  if (a.makespan_s < b.makespan_s * (1.0 - kRelative)) return true;
  if (a.makespan_s > b.makespan_s * (1.0 + kRelative)) return false;
  return a.cost_s < b.cost_s * (1.0 - kRelative);
}

// Descent on the group counts, one class of equal cells (equal_cost_classes)
// at a time: change the class's count by -2..+3 and keep the change if
// better(). A uniform cost target cannot split a cell below the target (two
// 38-s cells on a 72-s makespan) while cutting a larger one; this can. Stops
// when no move helps; each kept move strictly improves (makespan, cost), so
// it ends.
Candidate refine(const Grid& grid, const Pending& pending,
                 const std::vector<std::vector<int>>& classes, Candidate best, int ranks, int cap) {
  for (bool improved = true; improved;) {
    improved = false;
    for (const std::vector<int>& cells : classes) {
      const int n = static_cast<int>(pending[static_cast<std::size_t>(cells.front())].size());
      const int fewest = cap > 0 ? largest_group(n, cap) : 1;
      for (int step : {-2, -1, 1, 2, 3}) {
        const int count = best.counts[static_cast<std::size_t>(cells.front())] + step;
        if (count < fewest || count > n) continue;
        std::vector<int> trial = best.counts;
        for (int c : cells) trial[static_cast<std::size_t>(c)] = count;
        Candidate candidate = simulate(grid, pending, std::move(trial), ranks);
        if (better(candidate, best)) {
          best = std::move(candidate);
          improved = true;
        }
      }
    }
  }
  return best;
}

}  // namespace

WorkPlan plan_work(const Grid& grid, const Pending& pending, int ranks,
                   const SplitOptions& options) {
  options.validate();
  check_pending(grid, pending);
  if (ranks < 1) {
    throw std::invalid_argument("plan_work: ranks = " + std::to_string(ranks) +
                                "; need at least 1 rank");
  }
  const int cap = options.max_group_size;
  const std::vector<int> unsplit = group_counts(grid, pending, /*target=*/1e300, cap);
  const std::vector<double> targets = candidate_targets(grid, pending, cap);
  if (options.mode == SplitOptions::Mode::kOff || targets.empty()) {
    return make_plan(grid, pending, unsplit, ranks);
  }
  // Candidates: the uniform cut at every target, then the refinement of the
  // best of them and of the unsplit plan.
  std::vector<Candidate> candidates;
  for (double target : targets) {
    candidates.push_back(simulate(grid, pending, group_counts(grid, pending, target, cap), ranks));
  }
  const Candidate best_cut = *std::min_element(candidates.begin(), candidates.end(), better);
  const std::vector<std::vector<int>> classes = equal_cost_classes(grid, pending);
  candidates.push_back(refine(grid, pending, classes, best_cut, ranks, cap));
  candidates.push_back(
      refine(grid, pending, classes, simulate(grid, pending, unsplit, ranks), ranks, cap));
  // The cheapest plan (fewest core-hours) within (1 + min_gain) of the
  // shortest makespan; the first such on ties.
  const double shortest =
      std::min_element(candidates.begin(), candidates.end(), better)->makespan_s;
  const Candidate* chosen = nullptr;
  for (const Candidate& c : candidates) {
    if (c.makespan_s > shortest * (1.0 + options.min_gain)) continue;
    if (chosen == nullptr || c.cost_s < chosen->cost_s) chosen = &c;
  }
  return make_plan(grid, pending, chosen->counts, ranks);
}

WorkPlan plan_work(const Grid& grid, int ranks, const SplitOptions& options) {
  Pending pending;
  for (const Cell& cell : grid.cells) pending.push_back(cell.runs);
  return plan_work(grid, pending, ranks, options);
}

namespace {

std::string format_duration(double seconds) {
  char buf[64];
  if (seconds < 10.0) {
    std::snprintf(buf, sizeof buf, "%.1f s", seconds);
  } else if (seconds < 120.0) {
    std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  } else if (seconds < 7200.0) {
    std::snprintf(buf, sizeof buf, "%.1f min", seconds / 60.0);
  } else {
    std::snprintf(buf, sizeof buf, "%.1f h", seconds / 3600.0);
  }
  return buf;
}

// "1 system", "3 systems".
std::string count(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

std::string core_hours(double seconds) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g core-hours", seconds / 3600.0);
  return buf;
}

}  // namespace

std::string schedule_line(const WorkPlan& plan) {
  const std::size_t groups =
      plan.items.size() - static_cast<std::size_t>(plan.cells - plan.split_cells);
  char efficiency[32];
  std::snprintf(efficiency, sizeof efficiency, "%.1f %%", 100.0 * plan.efficiency());
  std::ostringstream out;
  out << plan.ranks << (plan.ranks == 1 ? " rank: " : " ranks: ")
      << count(plan.items.size(), "item") << " ("
      << count(static_cast<std::size_t>(plan.cells - plan.split_cells), "whole cell");
  if (plan.split_cells > 0)
    out << " + " << groups << " groups of " << count(plan.split_cells, "cell");
  out << "), makespan " << format_duration(plan.makespan_s) << ", " << core_hours(plan.cost_s)
      << ", efficiency " << efficiency;
  return out.str();
}

namespace {

// "study I: 450 runs in 45 cells (3 systems x ...), 150 shared ... — title".
std::string study_lines(const Grid& grid) {
  std::map<std::string, int> cell_index;  // cell_key -> index in grid.cells
  for (int c = 0; c < static_cast<int>(grid.cells.size()); ++c) cell_index[grid.cells[c].key] = c;
  std::ostringstream out;
  for (const StudyTable& study : grid.studies) {
    std::set<int> runs(study.runs.begin(), study.runs.end());
    std::set<int> cells;
    int shared = 0;
    for (int r : runs) {
      cells.insert(cell_index[grid.runs[r].cell_key()]);
      if (grid.run_studies[r].size() > 1) ++shared;
    }
    out << "study " << study.name << ": " << runs.size() << " runs in " << cells.size()
        << " cells (" << count(study.systems.size(), "system") << " x "
        << count(study.rows.size(), "model") << " x " << count(study.columns.size(), "column");
    if (!study.varied_axis.empty()) out << " of " << study.varied_axis;
    out << "), " << shared << " shared with other studies";
    if (!study.title.empty()) out << " — " << study.title;
    out << "\n";
  }
  return out.str();
}

}  // namespace

std::string dry_run_summary(const Grid& grid, const std::vector<int>& ranks,
                            const SplitOptions& options) {
  if (ranks.empty()) throw std::invalid_argument("dry_run_summary: no rank count given");
  std::vector<WorkPlan> plans;
  for (int r : ranks) plans.push_back(plan_work(grid, r, options));  // throws if r < 1
  std::ostringstream out;
  out << grid.runs.size() << " runs in " << grid.cells.size() << " cells\n";
  out << "estimated cost: " << core_hours(grid.estimated_cost_s) << " unsplit ("
      << format_duration(grid.estimated_cost_s)
      << " on one core; cost model fit on one development machine, see "
         "include/phnn/sweep/grid.h)\n";
  if (!grid.cells.empty()) {
    out << "largest cell: " << format_duration(grid.cells.front().estimated_cost_s)
        << ", smallest: " << format_duration(grid.cells.back().estimated_cost_s) << "\n";
  }
  out << "schedule (split " << to_string(options.mode)
      << "; items largest first to the first free rank; efficiency = unsplit cost / (ranks x "
         "makespan)):\n";
  for (const WorkPlan& plan : plans) out << "  " << schedule_line(plan) << "\n";
  out << study_lines(grid);
  return out.str();
}

namespace {

// RunConfig::id() of `runs` (indices into Grid::runs), separated by spaces.
std::string run_ids(const Grid& grid, const std::vector<int>& runs) {
  std::string ids;
  for (int r : runs) {
    if (!ids.empty()) ids += ' ';
    ids += grid.runs[static_cast<std::size_t>(r)].id();
  }
  return ids;
}

}  // namespace

std::string cell_costs_csv(const Grid& grid) {
  std::ostringstream out;
  out.precision(6);
  out << "cell,system,model,size,n_train,regularizer,members,fixed_s,member_s,estimated_s,"
         "run_ids\n";
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const Cell& cell = grid.cells[c];
    const RunConfig& run = grid.runs[static_cast<std::size_t>(cell.runs.front())];
    out << c << "," << run.system_name() << "," << model_label(run.model, run.integrator) << ","
        << to_string(run.size) << "," << run.n_train << "," << to_string(run.regularizer) << ","
        << cell.runs.size() << "," << cell.fixed_cost_s << "," << cell.member_cost_s << ","
        << cell.estimated_cost_s << ",";
    out << run_ids(grid, cell.runs) << "\n";
  }
  return out.str();
}

std::string plan_items_csv(const Grid& grid, const WorkPlan& plan) {
  std::ostringstream out;
  out.precision(6);
  out << "item,cell,runs,estimated_s,run_ids\n";
  for (std::size_t i = 0; i < plan.items.size(); ++i) {
    const WorkItem& item = plan.items[i];
    out << i << "," << item.cell << "," << item.runs.size() << "," << item.estimated_cost_s << ","
        << run_ids(grid, item.runs) << "\n";
  }
  return out.str();
}

}  // namespace phnn
