// tests/sweep/search_early_test.cpp — search_cells_known_early and
// search_runs_ahead: while a rung drains, the survivors of the groups
// already complete are exactly those the rung's end keeps, and once every
// run has finished they are all of them; idle ranks may take the next rung
// of every configuration at the rung in progress.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/search.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

// Two groups (the study on each system) of 2 models x 2 rates = 4
// configurations, 3 seeds, rungs 100/200/400, eta 2.
const char* kSearch =
    "name = \"s\"\n"
    "[training]\n"
    "eval_every = 100\n"
    "[grid]\n"
    "systems = [\"harmonic\", \"duffing\"]\n"
    "models = [\"phnn-s-rk2\", \"node-rk2\"]\n"
    "seeds = \"0-2\"\n"
    "[search]\n"
    "rungs = [100, 200, 400]\n"
    "eta = 2\n"
    "learning_rate = [1e-3, 3e-3]\n";

// A criterion that reorders the configurations between rungs, with a
// failed and a diverged run.
struct Outcomes {
  std::vector<RunStatus> status;
  std::vector<double> criterion, mse;
};
Outcomes outcomes_of(const Grid& grid) {
  Outcomes o;
  for (const RunConfig& run : grid.runs) {
    const double model = run.model == ModelKind::kNode ? 2.0 : 1.0;
    const double rate = run.training.steps == 200 ? 1.0 / run.training.learning_rate
                                                  : run.training.learning_rate * 1e3;
    const double system = run.system_name() == "duffing" ? 3.0 : 1.0;
    o.status.push_back(RunStatus::kDone);
    o.criterion.push_back(model * rate * system * (1.0 + 0.1 * run.seed));
    o.mse.push_back(10 * o.criterion.back());
    if (run.seed == 1 && run.model == ModelKind::kNode) o.status.back() = RunStatus::kFailed;
    if (run.seed == 2 && run.training.steps == 200) o.status.back() = RunStatus::kDiverged;
  }
  return o;
}

TEST(SearchEarlyTest, SurvivorsKnownEarlyAreTheRungsDecision) {
  const SweepSpec spec = parse_sweep_text(kSearch, "x.toml");
  const Grid grid = expand_grid(spec);
  const Outcomes o = outcomes_of(grid);
  ASSERT_TRUE(replay_search(spec, grid, o.status, o.criterion, o.mse).state.complete);
  int early = 0;
  std::mt19937 shuffle(5);
  for (std::size_t r = 0; r + 1 < spec.search.rungs.size(); ++r) {
    // The rung's decision: the runs asked for at rung r + 1.
    const auto after =
        replay_search(spec, grid, o.status, o.criterion, o.mse, static_cast<int>(r) + 1);
    const auto upto = replay_search(spec, grid, o.status, o.criterion, o.mse, static_cast<int>(r));
    std::set<int> next;
    for (std::size_t c = 0; c < grid.cells.size(); ++c) {
      const int run = grid.cells[c].runs.front();
      if (after.state.active[static_cast<std::size_t>(run)] &&
          grid.runs[static_cast<std::size_t>(run)].training.steps == spec.search.rungs[r + 1]) {
        next.insert(static_cast<int>(c));
      }
    }
    ASSERT_FALSE(next.empty());
    std::vector<int> order;  // rung r's runs
    for (std::size_t i = 0; i < grid.runs.size(); ++i) {
      if (upto.state.active[i] && grid.runs[i].training.steps == spec.search.rungs[r]) {
        order.push_back(static_cast<int>(i));
      }
    }
    std::shuffle(order.begin(), order.end(), shuffle);
    std::vector<RunStatus> status = o.status;
    for (std::size_t i = 0; i < status.size(); ++i) {  // beyond rung r: not trained yet
      if (!upto.state.active[i]) status[i] = RunStatus::kPending;
    }
    for (int i : order) status[static_cast<std::size_t>(i)] = RunStatus::kPending;
    const auto ahead =
        search_runs_ahead(spec, grid, static_cast<int>(r), status, o.criterion, o.mse);
    ASSERT_EQ(ahead.size(), grid.cells.size());
    for (int c : next) EXPECT_FALSE(ahead[static_cast<std::size_t>(c)].empty()) << "cell " << c;
    std::vector<char> decided;
    std::set<int> known;
    for (std::size_t j = 0; j <= order.size(); ++j) {
      if (j > 0) {
        const auto i = static_cast<std::size_t>(order[j - 1]);
        status[i] = o.status[i];
      }
      for (int c : search_cells_known_early(spec, grid, static_cast<int>(r), status, o.criterion,
                                            o.mse, &decided)) {
        EXPECT_TRUE(next.count(c)) << "rung " << r << ": cell " << c << " known early, not kept";
        if (known.insert(c).second && j < order.size()) ++early;
      }
    }
    EXPECT_EQ(known, next) << "rung " << r;
  }
  EXPECT_GT(early, 0) << "no group was ever decided before its rung ended";
}

}  // namespace
}  // namespace phnn
