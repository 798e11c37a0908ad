// src/sweep/search.cpp — successive halving ([search]): the rungs replayed
// from finished results (each group keeps its best ceil(n / eta)
// configurations by the median best validation loss over seeds), and their
// Markdown report. Reads the grid; writes nothing.
#include "phnn/sweep/search.h"

#include "phnn/report/statistics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>


namespace phnn {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A configuration of a group: its cell at each rung (-1: none).
struct Configuration {
  std::string label;
  std::vector<int> cells;
};

struct Group {
  std::string study, system;
  std::vector<Configuration> configurations;
};

// "small/learning_rate=0.001/steps=5000" -> "small/learning_rate=0.001";
// "steps=5000" -> "".
std::string without_budget(const std::string& column) {
  const std::size_t at = column.rfind("steps=");
  if (at == std::string::npos) return column;
  return at == 0 ? "" : column.substr(0, at - 1);
}

// The groups of the grid: per study and system, its configurations in grid
// order, each with its cell per rung.
std::vector<Group> groups_of(const SweepSpec& spec, const Grid& grid) {
  const std::vector<int> cell_of = cell_of_runs(grid);
  const std::vector<int>& rungs = spec.search.rungs;
  std::vector<Group> groups;
  for (const StudyTable& study : grid.studies) {
    for (const std::string& system : study.systems) {
      Group g{study.name, system, {}};
      std::map<std::string, std::size_t> index;  // configuration key -> position
      for (std::size_t i = 0; i < study.runs.size(); ++i) {
        const RunConfig& run = grid.runs[static_cast<std::size_t>(study.runs[i])];
        if (run.system_name() != system) continue;
        const auto rung = std::find(rungs.begin(), rungs.end(), run.training.steps) - rungs.begin();
        if (rung == static_cast<long>(rungs.size())) {
          throw std::invalid_argument("replay_search: a run of " + std::to_string(run.training.steps) +
                                      " steps is at no rung");
        }
        const auto [it, added] = index.emplace(configuration_key(run), g.configurations.size());
        if (added) {
          const std::string column = without_budget(study.run_columns[i]);
          g.configurations.push_back(
              {model_label(run.model, run.integrator) + (column.empty() ? "" : " " + column),
               std::vector<int>(rungs.size(), -1)});
        }
        g.configurations[it->second].cells[static_cast<std::size_t>(rung)] =
            cell_of[static_cast<std::size_t>(study.runs[i])];
      }
      groups.push_back(std::move(g));
    }
  }
  return groups;
}

// The median (quantile_linear, exact with +inf), +inf for no values.
double median_of(const std::vector<double>& v) { return v.empty() ? kInf : quantile_linear(v, 0.5); }

// The entry of `cell` from its finished runs: criterion and MSE medians,
// a diverged run +inf in both, a failed one left out.
SearchEntry entry_of(const Grid& grid, int cell, const std::string& label,
                     const std::vector<RunStatus>& status, const std::vector<double>& criterion,
                     const std::vector<double>& mse) {
  std::vector<double> c, m;
  for (int r : grid.cells[static_cast<std::size_t>(cell)].runs) {
    const auto i = static_cast<std::size_t>(r);
    if (status[i] == RunStatus::kDone) {
      c.push_back(std::isnan(criterion[i]) ? kInf : criterion[i]);
      if (!std::isnan(mse[i])) m.push_back(mse[i]);
    } else if (status[i] == RunStatus::kDiverged) {
      c.push_back(kInf);
      m.push_back(kInf);
    }
  }
  // A rung before the last has no inference (MSE NaN).
  const double mse_median = m.empty() ? std::numeric_limits<double>::quiet_NaN() : median_of(m);
  return SearchEntry{cell, label, median_of(c), mse_median, false};
}

// The cost-model seconds of `cell`'s steps and validations up to `steps`
// (no inference): what going on from that rung's state saves.
double trained_before_s(const Grid& grid, const Cell& cell, int steps) {
  RunConfig run = grid.runs[static_cast<std::size_t>(cell.runs.front())];
  run.training.steps = steps;
  run.training.checkpoints.clear();
  run.data.num_inference = 0;
  return estimate_group_cost_s(run, static_cast<int>(cell.runs.size()));
}

// Rung r of `group` decided: the entries of its configurations that train
// there (alive), best criterion first (ties by grid order), each kept unless
// `last` while among the best ceil(n / eta); *next: which configurations go
// on to rung r + 1.
std::vector<SearchEntry> decide_rung(const SweepSpec& spec, const Grid& grid, const Group& group,
                                     const std::vector<char>& alive, std::size_t r, bool last,
                                     const std::vector<RunStatus>& status,
                                     const std::vector<double>& criterion,
                                     const std::vector<double>& mse, std::vector<char>* next) {
  std::vector<SearchEntry> entries;
  std::vector<std::size_t> which;
  for (std::size_t k = 0; k < alive.size(); ++k) {
    const Configuration& conf = group.configurations[k];
    if (!alive[k] || conf.cells[r] < 0) continue;
    entries.push_back(entry_of(grid, conf.cells[r], conf.label, status, criterion, mse));
    which.push_back(k);
  }
  std::vector<std::size_t> order(entries.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return entries[a].criterion < entries[b].criterion;
  });
  const std::size_t keep = (entries.size() + static_cast<std::size_t>(spec.search.eta) - 1) /
                           static_cast<std::size_t>(spec.search.eta);
  std::vector<SearchEntry> sorted;
  next->assign(alive.size(), 0);
  for (std::size_t i = 0; i < order.size(); ++i) {
    SearchEntry e = entries[order[i]];
    e.kept = !last && i < keep;
    if (e.kept) (*next)[which[order[i]]] = 1;
    sorted.push_back(e);
  }
  return sorted;
}

// Per group, which configurations train at rung `rung` (all at rung 0;
// then those rung - 1 kept, as replay_search decided it).
struct RungConfigurations {
  std::vector<Group> groups;
  std::vector<std::vector<char>> alive;
};
RungConfigurations at_rung(const SweepSpec& spec, const Grid& grid, int rung,
                           const std::vector<RunStatus>& status,
                           const std::vector<double>& criterion, const std::vector<double>& mse) {
  RungConfigurations out;
  out.groups = groups_of(spec, grid);
  const SearchReplay replay =
      rung > 0 ? replay_search(spec, grid, status, criterion, mse, rung) : SearchReplay{};
  for (std::size_t g = 0; g < out.groups.size(); ++g) {
    const auto& configurations = out.groups[g].configurations;
    std::vector<char> alive(configurations.size(), rung == 0 ? 1 : 0);
    const auto before = static_cast<std::size_t>(rung) - 1;
    if (rung > 0 && replay.groups[g].rungs.size() > before) {  // kept at the rung before
      for (const SearchEntry& e : replay.groups[g].rungs[before]) {
        for (std::size_t k = 0; k < alive.size(); ++k) {
          if (e.kept && configurations[k].cells[before] == e.cell) alive[k] = 1;
        }
      }
    }
    out.alive.push_back(std::move(alive));
  }
  return out;
}

}  // namespace

std::string configuration_key(const RunConfig& run) {
  RunConfig c = run;
  c.training.steps = 0;
  c.training.skip_inference = false;
  return c.cell_key();
}

SearchReplay replay_search(const SweepSpec& spec, const Grid& grid,
                           const std::vector<RunStatus>& status,
                           const std::vector<double>& criterion, const std::vector<double>& mse,
                           int last_round) {
  if (!spec.search.enabled || status.size() != grid.runs.size() ||
      criterion.size() != grid.runs.size() || mse.size() != grid.runs.size()) {
    throw std::invalid_argument("replay_search: needs [search] and one status, criterion and MSE per run");
  }
  const std::vector<Group> groups = groups_of(spec, grid);
  const std::size_t R = spec.search.rungs.size();
  SearchReplay out;
  AdaptiveState& state = out.state;
  state.active.assign(grid.runs.size(), 0);
  // alive[g][k]: configuration k of group g trains at the current rung.
  std::vector<std::vector<char>> alive;
  for (const Group& g : groups) {
    alive.emplace_back(g.configurations.size(), 1);
    out.groups.push_back({g.study, g.system, {}});
  }
  for (std::size_t r = 0; r < R; ++r) {
    state.round = static_cast<int>(r);
    state.pending = state.failed = 0;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      for (std::size_t k = 0; k < alive[g].size(); ++k) {
        const int cell = groups[g].configurations[k].cells[r];
        if (!alive[g][k] || cell < 0) continue;
        for (int run : grid.cells[static_cast<std::size_t>(cell)].runs) {
          state.active[static_cast<std::size_t>(run)] = 1;
        }
      }
    }
    for (std::size_t i = 0; i < grid.runs.size(); ++i) {
      if (!state.active[i] || grid.runs[i].training.steps != spec.search.rungs[r]) continue;
      state.pending += status[i] == RunStatus::kPending ? 1 : 0;
      state.failed += status[i] == RunStatus::kFailed ? 1 : 0;
    }
    if (state.pending > 0) return out;
    const bool last = r + 1 == R || static_cast<int>(r) == last_round;
    int kept_total = 0;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      std::vector<char> next;
      out.groups[g].rungs.push_back(
          decide_rung(spec, grid, groups[g], alive[g], r, last, status, criterion, mse, &next));
      kept_total += static_cast<int>(std::count(next.begin(), next.end(), 1));
      alive[g] = std::move(next);
    }
    if (last) {
      state.complete = r + 1 == R;
      return out;
    }
    state.cells_grown.push_back(kept_total);
  }
  return out;
}

std::vector<std::vector<int>> search_runs_ahead(const SweepSpec& spec, const Grid& grid, int rung,
                                                const std::vector<RunStatus>& status,
                                                const std::vector<double>& criterion,
                                                const std::vector<double>& mse) {
  const auto next = static_cast<std::size_t>(rung + 1);
  if (rung < 0 || next >= spec.search.rungs.size()) return {};
  const RungConfigurations now = at_rung(spec, grid, rung, status, criterion, mse);
  std::vector<std::vector<int>> ahead(grid.cells.size());
  bool any = false;
  for (std::size_t g = 0; g < now.groups.size(); ++g) {
    for (std::size_t k = 0; k < now.alive[g].size(); ++k) {
      const int cell = now.groups[g].configurations[k].cells[next];
      if (!now.alive[g][k] || cell < 0) continue;
      for (int r : grid.cells[static_cast<std::size_t>(cell)].runs) {
        if (status[static_cast<std::size_t>(r)] != RunStatus::kPending) continue;
        ahead[static_cast<std::size_t>(cell)].push_back(r);
        any = true;
      }
    }
  }
  return any ? ahead : std::vector<std::vector<int>>();
}

std::vector<int> search_cells_known_early(const SweepSpec& spec, const Grid& grid, int rung_index,
                                          const std::vector<RunStatus>& status,
                                          const std::vector<double>& criterion,
                                          const std::vector<double>& mse,
                                          std::vector<char>* decided) {
  const auto rung = static_cast<std::size_t>(rung_index);
  if (rung_index < 0 || rung + 1 >= spec.search.rungs.size()) return {};
  const RungConfigurations now = at_rung(spec, grid, rung_index, status, criterion, mse);
  decided->resize(now.groups.size(), 0);
  std::vector<int> out;
  for (std::size_t g = 0; g < now.groups.size(); ++g) {
    const Group& group = now.groups[g];
    bool pending = false;
    for (std::size_t k = 0; k < now.alive[g].size(); ++k) {
      const int cell = group.configurations[k].cells[rung];
      if (!now.alive[g][k] || cell < 0) continue;
      for (int r : grid.cells[static_cast<std::size_t>(cell)].runs) {
        pending = pending || status[static_cast<std::size_t>(r)] == RunStatus::kPending;
      }
    }
    if ((*decided)[g] || pending) continue;
    (*decided)[g] = 1;
    std::vector<char> next;
    decide_rung(spec, grid, group, now.alive[g], rung, false, status, criterion, mse, &next);
    for (std::size_t k = 0; k < next.size(); ++k) {
      const int cell = group.configurations[k].cells[rung + 1];
      if (next[k] && cell >= 0) out.push_back(cell);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

SearchCost estimate_search_cost(const SweepSpec& spec, const Grid& grid) {
  const std::vector<int>& rungs = spec.search.rungs;
  SearchCost cost;
  cost.configurations.assign(rungs.size(), 0);
  cost.items_s.assign(rungs.size(), {});
  for (const Group& g : groups_of(spec, grid)) {
    std::size_t n = g.configurations.size();
    for (std::size_t r = 0; r < rungs.size(); ++r) {
      double sum = 0.0, going_on = 0.0;
      int cells = 0;
      for (const Configuration& c : g.configurations) {
        if (c.cells[r] < 0) continue;
        const Cell& cell = grid.cells[static_cast<std::size_t>(c.cells[r])];
        sum += cell.estimated_cost_s;
        going_on += cell.estimated_cost_s - (r == 0 ? 0.0 : trained_before_s(grid, cell, rungs[r - 1]));
        ++cells;
      }
      cost.configurations[r] += static_cast<int>(n);
      if (cells > 0) cost.halving_s += static_cast<double>(n) * going_on / cells;
      if (cells > 0) cost.items_s[r].insert(cost.items_s[r].end(), n, going_on / cells);
      if (r + 1 == rungs.size()) cost.full_s += sum;
      n = (n + static_cast<std::size_t>(spec.search.eta) - 1) / static_cast<std::size_t>(spec.search.eta);
    }
  }
  return cost;
}

std::string search_report(const SweepSpec& spec, const SearchReplay& replay) {
  std::ostringstream out;
  const auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3e", v);
    return std::isnan(v) ? std::string("—") : std::isinf(v) ? std::string("inf") : std::string(text);
  };
  for (const SearchGroup& g : replay.groups) {
    out << "### Search " << g.study << " — " << g.system << "\n\n";
    for (std::size_t r = 0; r < g.rungs.size(); ++r) {
      const bool last = r + 1 == spec.search.rungs.size();
      out << "Rung " << r << " (" << spec.search.rungs[r] << " steps): " << g.rungs[r].size()
          << " configuration" << (g.rungs[r].size() == 1 ? "" : "s")
          << (last ? "" : ", the best 1/" + std::to_string(spec.search.eta) + " go on") << "\n\n"
          << "| configuration | best validation loss | MSE | |\n|---|---|---|---|\n";
      for (const SearchEntry& e : g.rungs[r]) {
        out << "| " << e.label << " | " << number(e.criterion) << " | " << number(e.mse) << " | "
            << (e.kept ? "on" : "") << " |\n";
      }
      out << "\n";
    }
    if (replay.state.complete && !g.rungs.empty() && !g.rungs.back().empty()) {
      const SearchEntry& best = g.rungs.back().front();
      out << "Best: **" << best.label << "** (best validation loss " << number(best.criterion)
          << ", inference MSE " << number(best.mse) << ", medians over seeds)\n\n";
    }
  }
  return out.str();
}

}  // namespace phnn
