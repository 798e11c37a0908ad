// src/sweep/adaptive.cpp — adaptive seeds: the rounds replayed from finished
// results, and the two rules that name the cells of the next round
// (column-best: the reducer's (tie) cells; comparisons: both sides of every
// comparison whose intervals overlap — or, with reading = "four-way", that
// compare_cells leaves undecided — or with grow = "one" the side that
// closes the gap more cheaply). Reads the report's statistics
// (phnn/report/tables.h) and the grid's cost model; writes nothing.
#include "phnn/sweep/adaptive.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include "phnn/report/comparison.h"
#include "phnn/report/tables.h"

namespace phnn {
namespace {

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

// "system|model|n_train|size|regularizer" of a run or of one model of a selector.
std::string selector_key(const std::string& system, ModelKind model, IntegratorKind integrator,
                         int n_train, ModelSize size, Regularizer regularizer) {
  return system + "|" + model_key(model, integrator) + "|" + std::to_string(n_train) + "|" +
         to_string(size) + "|" + to_string(regularizer);
}

class ComparisonRule {
 public:
  ComparisonRule(const AdaptiveSpec& adaptive, const Grid& grid, const std::vector<char>& active,
                 const std::vector<RunStatus>& status, const std::vector<double>& mse,
                 const BootstrapOptions& bootstrap, const BootstrapOptions& stop)
      : adaptive_(adaptive), grid_(grid), active_(active), status_(status), mse_(mse),
        bootstrap_(bootstrap), stop_(stop) {
    for (std::size_t c = 0; c < grid.cells.size(); ++c) {
      const RunConfig& run = grid.runs[static_cast<std::size_t>(grid.cells[c].runs.front())];
      cell_by_key_[selector_key(run.system_name(), run.model, run.integrator, run.n_train,
                                run.size, run.regularizer)] = static_cast<int>(c);
    }
  }

  // Named cells of one comparison (none, one or both sides' picks): resolved
  // at the stop confidence, or futile at the tables' confidence, stops it;
  // grow = "one" names one side when both have intervals and unequal medians.
  void name_cells(const SeedComparison& c, std::vector<int>* cells) {
    const int a = pick(c.a), b = pick(c.b);
    if (a < 0 || b < 0) return;
    if (adaptive_.four_way) return name_four_way(a, b, cells);
    if (resolved(summary(a, stop_, &stop_summaries_), summary(b, stop_, &stop_summaries_))) return;
    const CellSummary& sa = summary(a);
    const CellSummary& sb = summary(b);
    if (adaptive_.futility && sa.has_interval() && sb.has_interval() && futile(sa, sb)) {
      return;  // max_seeds is not expected to resolve it
    }
    if (adaptive_.grow_one && sa.has_interval() && sb.has_interval() && sa.median != sb.median) {
      const double ga = gain_per_second(a, sa, sb), gb = gain_per_second(b, sb, sa);
      if (ga > gb) return cells->push_back(a);
      if (gb > ga) return cells->push_back(b);
    }
    cells->push_back(a);
    cells->push_back(b);
  }

 private:
  // reading = "four-way": compare_cells on the two cells' finished seeds
  // (paired when cells_are_paired), at the stop confidence; anything but
  // undecided stops the comparison. An undecided one names both cells, or
  // with grow = "one" and unpaired cells the side that closes more of the
  // gap per core-second (as the intervals reading does).
  void name_four_way(int a, int b, std::vector<int>* cells) {
    const RunConfig& ra = grid_.runs[static_cast<std::size_t>(grid_.cells[static_cast<std::size_t>(a)].runs.front())];
    const RunConfig& rb = grid_.runs[static_cast<std::size_t>(grid_.cells[static_cast<std::size_t>(b)].runs.front())];
    const bool paired = cells_are_paired(ra, rb);
    ComparisonOptions options;
    options.delta = adaptive_.delta;
    options.confidence = stop_.confidence;
    const SeedResults sa = seed_results(a), sb = seed_results(b);
    if (!sa.empty() && !sb.empty()) {
      const Comparison c = compare_cells(sa, sb, paired, options);
      if (c.reading != ComparisonReading::kUndecided) return;
      if (adaptive_.futility && four_way_futile(c, options.delta)) return;
    }
    const CellSummary& ca = summary(a);
    const CellSummary& cb = summary(b);
    if (!paired && adaptive_.grow_one && ca.has_interval() && cb.has_interval() &&
        ca.median != cb.median) {
      const double ga = gain_per_second(a, ca, cb), gb = gain_per_second(b, cb, ca);
      if (ga > gb) return cells->push_back(a);
      if (gb > ga) return cells->push_back(b);
    }
    cells->push_back(a);
    cells->push_back(b);
  }

  // With futility, an undecided four-way comparison stops when max_seeds is
  // not expected to read it: its effect interval narrowed about the effect
  // (narrowed(), n its pairs, or its smaller side) would still neither lie
  // inside (-log10 delta, log10 delta) nor exclude 0 (docs/METHOD.md,
  // "Adaptive seeds"). An interval with an infinite end (diverged seeds) or
  // one below min_seeds is never futile.
  bool four_way_futile(const Comparison& c, double delta) const {
    const int n = c.paired ? c.n_pairs : std::min(c.n_a, c.n_b);
    const Interval& i = c.effect_interval;
    if (n < kMinSeedsForInterval || !std::isfinite(i.low) || !std::isfinite(i.high) ||
        !std::isfinite(c.effect)) {
      return false;
    }
    const Interval p = narrowed(i, c.effect, n);
    const double margin = std::log10(delta);
    const bool equivalent = -margin < p.low && p.high < margin;
    const bool decided = p.high < 0.0 || p.low > 0.0;
    return !equivalent && !decided;
  }

  // Seed -> MSE of the cell's finished runs among those asked for (a
  // diverged run's MSE is +inf).
  SeedResults seed_results(int cell) const {
    SeedResults out;
    for (int r : grid_.cells[static_cast<std::size_t>(cell)].runs) {
      const auto i = static_cast<std::size_t>(r);
      if (!active_[i]) continue;
      if (status_[i] == RunStatus::kDone) out[grid_.runs[i].seed] = mse_[i];
      if (status_[i] == RunStatus::kDiverged) out[grid_.runs[i].seed] = std::numeric_limits<double>::infinity();
    }
    return out;
  }

  // The smallest-median cell of a selector with a finished run, or -1.
  int pick(const CellSelector& s) {
    int best = -1;
    for (const auto& [model, integrator] : s.models) {
      const auto it = cell_by_key_.find(
          selector_key(s.system, model, integrator, s.n_train, s.size, s.regularizer));
      if (it == cell_by_key_.end()) continue;  // the parser checked; a shard may lack it
      const CellSummary& cs = summary(it->second);
      if (cs.finished() == 0) continue;
      if (best < 0 || cs.median < summary(best).median) best = it->second;
    }
    return best;
  }

  // A tie more seeds are not expected to break: one median lies inside the
  // other's interval projected to max_seeds (the medians would have to move
  // apart by more than a projected half-width). A mere overlap of the two
  // projections is not enough: such a pair sits at the margin, where a few
  // more seeds often resolve it.
  bool futile(const CellSummary& a, const CellSummary& b) const {
    const auto inside = [](double m, const Interval& i) { return i.low <= m && m <= i.high; };
    return inside(a.median, projected(b)) || inside(b.median, projected(a));
  }

  // The interval at max_seeds if the median stays and both distances to
  // it shrink as 1 / sqrt(seeds).
  Interval projected(const CellSummary& s) const {
    return narrowed(s.median_interval, s.median, s.finished());
  }

  // The interval `i` about `center` of a statistic of n seeds as it would
  // be at max_seeds if the center stays and both distances to it shrink as
  // 1 / sqrt(seeds): [c - (c - lo) r, c + (hi - c) r] with r = sqrt(n /
  // max_seeds) (1 once at the cap). Infinite ends stay.
  Interval narrowed(const Interval& i, double center, int n) const {
    const double r = std::sqrt(std::min(1.0, static_cast<double>(n) /
                                                 static_cast<double>(adaptive_.max_seeds)));
    const auto toward = [&](double end) {
      return std::isfinite(end) && std::isfinite(center) ? center + (end - center) * r : end;
    };
    return Interval{toward(i.low), toward(i.high)};
  }

  // grow = "one": the two intervals separate when the half-widths that face
  // each other, (hi - m) of the smaller median's cell and (m - lo) of the
  // other's, sum to less than the distance of the medians. k = min(batch,
  // max_seeds - n) more seeds shrink a cell's facing half-width w by the
  // factor sqrt(n / (n + k)) (n its seeds asked for; the futility
  // projection's 1 / sqrt(n) law), so they close
  //   gain = w (1 - sqrt(n / (n + k)))   of the gap, at a cost of
  //   k * member_cost_s                  (the cost model's per-seed seconds,
  // not a timing: the decision is a function of the results, the sweep and
  // the binary's cost model, pinned by a test; the per-round fixed cost is
  // left out). Returns gain per core-second; 0 for a cell at max_seeds, +inf
  // for an infinite w (diverged seeds). Equal gains name both cells.
  double gain_per_second(int cell, const CellSummary& s, const CellSummary& other) const {
    const auto& runs = grid_.cells[static_cast<std::size_t>(cell)].runs;
    int n = 0;
    for (int r : runs) n += active_[static_cast<std::size_t>(r)] ? 1 : 0;
    if (n >= adaptive_.max_seeds) return 0.0;
    const double w = s.median < other.median ? s.median_interval.high - s.median
                                             : s.median - s.median_interval.low;
    if (!(w < std::numeric_limits<double>::infinity())) return w == w ? w : 0.0;
    const int k = std::min(adaptive_.batch, adaptive_.max_seeds - n);
    const double shrink = 1.0 - std::sqrt(static_cast<double>(n) / static_cast<double>(n + k));
    const double cost = k * grid_.cells[static_cast<std::size_t>(cell)].member_cost_s;
    return w * shrink / cost;
  }

  // The medians differ and their intervals are disjoint.
  static bool resolved(const CellSummary& sa, const CellSummary& sb) {
    if (!sa.has_interval() || !sb.has_interval() || sa.median == sb.median) return false;
    return sa.median < sb.median ? sa.median_interval.high < sb.median_interval.low
                                 : sa.median_interval.low > sb.median_interval.high;
  }

  const CellSummary& summary(int cell) { return summary(cell, bootstrap_, &summaries_); }

  // The cell's statistics with `options`, cached in `cache`.
  const CellSummary& summary(int cell, const BootstrapOptions& options,
                             std::map<int, CellSummary>* cache) {
    const auto it = cache->find(cell);
    if (it != cache->end()) return it->second;
    std::vector<TableEntry> entries;
    for (int r : grid_.cells[static_cast<std::size_t>(cell)].runs) {
      const auto i = static_cast<std::size_t>(r);
      if (!active_[i]) continue;
      TableEntry e;
      e.status = status_[i];
      e.mse = mse_[i];
      entries.push_back(e);
    }
    return cache->emplace(cell, summarize_cell(entries, 0, options)).first->second;
  }

  const AdaptiveSpec& adaptive_;
  const Grid& grid_;
  const std::vector<char>& active_;
  const std::vector<RunStatus>& status_;
  const std::vector<double>& mse_;
  const BootstrapOptions& bootstrap_;
  const BootstrapOptions& stop_;
  std::map<std::string, int> cell_by_key_;
  std::map<int, CellSummary> summaries_, stop_summaries_;
};

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

}  // namespace

int AdaptiveState::active_runs() const {
  return static_cast<int>(std::count(active.begin(), active.end(), 1));
}

std::vector<int> adaptive_rule_cells(const SweepSpec& spec, const Grid& grid,
                                     const std::vector<char>& active,
                                     const std::vector<RunStatus>& status,
                                     const std::vector<double>& mse,
                                     const BootstrapOptions& bootstrap) {
  // The stop test's intervals: at stop_confidence when set.
  BootstrapOptions stop = bootstrap;
  if (spec.adaptive.stop_confidence > 0) stop.confidence = spec.adaptive.stop_confidence;
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

std::vector<std::vector<int>> runs_to_speculate(const SweepSpec& spec, const Grid& grid,
                                                const AdaptiveState& state,
                                                const std::vector<RunStatus>& status) {
  std::vector<std::vector<int>> ahead(grid.cells.size());
  if (!spec.adaptive.enabled || state.complete) return {};
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const auto& runs = grid.cells[c].runs;
    const auto asked = std::min<std::size_t>(runs.size(), static_cast<std::size_t>(state.cell_seeds[c]));
    const bool growing = std::any_of(runs.begin(), runs.begin() + static_cast<long>(asked), [&](int r) {
      return status[static_cast<std::size_t>(r)] == RunStatus::kPending;
    });
    if (!growing) continue;
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
