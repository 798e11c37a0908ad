// src/apps/sweep_search.cpp — see apps/sweep_search.h. Touches the rung
// state files under `<results>.journal/` only (through ItemCheckpoints).
#include "apps/sweep_search.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "phnn/common/counted.h"
#include "phnn/store/cell_checkpoint.h"
#include "phnn/sweep/search.h"

namespace phnn {
namespace apps {

namespace {

// The key of the rung state of `runs` at `steps`: the build, each run's
// configuration and seed, and the budget.
std::string rung_key(const Grid& grid, const std::vector<int>& runs, int steps,
                     const std::string& build_key) {
  std::string key = build_key + "\nrung";
  for (int row : runs) {
    const RunConfig& run = grid.runs[static_cast<std::size_t>(row)];
    key += " " + hex64(fnv1a64(configuration_key(run))) + ":" + std::to_string(run.seed);
  }
  return key + "\nsteps=" + std::to_string(steps);
}

std::string hours(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", seconds / 3600.0);
  return text;
}

}  // namespace

void link_rung_states(const SweepSpec& spec, const Grid& grid, const std::vector<int>& runs,
                      const std::string& out, const std::string& build_key,
                      ItemCheckpoints* checkpoints) {
  if (!spec.search.enabled || runs.empty()) return;
  const std::vector<int>& rungs = spec.search.rungs;
  const int steps = grid.runs[static_cast<std::size_t>(runs.front())].training.steps;
  const auto at = static_cast<std::size_t>(std::find(rungs.begin(), rungs.end(), steps) - rungs.begin());
  if (at >= rungs.size()) return;
  if (at > 0) {
    const std::string key = rung_key(grid, runs, rungs[at - 1], build_key);
    checkpoints->go_on_from(rung_state_path(out, key), key);
  }
  if (at + 1 < rungs.size()) {
    const std::string key = rung_key(grid, runs, steps, build_key);
    checkpoints->keep_final(rung_state_path(out, key), key);
  }
}

std::string search_round_line(const SweepSpec& spec, const AdaptiveState& state) {
  if (!spec.search.enabled || state.complete) return "";
  const int r = state.round;
  std::ostringstream line;
  line << "phnn sweep: search rung " << r << " (" << spec.search.rungs[static_cast<std::size_t>(r)]
       << " steps): " << state.active_runs() << " runs asked for so far (";
  if (r == 0) {
    line << "every configuration";
  } else {
    line << counted(state.cells_grown.back(), "configuration") << " went on after rung " << r - 1
         << ", the best 1/" << spec.search.eta << " of each study and system";
  }
  line << ")";
  return line.str();
}

std::string search_complete_line(const SweepSpec& spec, const Grid& grid,
                                 const AdaptiveState& state) {
  if (!spec.search.enabled || !state.complete) return "";
  return "search complete after rung " + std::to_string(state.round) + ": " +
         std::to_string(state.active_runs()) + " runs of at most " +
         std::to_string(grid.runs.size()) + "; phnn reduce shows the rungs and the best";
}

std::string search_dry_run(const SweepSpec& spec, const Grid& grid, const std::vector<int>& ranks,
                           const SplitOptions& split) {
  SweepSpec first = spec;
  first.search.rungs = {spec.search.rungs.front()};
  const SearchCost cost = estimate_search_cost(spec, grid);
  std::ostringstream out;
  out << "search (successive halving, eta " << spec.search.eta << ", rungs";
  for (int b : spec.search.rungs) out << " " << b;
  out << " steps)\nrung 0 (every configuration at " << spec.search.rungs.front() << " steps):\n"
      << dry_run_summary(expand_grid(first), ranks, split) << "configurations per rung:";
  for (int n : cost.configurations) out << " " << n;
  out << "\nrungs one after the other (every rank waits for a rung's last item):\n";
  for (int ranks_n : ranks) {
    double makespan = 0.0;
    for (const std::vector<double>& items : cost.items_s) makespan += greedy_makespan_s(items, ranks_n);
    char line[160];
    std::snprintf(line, sizeof line, "  %d rank%s: makespan %.0f s, efficiency %.1f %%\n", ranks_n,
                  ranks_n == 1 ? "" : "s", makespan,
                  100.0 * cost.halving_s / (ranks_n * std::max(makespan, 1e-9)));
    out << line;
  }
  out << "estimated " << hours(cost.halving_s) << " core-hours with halving (each rung going on "
      << "from the one before) against " << hours(cost.full_s) << " for every configuration at "
      << spec.search.rungs.back() << " steps ("
      << static_cast<int>(100.0 * cost.halving_s / std::max(cost.full_s, 1e-9) + 0.5) << " %)\n";
  return out.str();
}

}  // namespace apps
}  // namespace phnn
