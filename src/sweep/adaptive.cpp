// src/sweep/adaptive.cpp — adaptive seeds: the rounds replayed from finished
// results, and the two rules that name the cells of the next round
// (column-best: the reducer's (tie) cells; comparisons: comparison_rule.h),
// also while a round drains (cells_named_early), and the runs idle ranks
// may train ahead. Reads the report's statistics (phnn/report/tables.h) and
// the grid's cost model; writes nothing.
#include "phnn/sweep/adaptive.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include "phnn/report/tables.h"
#include "sweep/comparison_rule.h"

namespace phnn {
namespace {

using adaptive_detail::cells_by_key;
using adaptive_detail::ComparisonRule;
using adaptive_detail::selector_cells;

std::vector<int> column_best_cells(const Grid& grid, const std::vector<char>& active,
                                   const std::vector<RunStatus>& status,
                                   const std::vector<double>& mse,
                                   const BootstrapOptions& bootstrap) {
  const auto entries = make_table_entries(grid, status, mse, &active);
  std::map<std::tuple<std::string, std::string, std::string, std::string>, int> cell_by_name;
  const std::vector<int> cell_of = cell_of_runs(grid);
  for (const StudyTable& study : grid.studies) {
    for (std::size_t i = 0; i < study.runs.size(); ++i) {
      const RunConfig& run = grid.runs[static_cast<std::size_t>(study.runs[i])];
      cell_by_name[{study.name, run.system_name(), model_label(run.model, run.integrator),
                    study.run_columns[i]}] = cell_of[static_cast<std::size_t>(study.runs[i])];
    }
  }
  std::vector<int> cells;
  for (const TableCellName& t : undecided_cells(grid.studies, entries, 0, bootstrap)) {
    cells.push_back(cell_by_name.at({t.study, t.system, t.row, t.column}));
  }
  return cells;
}

void mark_active(const Grid& grid, AdaptiveState* state) {
  state->active.assign(grid.runs.size(), 0);
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const auto& runs = grid.cells[c].runs;
    const auto n = std::min<std::size_t>(runs.size(), static_cast<std::size_t>(state->cell_seeds[c]));
    for (std::size_t k = 0; k < n; ++k) state->active[static_cast<std::size_t>(runs[k])] = 1;
  }
}

// Counts the runs asked for that are pending or failed, and the finished
// runs not asked for.
void count_runs(const std::vector<RunStatus>& status, AdaptiveState* state) {
  state->pending = state->failed = state->trained_ahead = 0;
  for (std::size_t i = 0; i < status.size(); ++i) {
    if (!state->active[i]) {
      state->trained_ahead += status[i] == RunStatus::kPending ? 0 : 1;
      continue;
    }
    state->pending += status[i] == RunStatus::kPending ? 1 : 0;
    state->failed += status[i] == RunStatus::kFailed ? 1 : 0;
  }
}

// The stop test's intervals: at stop_confidence when set.
BootstrapOptions stop_options(const SweepSpec& spec, const BootstrapOptions& bootstrap) {
  BootstrapOptions stop = bootstrap;
  if (spec.adaptive.stop_confidence > 0) stop.confidence = spec.adaptive.stop_confidence;
  return stop;
}

// Seeds asked for of each cell (its active runs).
std::vector<int> asked_seeds(const Grid& grid, const std::vector<char>& active) {
  std::vector<int> n(grid.cells.size(), 0);
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    for (int r : grid.cells[c].runs) n[c] += active[static_cast<std::size_t>(r)] ? 1 : 0;
  }
  return n;
}

}  // namespace

int AdaptiveState::active_runs() const {
  return static_cast<int>(std::count(active.begin(), active.end(), 1));
}

std::vector<int> adaptive_rule_cells(const SweepSpec& spec, const Grid& grid,
                                     const std::vector<char>& active,
                                     const std::vector<RunStatus>& status,
                                     const std::vector<double>& mse,
                                     const BootstrapOptions& bootstrap) {
  const BootstrapOptions stop = stop_options(spec, bootstrap);
  std::vector<int> cells;
  if (spec.adaptive.rule == AdaptiveRule::kColumnBest) {
    cells = column_best_cells(grid, active, status, mse, stop);
  } else {
    ComparisonRule rule(spec.adaptive, grid, active, status, mse, bootstrap, stop);
    for (const SeedComparison& c : spec.adaptive.comparisons) rule.name_cells(c, &cells);
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  return cells;
}

AdaptiveState replay_adaptive_rounds(const SweepSpec& spec, const Grid& grid,
                                     const std::vector<RunStatus>& status,
                                     const std::vector<double>& mse,
                                     const BootstrapOptions& bootstrap, int last_round) {
  if (!spec.adaptive.enabled) {
    throw std::invalid_argument("replay_adaptive_rounds: the sweep has no [adaptive] table");
  }
  if (status.size() != grid.runs.size() || mse.size() != grid.runs.size()) {
    throw std::invalid_argument("replay_adaptive_rounds: got " + std::to_string(status.size()) +
                                " statuses and " + std::to_string(mse.size()) +
                                " MSEs for a grid of " + std::to_string(grid.runs.size()) + " runs");
  }
  const AdaptiveSpec& a = spec.adaptive;
  AdaptiveState state;
  state.cell_seeds.assign(grid.cells.size(), static_cast<int>(a.initial_seeds.size()));
  for (;;) {
    mark_active(grid, &state);
    count_runs(status, &state);
    if (state.pending > 0) return state;  // round in progress
    std::vector<int> grow;
    for (int c : adaptive_rule_cells(spec, grid, state.active, status, mse, bootstrap)) {
      if (state.cell_seeds[static_cast<std::size_t>(c)] < a.max_seeds) grow.push_back(c);
    }
    if (grow.empty()) {
      state.complete = true;
      return state;
    }
    if (last_round >= 0 && state.round >= last_round) return state;
    for (int c : grow) {
      int& seeds = state.cell_seeds[static_cast<std::size_t>(c)];
      seeds = std::min(a.max_seeds, seeds + a.batch);
    }
    state.cells_grown.push_back(static_cast<int>(grow.size()));
    ++state.round;
  }
}

std::vector<std::vector<int>> comparison_named_cells(const SweepSpec& spec, const Grid& grid,
                                                     const std::vector<char>& active,
                                                     const std::vector<RunStatus>& status,
                                                     const std::vector<double>& mse,
                                                     const std::vector<char>& read,
                                                     const BootstrapOptions& bootstrap) {
  const auto& comparisons = spec.adaptive.comparisons;
  std::vector<std::vector<int>> named(comparisons.size());
  if (spec.adaptive.rule != AdaptiveRule::kComparisons) return named;
  const BootstrapOptions stop = stop_options(spec, bootstrap);  // the rule keeps a reference
  ComparisonRule rule(spec.adaptive, grid, active, status, mse, bootstrap, stop);
  const std::vector<int> seeds = asked_seeds(grid, active);
  for (std::size_t j = 0; j < comparisons.size(); ++j) {
    if (!read.empty() && !read[j]) continue;
    std::vector<int> cells;
    rule.name_cells(comparisons[j], &cells);
    for (int c : cells) {
      if (seeds[static_cast<std::size_t>(c)] < spec.adaptive.max_seeds) named[j].push_back(c);
    }
  }
  return named;
}

std::vector<int> cells_named_early(const SweepSpec& spec, const Grid& grid,
                                   const std::vector<char>& active,
                                   const std::vector<RunStatus>& status,
                                   const std::vector<double>& mse, std::vector<char>* decided,
                                   const BootstrapOptions& bootstrap) {
  const auto& comparisons = spec.adaptive.comparisons;
  if (spec.adaptive.rule != AdaptiveRule::kComparisons) return {};
  decided->resize(comparisons.size(), 0);
  const std::map<std::string, int> cell_by_key = cells_by_key(grid);
  const auto pending = [&](int cell) {
    const auto& runs = grid.cells[static_cast<std::size_t>(cell)].runs;
    return std::any_of(runs.begin(), runs.end(), [&](int r) {
      const auto i = static_cast<std::size_t>(r);
      return active[i] && status[i] == RunStatus::kPending;
    });
  };
  std::vector<char> now(comparisons.size(), 0);  // complete since the last call
  for (std::size_t j = 0; j < comparisons.size(); ++j) {
    const std::vector<int> cells = selector_cells(cell_by_key, comparisons[j]);
    now[j] = !(*decided)[j] && std::none_of(cells.begin(), cells.end(), pending);
    if (now[j]) (*decided)[j] = 1;
  }
  if (std::none_of(now.begin(), now.end(), [](char c) { return c != 0; })) return {};
  std::vector<int> out;
  for (const auto& cells :
       comparison_named_cells(spec, grid, active, status, mse, now, bootstrap)) {
    out.insert(out.end(), cells.begin(), cells.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<std::vector<int>> runs_to_speculate(const SweepSpec& spec, const Grid& grid,
                                                const AdaptiveState& state,
                                                const std::vector<RunStatus>& status) {
  if (!spec.adaptive.enabled || state.complete) return {};
  // The candidates: comparisons, every cell a comparison selects from (which
  // of them the next round grows is known as the round drains:
  // cells_named_early); column-best, the cells the round in progress grows.
  const bool comparisons = spec.adaptive.rule == AdaptiveRule::kComparisons;
  std::vector<char> candidate(grid.cells.size(), 0);
  if (comparisons) {
    const std::map<std::string, int> cell_by_key = cells_by_key(grid);
    for (const SeedComparison& c : spec.adaptive.comparisons) {
      for (int cell : selector_cells(cell_by_key, c)) candidate[static_cast<std::size_t>(cell)] = 1;
    }
  }
  std::vector<std::vector<int>> ahead(grid.cells.size());
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const auto& runs = grid.cells[c].runs;
    const auto asked = std::min<std::size_t>(runs.size(), static_cast<std::size_t>(state.cell_seeds[c]));
    const bool growing = std::any_of(
        runs.begin(), runs.begin() + static_cast<long>(asked),
        [&](int r) { return status[static_cast<std::size_t>(r)] == RunStatus::kPending; });
    if (comparisons ? !candidate[c] : !growing) continue;
    const std::size_t next = std::min<std::size_t>(
        {runs.size(), asked + static_cast<std::size_t>(spec.adaptive.batch),
         static_cast<std::size_t>(spec.adaptive.max_seeds)});
    for (std::size_t k = asked; k < next; ++k) {
      if (status[static_cast<std::size_t>(runs[k])] == RunStatus::kPending) ahead[c].push_back(runs[k]);
    }
  }
  const bool none = std::all_of(ahead.begin(), ahead.end(), [](const auto& r) { return r.empty(); });
  return none ? std::vector<std::vector<int>>() : ahead;
}

SweepSpec round_zero_spec(const SweepSpec& spec) {
  SweepSpec zero = spec;
  if (!spec.adaptive.enabled) return zero;
  for (StudySpec& s : zero.studies) s.seeds = spec.adaptive.initial_seeds;
  zero.adaptive = AdaptiveSpec();
  return zero;
}

}  // namespace phnn
