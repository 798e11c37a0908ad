// tests/sweep/adaptive_early_test.cpp — cells_named_early: while a round of
// the comparisons rule drains, the cells it names from the comparisons
// already complete are exactly cells the round's end names, and once every
// run has finished they are all of them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "sweep/adaptive_test_util.h"

namespace phnn {
namespace {

using namespace adaptive_test;  // NOLINT: the shared helpers

const std::string kModels = "\"phnn-jr-rk2\", \"phnn-jr-rk4\", \"phnn-s-rk2\", \"node-rk2\"";
const std::string kComparisons =
    "max_seeds = 25\nbatch = 5\nrule = \"comparisons\"\n"
    "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", "
    "\"harmonic/phnn-jr-rk4/25/small/none\"],\n"
    "  [\"harmonic/node-rk2/25/small/none\", \"harmonic/phnn-jr-rk2+phnn-s-rk2/25/small/none\"],\n"
    "  [\"harmonic/phnn-s-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"],\n"
    "  [\"harmonic/node-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"]]\n";

// Overlapping, spread-out MSEs per model (a log-normal-like spread from a
// fixed hash of model and seed), so rounds stay undecided for a while.
double mse_of(const RunConfig& run) {
  const double centre = run.model == ModelKind::kNode            ? 1.6
                        : run.integrator == IntegratorKind::kRk4 ? 1.2
                        : run.model == ModelKind::kPhnnS         ? 1.1
                                                                 : 1.0;
  const unsigned h =
      (static_cast<unsigned>(run.seed) * 2654435761u) ^
      (static_cast<unsigned>(run.model) * 40503u + static_cast<unsigned>(run.integrator));
  return centre * std::exp(0.6 * (static_cast<double>(h % 1000) / 1000.0 - 0.5));
}

std::vector<int> below_cap(const SweepSpec& spec, const Grid& grid, const std::vector<char>& active,
                           const std::vector<int>& cells) {
  std::vector<int> out;
  for (int c : cells) {
    int n = 0;
    for (int r : grid.cells[static_cast<std::size_t>(c)].runs)
      n += active[static_cast<std::size_t>(r)];
    if (n < spec.adaptive.max_seeds) out.push_back(c);
  }
  return out;
}

// Every round of a sweep whose results are `r`: its runs finish one by one
// in a shuffled order; after each, what cells_named_early returns (kept
// across the round) is a subset of the round's decision, and all of it at
// the end. Returns how many cells were named while runs were still pending.
int check_rounds(const SweepSpec& spec, const Grid& grid, const Results& r, unsigned seed) {
  BootstrapOptions fast;  // the property holds for any options; fewer resamples, a faster test
  fast.resamples = 2000;
  std::mt19937 shuffle(seed);
  int early = 0, rounds = 0;
  for (int k = 0;; ++k) {
    const AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse, fast, k);
    if (s.round < k) break;  // the sweep ended before round k
    ++rounds;
    const std::vector<int> decision = below_cap(
        spec, grid, s.active, adaptive_rule_cells(spec, grid, s.active, r.status, r.mse, fast));
    std::vector<char> before(grid.runs.size(), 0);  // the runs of rounds 0 .. k-1
    if (k > 0) before = replay_adaptive_rounds(spec, grid, r.status, r.mse, fast, k - 1).active;
    std::vector<int> order;  // round k's runs
    for (std::size_t i = 0; i < grid.runs.size(); ++i) {
      if (s.active[i] && !before[i]) order.push_back(static_cast<int>(i));
    }
    std::shuffle(order.begin(), order.end(), shuffle);
    std::vector<RunStatus> status = r.status;
    for (int i : order) status[static_cast<std::size_t>(i)] = RunStatus::kPending;
    std::vector<char> decided;
    std::set<int> named;
    for (std::size_t j = 0; j <= order.size(); ++j) {
      if (j > 0) status[static_cast<std::size_t>(order[j - 1])] = RunStatus::kDone;
      for (int c : cells_named_early(spec, grid, s.active, status, r.mse, &decided, fast)) {
        EXPECT_TRUE(std::find(decision.begin(), decision.end(), c) != decision.end())
            << "round " << k << ": cell " << c << " named early, not at the round's end";
        if (named.insert(c).second && j < order.size()) ++early;
      }
    }
    EXPECT_EQ(std::vector<int>(named.begin(), named.end()), decision) << "round " << k;
    if (decision.empty()) break;
  }
  EXPECT_GE(rounds, 2);
  return early;
}

TEST(AdaptiveEarlyTest, CellsNamedEarlyAreTheRoundsDecision) {
  for (const std::string& options :
       {std::string(), std::string("futility = true\n"), std::string("grow = \"one\"\n"),
        std::string("grow = \"one\"\nfutility = true\n")}) {
    SCOPED_TRACE(options);
    const SweepSpec spec = parse_sweep_text(sweep_text(kModels, kComparisons + options), "x.toml");
    const Grid grid = expand_grid(spec);
    const Results r = results_of(grid, mse_of);
    int early = 0;
    for (unsigned seed = 1; seed <= 3; ++seed) early += check_rounds(spec, grid, r, seed);
    EXPECT_GT(early, 0) << "no cell was ever known before its round ended";
  }
}

TEST(AdaptiveEarlyTest, ColumnBestNamesNothingEarly) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  const Grid grid = expand_grid(spec);
  const Results r = results_of(grid, mse_of);
  std::vector<char> active(grid.runs.size(), 0), decided;
  for (std::size_t i = 0; i < grid.runs.size(); ++i) active[i] = grid.runs[i].seed < 5;
  EXPECT_TRUE(cells_named_early(spec, grid, active, r.status, r.mse, &decided).empty());
}

}  // namespace
}  // namespace phnn
