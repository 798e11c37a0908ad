// src/sweep/comparison_rule.h — the comparisons rule of adaptive seeds
// (private to src/sweep; used by adaptive.cpp): which cells one comparison
// of an [adaptive] table names for the next round, from the finished runs
// of the cells its two sides select from — its intervals or four-way
// reading, futility and grow = "one"'s gains (docs/METHOD.md, "Adaptive
// seeds"). Reads the report's statistics and the grid's cost model.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "phnn/report/comparison.h"
#include "phnn/report/tables.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace adaptive_detail {

// "system|model|n_train|size|regularizer" of a run or of one model of a selector.
inline std::string selector_key(const std::string& system, ModelKind model,
                                IntegratorKind integrator, int n_train, ModelSize size,
                                Regularizer regularizer) {
  return system + "|" + model_key(model, integrator) + "|" + std::to_string(n_train) + "|" +
         to_string(size) + "|" + to_string(regularizer);
}

// Grid cell by selector_key.
inline std::map<std::string, int> cells_by_key(const Grid& grid) {
  std::map<std::string, int> out;
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const RunConfig& run = grid.runs[static_cast<std::size_t>(grid.cells[c].runs.front())];
    out[selector_key(run.system_name(), run.model, run.integrator, run.n_train, run.size,
                     run.regularizer)] = static_cast<int>(c);
  }
  return out;
}

// The grid cells a comparison's sides select from (each side's models; a
// shard's grid may lack some).
inline std::vector<int> selector_cells(const std::map<std::string, int>& cell_by_key,
                                       const SeedComparison& c) {
  std::vector<int> out;
  for (const CellSelector* s : {&c.a, &c.b}) {
    for (const auto& [model, integrator] : s->models) {
      const auto it = cell_by_key.find(
          selector_key(s->system, model, integrator, s->n_train, s->size, s->regularizer));
      if (it != cell_by_key.end()) out.push_back(it->second);
    }
  }
  return out;
}

class ComparisonRule {
 public:
  ComparisonRule(const AdaptiveSpec& adaptive, const Grid& grid, const std::vector<char>& active,
                 const std::vector<RunStatus>& status, const std::vector<double>& mse,
                 const BootstrapOptions& bootstrap, const BootstrapOptions& stop)
      : adaptive_(adaptive),
        grid_(grid),
        active_(active),
        status_(status),
        mse_(mse),
        bootstrap_(bootstrap),
        stop_(stop),
        cell_by_key_(cells_by_key(grid)) {}

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
    const RunConfig& ra =
        grid_.runs[static_cast<std::size_t>(grid_.cells[static_cast<std::size_t>(a)].runs.front())];
    const RunConfig& rb =
        grid_.runs[static_cast<std::size_t>(grid_.cells[static_cast<std::size_t>(b)].runs.front())];
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
      if (status_[i] == RunStatus::kDiverged)
        out[grid_.runs[i].seed] = std::numeric_limits<double>::infinity();
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
    const double r =
        std::sqrt(std::min(1.0, static_cast<double>(n) / static_cast<double>(adaptive_.max_seeds)));
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

}  // namespace adaptive_detail
}  // namespace phnn
