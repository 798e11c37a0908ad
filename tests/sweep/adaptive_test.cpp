// tests/sweep/adaptive_test.cpp — [adaptive] in sweep files (accepted forms,
// hostile inputs with FILE:LINE) and the rounds replayed from synthetic
// results: which cells each rule grows, the cap, a round in progress, and
// that runs outside the rounds never enter a decision.
#include "phnn/sweep/adaptive.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::string sweep_text(const std::string& models, const std::string& adaptive) {
  return "name = \"a\"\n"                         // 1
         "[grid]\n"                               // 2
         "systems = [\"harmonic\"]\n"             // 3
         "models = [" + models + "]\n"            // 4
         "seeds = \"0-4\"\n"                      // 5
         "[adaptive]\n"                           // 6
         + adaptive;                              // 7 ...
}

const std::string kTwoModels = "\"phnn-jr-rk2\", \"phnn-jr-rk4\"";
const std::string kColumnBest = "max_seeds = 12\nbatch = 3\nrule = \"column-best\"\n";

std::string error_of(const std::string& text) {
  try {
    parse_sweep_text(text, "x.toml");
  } catch (const SweepFileError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a SweepFileError for:\n" << text;
  return "";
}

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

// Results for every run: status done and mse = value(model label, seed).
struct Results {
  std::vector<RunStatus> status;
  std::vector<double> mse;
};
Results results_of(const Grid& grid, const std::function<double(const RunConfig&)>& value) {
  Results r;
  for (const RunConfig& run : grid.runs) {
    r.status.push_back(RunStatus::kDone);
    r.mse.push_back(value(run));
  }
  return r;
}

int seeds_of(const AdaptiveState& s, const Grid& grid, IntegratorKind integrator) {
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    if (grid.runs[static_cast<std::size_t>(grid.cells[c].runs[0])].integrator == integrator) {
      return s.cell_seeds[c];
    }
  }
  return -1;
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

TEST(AdaptiveRoundsTest, FutilitySkipsComparisonsMaxSeedsCannotResolve) {
  const std::string comparisons =
      "max_seeds = 40\nbatch = 10\nrule = \"comparisons\"\n"
      "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"],\n"
      "               [\"harmonic/phnn-jr-rk2/25/small/none\", \"harmonic/node-rk2/25/small/none\"]]\n";
  const SweepSpec plain =
      parse_sweep_text(sweep_text(kTwoModels + ", \"node-rk2\"", comparisons), "x.toml");
  const SweepSpec futile = parse_sweep_text(
      sweep_text(kTwoModels + ", \"node-rk2\"", comparisons + "futility = true\n"), "x.toml");
  ASSERT_TRUE(futile.adaptive.futility);
  const Grid grid = expand_grid(plain);
  // RK2 and RK4 equal (a tie no seed count resolves); NODE 0.3 higher: its
  // 5-seed interval overlaps RK2's, its interval at 40 seeds would not.
  const Results r = results_of(grid, [](const RunConfig& run) {
    return (run.model == ModelKind::kNode ? 1.3 : 1.0) + 0.1 * (run.seed % 5);
  });
  std::vector<char> active(grid.runs.size(), 0);
  for (std::size_t i = 0; i < grid.runs.size(); ++i) active[i] = grid.runs[i].seed < 5;
  EXPECT_EQ(adaptive_rule_cells(plain, grid, active, r.status, r.mse).size(), 3u);
  const std::vector<int> named = adaptive_rule_cells(futile, grid, active, r.status, r.mse);
  ASSERT_EQ(named.size(), 2u);
  for (int c : named) {
    EXPECT_NE(grid.runs[static_cast<std::size_t>(grid.cells[c].runs[0])].integrator,
              IntegratorKind::kRk4);
  }
  EXPECT_THAT(error_of(sweep_text(kTwoModels, kColumnBest + "futility = true\n")),
              HasSubstr("futility applies to rule = \"comparisons\" only"));
}

// At the margin: RK4 = RK2 + 0.1, 5 seeds 1.0 ... 1.4 apart by 0.1. The
// intervals narrowed to 40 seeds still overlap, but neither median lies
// inside the other's narrowed interval: not futile, both cells grow.
TEST(AdaptiveRoundsTest, FutilityLeavesMarginalOverlapsGrowing) {
  const std::string comparisons =
      "max_seeds = 40\nbatch = 10\nrule = \"comparisons\"\nfutility = true\n"
      "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"]]\n";
  const SweepSpec spec = parse_sweep_text(sweep_text(kTwoModels, comparisons), "x.toml");
  const Grid grid = expand_grid(spec);
  const double shift = 0.1;
  const Results r = results_of(grid, [&](const RunConfig& run) {
    return (run.integrator == IntegratorKind::kRk4 ? shift : 0.0) + 1.0 + 0.1 * (run.seed % 5);
  });
  std::vector<double> lo, hi;
  for (int k = 0; k < 5; ++k) {
    lo.push_back(1.0 + 0.1 * k);
    hi.push_back(shift + 1.0 + 0.1 * k);
  }
  // Preconditions on the statistics alone: 5-seed intervals overlap, their
  // projections (x sqrt(5/40) about the medians 1.2 and 1.3) too, and
  // neither projection holds the other median.
  const Interval a = bootstrap_median_interval(lo), b = bootstrap_median_interval(hi);
  const double r8 = std::sqrt(5.0 / 40.0);
  const Interval pa{1.2 - (1.2 - a.low) * r8, 1.2 + (a.high - 1.2) * r8};
  const Interval pb{1.3 - (1.3 - b.low) * r8, 1.3 + (b.high - 1.3) * r8};
  ASSERT_TRUE(a.overlaps(b));
  ASSERT_TRUE(pa.overlaps(pb)) << pa.low << " " << pa.high << " / " << pb.low << " " << pb.high;
  ASSERT_TRUE(pa.high < 1.3 && pb.low > 1.2);
  std::vector<char> active(grid.runs.size(), 0);
  for (std::size_t i = 0; i < grid.runs.size(); ++i) active[i] = grid.runs[i].seed < 5;
  EXPECT_EQ(adaptive_rule_cells(spec, grid, active, r.status, r.mse).size(), 2u);
}

// Two cells of 10 seeds each, 1..10 and 1..10 + shift: at the shift below
// their 95 % intervals are disjoint and their 99 % intervals overlap
// (checked first, on the statistics alone).
TEST(AdaptiveRoundsTest, StopConfidenceKeepsMarginalResolutionsGrowing) {
  const double shift = 5.5;
  std::vector<double> low, high;
  for (int k = 1; k <= 10; ++k) {
    low.push_back(k);
    high.push_back(k + shift);
  }
  BootstrapOptions at99;
  at99.confidence = 0.99;
  ASSERT_FALSE(bootstrap_median_interval(low).overlaps(bootstrap_median_interval(high)));
  ASSERT_TRUE(bootstrap_median_interval(low, at99).overlaps(bootstrap_median_interval(high, at99)));

  for (const std::string rule : {"comparisons", "column-best"}) {
    SCOPED_TRACE(rule);
    std::string adaptive = "max_seeds = 20\nbatch = 10\nrule = \"" + rule + "\"\n";
    if (rule == "comparisons") {
      adaptive += "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", "
                  "\"harmonic/phnn-jr-rk4/25/small/none\"]]\n";
    }
    std::string text = sweep_text(kTwoModels, adaptive);
    text.replace(text.find("\"0-4\""), 5, "\"0-9\"");
    const SweepSpec plain = parse_sweep_text(text, "x.toml");
    const SweepSpec strict = parse_sweep_text(text + "stop_confidence = 0.99\n", "x.toml");
    ASSERT_EQ(strict.adaptive.stop_confidence, 0.99);
    const Grid grid = expand_grid(plain);
    const Results r = results_of(grid, [&](const RunConfig& run) {
      const double v = 1.0 + run.seed % 10;
      return run.integrator == IntegratorKind::kRk4 ? v + shift : v;
    });
    std::vector<char> active(grid.runs.size(), 0);
    for (std::size_t i = 0; i < grid.runs.size(); ++i) active[i] = grid.runs[i].seed < 10;
    EXPECT_TRUE(adaptive_rule_cells(plain, grid, active, r.status, r.mse).empty());
    EXPECT_EQ(adaptive_rule_cells(strict, grid, active, r.status, r.mse).size(), 2u);
    // Replayed: the strict sweep takes both cells to 20 seeds; the plain one stops at 10.
    EXPECT_EQ(replay_adaptive_rounds(plain, grid, r.status, r.mse).active_runs(), 20);
    EXPECT_EQ(replay_adaptive_rounds(strict, grid, r.status, r.mse).active_runs(), 40);
  }
  for (const char* bad : {"0.3", "1", "\"high\""}) {
    EXPECT_THAT(error_of(sweep_text(kTwoModels, kColumnBest + "stop_confidence = " + bad + "\n")),
                AllOf(HasSubstr("x.toml:10:"), HasSubstr("stop_confidence expects a number")));
  }
}

// grow = "one": of an unresolved pair, only the cell whose next batch
// closes more of the gap between the intervals per estimated core-second.
// Facing half-widths w (RK2's upper, RK4's lower: RK2's median is smaller)
// set the gain; the cost model's member seconds (RK4 > RK2) the price.
TEST(AdaptiveRoundsTest, GrowOneNamesTheCheaperWayToCloseTheGap) {
  const std::string adaptive =
      "max_seeds = 40\nbatch = 10\nrule = \"comparisons\"\n"
      "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"]]\n";
  const SweepSpec both = parse_sweep_text(sweep_text(kTwoModels, adaptive), "x.toml");
  const SweepSpec one =
      parse_sweep_text(sweep_text(kTwoModels, adaptive + "grow = \"one\"\n"), "x.toml");
  ASSERT_TRUE(one.adaptive.grow_one);
  ASSERT_FALSE(both.adaptive.grow_one);
  const Grid grid = expand_grid(both);
  const auto cost_of = [&](IntegratorKind integrator) {
    for (const Cell& c : grid.cells) {
      if (grid.runs[static_cast<std::size_t>(c.runs[0])].integrator == integrator) return c.member_cost_s;
    }
    return -1.0;
  };
  const double c2 = cost_of(IntegratorKind::kRk2), c4 = cost_of(IntegratorKind::kRk4);
  ASSERT_GT(c4, 1.5 * c2);  // RK4 costs more per seed (the cost model: 2.3x)
  std::vector<char> active(grid.runs.size(), 0);
  for (std::size_t i = 0; i < grid.runs.size(); ++i) active[i] = grid.runs[i].seed < 5;
  const auto named = [&](const SweepSpec& spec, double spread2, double base4, double spread4) {
    const Results r = results_of(grid, [&](const RunConfig& run) {
      const int k = run.seed % 5;
      return run.integrator == IntegratorKind::kRk4 ? base4 + spread4 * k : 1.0 + spread2 * k;
    });
    std::vector<IntegratorKind> out;
    for (int c : adaptive_rule_cells(spec, grid, active, r.status, r.mse)) {
      out.push_back(grid.runs[static_cast<std::size_t>(grid.cells[c].runs[0])].integrator);
    }
    return out;
  };
  // RK2 wide (median 1.6, w ~ 0.3), RK4 narrow (median 1.82, w ~ 0.01):
  // RK2 closes 30x more of the gap at under half the price.
  EXPECT_THAT(named(one, 0.3, 1.8, 0.01), ElementsAre(IntegratorKind::kRk2));
  EXPECT_EQ(named(both, 0.3, 1.8, 0.01).size(), 2u);
  // Mirrored: RK2 narrow (1.00 ... 1.04), RK4 wide (0.5 ... 1.7, median 1.1,
  // lower w ~ 0.3): RK4, though dearer.
  EXPECT_THAT(named(one, 0.01, 0.5, 0.3), ElementsAre(IntegratorKind::kRk4));
  // Equal spreads, medians 1.2 and 1.35: facing widths alike by symmetry,
  // so the price decides.
  EXPECT_THAT(named(one, 0.1, 1.15, 0.1), ElementsAre(IntegratorKind::kRk2));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, adaptive + "grow = \"all\"\n")),
              AllOf(HasSubstr("x.toml:11:"), HasSubstr("grow expects \"both\"")));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, kColumnBest + "grow = \"one\"\n")),
              HasSubstr("grow = \"one\" applies to rule = \"comparisons\" only"));
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
