// tests/sweep/adaptive_test.cpp — [adaptive] in sweep files (accepted forms,
// hostile inputs with FILE:LINE) and the rounds replayed from synthetic
// results: which cells each rule grows, the cap, a round in progress, and
// that runs outside the rounds never enter a decision. The rule's options
// (futility, stop_confidence, grow): adaptive_options_test.cpp.
#include "phnn/sweep/adaptive.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "sweep/adaptive_test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using namespace adaptive_test;  // NOLINT: the shared helpers

TEST(AdaptiveSweepFileTest, SeedsGrowToMaxSeedsAndRoundZeroKeepsTheFileSeeds) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  ASSERT_TRUE(spec.adaptive.enabled);
  EXPECT_EQ(spec.adaptive.max_seeds, 12);
  EXPECT_EQ(spec.adaptive.batch, 3);
  EXPECT_EQ(spec.adaptive.rule, AdaptiveRule::kColumnBest);
  EXPECT_THAT(spec.adaptive.initial_seeds, ElementsAre(0, 1, 2, 3, 4));
  EXPECT_EQ(spec.studies[0].seeds.size(), 12u);
  EXPECT_EQ(spec.studies[0].seeds.back(), 11);
  EXPECT_EQ(expand_grid(spec).runs.size(), 24u);
  EXPECT_EQ(expand_grid(round_zero_spec(spec)).runs.size(), 10u);
}

TEST(AdaptiveSweepFileTest, ComparisonsParseIntoSelectors) {
  const SweepSpec spec = parse_sweep_text(
      sweep_text(kTwoModels + ", \"node-rk2\"",
                 "max_seeds = 12\nbatch = 3\nrule = \"comparisons\"\n"
                 "comparisons = [[\"harmonic/phnn-jr-rk2+phnn-jr-rk4/25/small/none\",\n"
                 "                \"harmonic/node-rk2/25/small/none\"]]\n"),
      "x.toml");
  ASSERT_EQ(spec.adaptive.comparisons.size(), 1u);
  const SeedComparison& c = spec.adaptive.comparisons[0];
  EXPECT_EQ(c.line, 10);
  EXPECT_EQ(c.a.models.size(), 2u);
  EXPECT_EQ(c.b.models.size(), 1u);
  EXPECT_EQ(c.a.n_train, 25);
  EXPECT_EQ(c.b.system, "harmonic");
}

TEST(AdaptiveSweepFileTest, BadTablesFailAtTheirLineWithTheFix) {
  EXPECT_THAT(error_of(sweep_text(kTwoModels, "max_seeds = 12\n")),
              AllOf(HasSubstr("x.toml:6:"), HasSubstr("needs batch")));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, kColumnBest + "max_seed = 3\n")),
              AllOf(HasSubstr("x.toml:10:"), HasSubstr("did you mean \"max_seeds\"")));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, "max_seeds = 3\nbatch = 1\n")),
              AllOf(HasSubstr("x.toml:6:"), HasSubstr("below the 5 seeds")));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, "max_seeds = 9\nbatch = 0\n")),
              AllOf(HasSubstr("x.toml:8:"), HasSubstr("batch")));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, "max_seeds = 9\nbatch = 2\nrule = \"best\"\n")),
              AllOf(HasSubstr("x.toml:9:"), HasSubstr("column-best, comparisons")));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, "max_seeds = 9\nbatch = 2\nrule = \"comparisons\"\n")),
              AllOf(HasSubstr("x.toml:6:"), HasSubstr("needs `comparisons")));
}

TEST(AdaptiveSweepFileTest, SelectorsMustNameCellsOfTheStudies) {
  const auto with = [](const std::string& a) {
    return sweep_text(kTwoModels, "max_seeds = 9\nbatch = 2\nrule = \"comparisons\"\n"
                                  "comparisons = [[\"" + a + "\", \"harmonic/phnn-jr-rk2/25/small/none\"]]\n");
  };
  EXPECT_THAT(error_of(with("harmonic/phnn-jr-rk2/25/small")),
              AllOf(HasSubstr("x.toml:10:"), HasSubstr("4 '/'-separated fields")));
  EXPECT_THAT(error_of(with("harmonic/phnn-jr-rk3/25/small/none")),
              AllOf(HasSubstr("x.toml:10:"), HasSubstr("unknown model \"phnn-jr-rk3\"")));
  EXPECT_THAT(error_of(with("duffing/phnn-jr-rk2/25/small/none")),
              AllOf(HasSubstr("x.toml:10:"), HasSubstr("no study trains phnn-jr-rk2 on \"duffing\"")));
  EXPECT_THAT(error_of(with("harmonic/phnn-jr-rk2/100/small/none")),
              HasSubstr("at n_train 100"));
  EXPECT_THAT(error_of(with("harmonic/phnn-jr-rk2/x/small/none")),
              HasSubstr("n_train \"x\" is not a positive integer"));
  EXPECT_THAT(error_of(with("harmonic//25/small/none")), HasSubstr("names no model"));
  EXPECT_THAT(error_of(with("harmonic/phnn-jr-rk4+phnn-jr-rk4/25/small/none")),
              HasSubstr("names model \"phnn-jr-rk4\" twice"));
  // The other side is phnn-jr-rk2 at the same settings: never resolvable.
  EXPECT_THAT(error_of(with("harmonic/phnn-jr-rk4+phnn-jr-rk2/25/small/none")),
              AllOf(HasSubstr("x.toml:10:"), HasSubstr("both sides can pick the same cell")));
}

TEST(AdaptiveSweepFileTest, ColumnBestNeedsFiveSeeds) {
  std::string text = sweep_text(kTwoModels, kColumnBest);
  text.replace(text.find("0-4"), 3, "0-3");
  EXPECT_THAT(error_of(text), AllOf(HasSubstr("x.toml:6:"), HasSubstr("at least 5 seeds")));
}

TEST(AdaptiveSweepFileTest, StudiesMustShareTheirSeeds) {
  const std::string text = "name = \"a\"\n[grid]\nsystems = [\"harmonic\"]\nseeds = \"0-4\"\n"
                           "[study.one]\nn_train = [25]\n[study.two]\nn_train = [100]\n"
                           "seeds = \"0-5\"\n[adaptive]\nmax_seeds = 20\nbatch = 5\n";
  EXPECT_THAT(error_of(text), AllOf(HasSubstr("x.toml:10:"), HasSubstr("same `seeds`")));
}


TEST(AdaptiveRoundsTest, SeparatedCellsStopAfterRoundZeroWhateverLaterSeedsHold) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  const Grid grid = expand_grid(spec);
  // RK2: 1e-3 ... 5e-3, RK4: 1 ... 5: the intervals are disjoint. Seeds 5-11
  // (asked for by no round) hold the reverse order: they must not count.
  const Results r = results_of(grid, [](const RunConfig& run) {
    const double base = run.seed < 5 ? 1.0 + run.seed : 100.0 - run.seed;
    return run.integrator == IntegratorKind::kRk2 ? (run.seed < 5 ? 1e-3 : 1e3) * base : base;
  });
  const AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.round, 0);
  EXPECT_EQ(s.active_runs(), 10);
  EXPECT_TRUE(s.cells_grown.empty());
}

TEST(AdaptiveRoundsTest, TiedCellsGrowByBatchUpToMaxSeeds) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  const Grid grid = expand_grid(spec);
  // Interleaved errors: every round ties, so both cells reach 12 = 5 + 3 + 3 + 1.
  const Results r = results_of(grid, [](const RunConfig& run) {
    return 1e-3 * (1.0 + run.seed) * (run.integrator == IntegratorKind::kRk2 ? 1.0 : 1.05);
  });
  const AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.round, 3);
  EXPECT_THAT(s.cells_grown, ElementsAre(2, 2, 2));
  EXPECT_EQ(s.active_runs(), 24);
  // The same file as it stood after round 1: 5 + 3 seeds per cell.
  const AdaptiveState after1 = replay_adaptive_rounds(spec, grid, r.status, r.mse, {}, 1);
  EXPECT_FALSE(after1.complete);
  EXPECT_EQ(after1.round, 1);
  EXPECT_EQ(after1.active_runs(), 16);
}

TEST(AdaptiveRoundsTest, ColumnBestNamesCellsWithoutAnIntervalAndFailedRunsStayOut) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  const Grid grid = expand_grid(spec);
  // Separated cells, but one RK4 seed of round 0 failed: RK4 has 4 finished
  // seeds, no interval, the column marks nothing, and RK4 alone gets seeds.
  Results r = results_of(grid, [](const RunConfig& run) {
    return run.integrator == IntegratorKind::kRk2 ? 1e-3 * (1.0 + run.seed) : 1.0 + run.seed;
  });
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    if (grid.runs[i].seed == 2 && grid.runs[i].integrator == IntegratorKind::kRk4) {
      r.status[i] = RunStatus::kFailed;
      r.mse[i] = 1e-9;  // never read: a failed run's MSE is not a result
    }
  }
  const AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.failed, 1);
  EXPECT_EQ(seeds_of(s, grid, IntegratorKind::kRk2), 5);
  EXPECT_EQ(seeds_of(s, grid, IntegratorKind::kRk4), 8);  // 7 finished: separated again
  EXPECT_THAT(s.cells_grown, ElementsAre(1));
}

TEST(AdaptiveRoundsTest, ARoundWithAPendingRunIsInProgress) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  const Grid grid = expand_grid(spec);
  Results r = results_of(grid, [](const RunConfig& run) { return 1e-3 * (1.0 + run.seed); });
  // Seed 6 of the RK4 cell (round 1) is not finished: round 1 is in progress.
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    if (grid.runs[i].seed == 6 && grid.runs[i].integrator == IntegratorKind::kRk4) {
      r.status[i] = RunStatus::kPending;
    }
  }
  const AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  EXPECT_FALSE(s.complete);
  EXPECT_EQ(s.round, 1);
  EXPECT_EQ(s.active_runs(), 16);
  EXPECT_EQ(s.pending, 1);
  EXPECT_EQ(seeds_of(s, grid, IntegratorKind::kRk4), 8);
  // Asked for the state after round 3 while round 1 is in progress: round 1.
  EXPECT_EQ(replay_adaptive_rounds(spec, grid, r.status, r.mse, {}, 3).round, 1);
}

// What idle ranks train ahead: the next batch of the cells the round in
// progress grows, still pending ones only; nothing once the sweep is done.
TEST(AdaptiveRoundsTest, SpeculationTakesTheNextBatchOfTheCellsTheRoundGrows) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  const Grid grid = expand_grid(spec);
  // RK4's seed 2 failed, so round 0 leaves it without an interval and round
  // 1 grows it alone (5 -> 8 seeds), its seed 6 still pending; no run beyond
  // those asked for is finished. Ahead: RK4's seeds 8-10.
  Results r = results_of(grid, [](const RunConfig& run) {
    return run.integrator == IntegratorKind::kRk2 ? 1e-3 * (1.0 + run.seed) : 1.0 + run.seed;
  });
  int rk4_cell = -1;
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    const bool rk4 = grid.runs[i].integrator == IntegratorKind::kRk4;
    if (rk4 && grid.runs[i].seed == 2) r.status[i] = RunStatus::kFailed;  // RK4 grows in round 1
    if (grid.runs[i].seed >= 5 && !(rk4 && grid.runs[i].seed < 8)) r.status[i] = RunStatus::kPending;
    if (rk4 && grid.runs[i].seed == 6) r.status[i] = RunStatus::kPending;
  }
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    if (grid.runs[static_cast<std::size_t>(grid.cells[c].runs[0])].integrator == IntegratorKind::kRk4) {
      rk4_cell = static_cast<int>(c);
    }
  }
  AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  ASSERT_EQ(s.round, 1);
  ASSERT_EQ(seeds_of(s, grid, IntegratorKind::kRk4), 8);
  std::vector<std::vector<int>> ahead = runs_to_speculate(spec, grid, s, r.status);
  ASSERT_EQ(ahead.size(), grid.cells.size());
  std::vector<int> seeds;
  for (std::size_t c = 0; c < ahead.size(); ++c) {
    if (static_cast<int>(c) != rk4_cell) {
      EXPECT_TRUE(ahead[c].empty()) << "cell " << c;
    }
  }
  for (int row : ahead[static_cast<std::size_t>(rk4_cell)]) {
    seeds.push_back(grid.runs[static_cast<std::size_t>(row)].seed);
  }
  EXPECT_THAT(seeds, ElementsAre(8, 9, 10));
  // Seed 9 already trained ahead: not again; it is counted as trained ahead.
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    if (grid.runs[i].integrator == IntegratorKind::kRk4 && grid.runs[i].seed == 9) {
      r.status[i] = RunStatus::kDone;
    }
  }
  s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  EXPECT_EQ(s.trained_ahead, 1);
  ahead = runs_to_speculate(spec, grid, s, r.status);
  EXPECT_EQ(ahead[static_cast<std::size_t>(rk4_cell)].size(), 2u);
  // Finished: nothing ahead.
  const Results all = results_of(grid, [](const RunConfig& run) { return 1e-3 * (1.0 + run.seed); });
  const AdaptiveState done = replay_adaptive_rounds(spec, grid, all.status, all.mse);
  ASSERT_TRUE(done.complete);
  EXPECT_TRUE(runs_to_speculate(spec, grid, done, all.status).empty());
}

TEST(AdaptiveRoundsTest, ComparisonsGrowOnlyTheCellsOfUnresolvedComparisons) {
  const std::string comparisons =
      "max_seeds = 8\nbatch = 3\nrule = \"comparisons\"\n"
      "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"],\n"
      "               [\"harmonic/phnn-jr-rk2+phnn-jr-rk4/25/small/none\", \"harmonic/node-rk2/25/small/none\"]]\n";
  const SweepSpec spec =
      parse_sweep_text(sweep_text(kTwoModels + ", \"node-rk2\"", comparisons), "x.toml");
  const Grid grid = expand_grid(spec);
  // RK2 and RK4 tie; NODE is far above the better of them: only the first
  // comparison is unresolved, so NODE keeps its 5 seeds.
  const Results r = results_of(grid, [](const RunConfig& run) {
    const double v = 1e-3 * (1.0 + run.seed);
    return run.model == ModelKind::kNode ? 1e3 * v : run.integrator == IntegratorKind::kRk4 ? 1.05 * v : v;
  });
  const AdaptiveState s = replay_adaptive_rounds(spec, grid, r.status, r.mse);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(seeds_of(s, grid, IntegratorKind::kRk2), 8);
  EXPECT_EQ(seeds_of(s, grid, IntegratorKind::kRk4), 8);
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    if (grid.runs[static_cast<std::size_t>(grid.cells[c].runs[0])].model == ModelKind::kNode) {
      EXPECT_EQ(s.cell_seeds[c], 5);
    }
  }
  EXPECT_THAT(s.cells_grown, ElementsAre(2));  // then both are at max_seeds
}

TEST(AdaptiveRoundsTest, TheRuleSeesOnlyTheRunsAskedFor) {
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, kColumnBest), "x.toml");
  const Grid grid = expand_grid(spec);
  const Results r = results_of(grid, [](const RunConfig& run) {
    return run.integrator == IntegratorKind::kRk2 ? 1e-3 * (1.0 + run.seed) : 1.0 + run.seed;
  });
  // No run asked for: no cell has an interval, so both are undecided.
  std::vector<char> active(grid.runs.size(), 0);
  EXPECT_EQ(adaptive_rule_cells(spec, grid, active, r.status, r.mse).size(), 2u);
  for (std::size_t i = 0; i < grid.runs.size(); ++i) active[i] = grid.runs[i].seed < 5;
  EXPECT_TRUE(adaptive_rule_cells(spec, grid, active, r.status, r.mse).empty());
  Results tied = r;
  for (std::size_t i = 0; i < grid.runs.size(); ++i) tied.mse[i] = 1e-3 * (1.0 + grid.runs[i].seed);
  EXPECT_EQ(adaptive_rule_cells(spec, grid, active, tied.status, tied.mse).size(), 2u);
}

}  // namespace
}  // namespace phnn
