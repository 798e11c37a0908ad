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
      if (j > 0) {  // run order[j - 1] finishes as it did
        const auto i = static_cast<std::size_t>(order[j - 1]);
        status[i] = r.status[i];
      }
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

// Every option of the comparisons rule (the four-way reading pairs the
// PHNN-JR cells: same architecture and seeds), with a failed and a
// diverged run among the results.
TEST(AdaptiveEarlyTest, CellsNamedEarlyAreTheRoundsDecision) {
  for (const std::string& options :
       {std::string(), std::string("futility = true\n"), std::string("grow = \"one\"\n"),
        std::string("grow = \"one\"\nfutility = true\n"), std::string("stop_confidence = 0.99\n"),
        std::string("reading = \"four-way\"\n"),
        std::string("reading = \"four-way\"\nfutility = true\ngrow = \"one\"\n")}) {
    SCOPED_TRACE(options);
    const SweepSpec spec = parse_sweep_text(sweep_text(kModels, kComparisons + options), "x.toml");
    const Grid grid = expand_grid(spec);
    Results r = results_of(grid, mse_of);
    for (std::size_t i = 0; i < grid.runs.size(); ++i) {
      const RunConfig& run = grid.runs[i];
      if (run.seed == 3 && run.model == ModelKind::kNode) r.status[i] = RunStatus::kFailed;
      if (run.seed == 7 && run.integrator == IntegratorKind::kRk4)
        r.status[i] = RunStatus::kDiverged;
    }
    int early = 0;
    for (unsigned seed = 1; seed <= 3; ++seed) early += check_rounds(spec, grid, r, seed);
    EXPECT_GT(early, 0) << "no cell was ever known before its round ended";
  }
}

// Under the comparisons rule idle ranks may take the next batch of every
// cell a comparison covers (which ones become certain is known as the round
// drains), and of no other cell, in round 0 too.
TEST(AdaptiveEarlyTest, SpeculationCandidatesAreTheComparisonsCells) {
  const std::string one =
      "max_seeds = 25\nbatch = 5\nrule = \"comparisons\"\n"
      "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", "
      "\"harmonic/phnn-jr-rk4/25/small/none\"]]\n";
  const SweepSpec spec = parse_sweep_text(sweep_text(kModels, one), "x.toml");
  const Grid grid = expand_grid(spec);
  Results r = results_of(grid, mse_of);
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    if (grid.runs[i].seed >= 3) r.status[i] = RunStatus::kPending;  // round 0 in progress
  }
  const AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  ASSERT_EQ(s.round, 0);
  const std::vector<std::vector<int>> ahead = runs_to_speculate(spec, grid, s, r.status);
  ASSERT_EQ(ahead.size(), grid.cells.size());
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const RunConfig& run = grid.runs[static_cast<std::size_t>(grid.cells[c].runs[0])];
    std::vector<int> seeds;
    for (int i : ahead[c]) seeds.push_back(grid.runs[static_cast<std::size_t>(i)].seed);
    const bool covered = run.model == ModelKind::kPhnnJr;
    EXPECT_EQ(seeds, covered ? std::vector<int>({5, 6, 7, 8, 9}) : std::vector<int>())
        << "cell " << c;
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
