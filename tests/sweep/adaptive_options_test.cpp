// tests/sweep/adaptive_options_test.cpp — the options of the comparisons
// rule, on synthetic results whose statistics are checked first: the
// futility stop, stop_confidence, and grow = "one".
#include "phnn/sweep/adaptive.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
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
      const RunConfig& run = grid.runs[static_cast<std::size_t>(c.runs[0])];
      if (run.integrator == integrator) return c.member_cost_s;
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
  // Diverged seeds give RK2 (median 1.2) an infinite facing half-width:
  // named, though RK4 (1.3 ... 5.3, median 3.3) has a wide finite one.
  {
    const Results r = results_of(grid, [](const RunConfig& run) {
      const int k = run.seed % 5;
      if (run.integrator == IntegratorKind::kRk4) return 1.3 + 1.0 * k;
      return k >= 3 ? std::numeric_limits<double>::infinity() : 1.0 + 0.1 * k;
    });
    std::vector<int> cells = adaptive_rule_cells(one, grid, active, r.status, r.mse);
    ASSERT_EQ(cells.size(), 1u);
    EXPECT_EQ(grid.runs[static_cast<std::size_t>(grid.cells[cells[0]].runs[0])].integrator,
              IntegratorKind::kRk2);
  }
  // The wide RK2 of the first case but already at max_seeds (10 seeds, cap
  // 10): it cannot grow, so RK4 is named; and a side without an interval
  // (RK4 at 4 seeds) names both, as grow = "both" does.
  {
    std::string text = sweep_text(kTwoModels, adaptive + "grow = \"one\"\n");
    text.replace(text.find("max_seeds = 40"), 14, "max_seeds = 10");
    const SweepSpec capped = parse_sweep_text(text, "x.toml");
    const Grid g = expand_grid(capped);
    const Results r = results_of(g, [](const RunConfig& run) {
      const int k = run.seed % 5;
      return run.integrator == IntegratorKind::kRk4 ? 1.8 + 0.01 * k : 1.0 + 0.3 * k;
    });
    const auto named_with = [&](int rk4_seeds) {
      std::vector<char> on(g.runs.size(), 0);
      for (std::size_t i = 0; i < g.runs.size(); ++i) {
        on[i] = g.runs[i].integrator == IntegratorKind::kRk2 || g.runs[i].seed < rk4_seeds;
      }
      std::vector<IntegratorKind> out;
      for (int c : adaptive_rule_cells(capped, g, on, r.status, r.mse)) {
        out.push_back(g.runs[static_cast<std::size_t>(g.cells[c].runs[0])].integrator);
      }
      return out;
    };
    EXPECT_THAT(named_with(5), ElementsAre(IntegratorKind::kRk4));
    EXPECT_EQ(named_with(4).size(), 2u);
  }
  EXPECT_THAT(error_of(sweep_text(kTwoModels, adaptive + "grow = \"all\"\n")),
              AllOf(HasSubstr("x.toml:11: unknown grow \"all\""),
                    HasSubstr("expected one of: both, one")));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, kColumnBest + "grow = \"one\"\n")),
              HasSubstr("grow = \"one\" applies to rule = \"comparisons\" only"));
}
// grow = "one" reads the cost model's per-seed seconds, so a refit of the
// model (include/phnn/sweep/grid.h) changes which cell of a pair grows, and
// with it the runs sweeps/paper-adaptive.toml asks for on results already
// trained: replays of existing files would no longer match their sweeps.
// This pins the model's per-seed seconds of every cell of that grid. If a
// refit is intended, freeze the old values for grow = "one" (or make the
// change a new rule) rather than updating the fingerprint.
TEST(AdaptiveRoundsTest, GrowOneCostsOfThePaperGridArePinned) {
  const SweepSpec spec =
      parse_sweep_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/paper-adaptive.toml");
  ASSERT_TRUE(spec.adaptive.grow_one);
  const Grid grid = expand_grid(spec);
  std::string all;
  for (const Cell& c : grid.cells) {
    char v[32];
    std::snprintf(v, sizeof v, "%.17g", c.member_cost_s);
    all += grid.runs[static_cast<std::size_t>(c.runs[0])].cell_key() + "=" + v + ";";
  }
  EXPECT_EQ(hex64(fnv1a64(all)), "1577893f59b2b1a4") << "the cost model's per-seed seconds changed";
}

}  // namespace
}  // namespace phnn

namespace phnn {
namespace {

// reading = "four-way" (paired here: PHNN-JR with RK2 and with RK4 share
// their seeds' initial weights and batches): a pair whose per-seed ratio is
// ~1.01 is equivalent within x1.5 and a pair 1.8x apart is decided, so
// neither grows — although the second pair's median intervals overlap,
// which keeps the intervals reading growing it; a pair whose ratio swings
// between x3 and x1/3 by seed is undecided and grows both cells to max_seeds.
TEST(AdaptiveRoundsTest, FourWayReadingStopsEquivalentAndDecidedPairsAndGrowsUndecidedOnes) {
  const auto text = [](const std::string& reading) {
    return "name = \"a\"\n[grid]\nsystems = [\"harmonic\"]\nmodels = [\"phnn-jr-rk2\", "
           "\"phnn-jr-rk4\"]\nseeds = \"0-9\"\n[adaptive]\nmax_seeds = 20\nbatch = 5\n"
           "rule = \"comparisons\"\ncomparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", "
           "\"harmonic/phnn-jr-rk4/25/small/none\"]]\n" + reading;
  };
  const SweepSpec four_way = parse_sweep_text(text("reading = \"four-way\"\n"), "x.toml");
  const SweepSpec intervals = parse_sweep_text(text(""), "x.toml");
  EXPECT_TRUE(four_way.adaptive.four_way);
  EXPECT_EQ(four_way.adaptive.delta, 1.5);
  const Grid grid = expand_grid(four_way);
  const auto with_ratio = [&](const std::function<double(int)>& ratio) {
    return adaptive_test::results_of(grid, [&](const RunConfig& run) {
      const double v = 1e-3 * (1.0 + run.seed);
      return run.integrator == IntegratorKind::kRk4 ? v * ratio(run.seed) : v;
    });
  };
  const auto equivalent = with_ratio([](int) { return 1.01; });
  const auto decided = with_ratio([](int) { return 1.8; });
  const auto undecided = with_ratio([](int seed) { return seed % 2 ? 3.0 : 1.0 / 3.0; });
  for (const auto* r : {&equivalent, &decided}) {
    const AdaptiveState s = replay_adaptive_rounds(four_way, grid, r->status, r->mse);
    EXPECT_TRUE(s.complete);
    EXPECT_TRUE(s.cells_grown.empty());
    EXPECT_EQ(adaptive_test::seeds_of(s, grid, IntegratorKind::kRk4), 10);
  }
  const AdaptiveState by_intervals = replay_adaptive_rounds(intervals, grid, decided.status, decided.mse);
  EXPECT_FALSE(by_intervals.cells_grown.empty()) << "the intervals reading should not decide 1.8x at 10 seeds";
  const AdaptiveState grown = replay_adaptive_rounds(four_way, grid, undecided.status, undecided.mse);
  EXPECT_EQ(adaptive_test::seeds_of(grown, grid, IntegratorKind::kRk2), 20);
  EXPECT_EQ(adaptive_test::seeds_of(grown, grid, IntegratorKind::kRk4), 20);
}

// Four-way futility: the effect interval narrowed by sqrt(10 / 20) about
// the effect. A pair whose per-seed log ratio alternates +-0.48 (median 0,
// interval [-0.48, 0.48] -> [-0.34, 0.34]) can reach neither reading at 20
// seeds: it stops at 10. A pair 2x apart on 7 seeds and 0.8x on 3 (median
// 0.30, interval [-0.10, 0.30] -> [0.02, 0.30]) can be decided: it grows.
TEST(AdaptiveRoundsTest, FourWayFutilityStopsPairsThatMaxSeedsCannotRead) {
  const std::string text =
      "name = \"a\"\n[grid]\nsystems = [\"harmonic\"]\nmodels = [\"phnn-jr-rk2\", \"phnn-jr-rk4\"]\n"
      "seeds = \"0-9\"\n[adaptive]\nmax_seeds = 20\nbatch = 5\nrule = \"comparisons\"\n"
      "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"]]\n"
      "reading = \"four-way\"\n";
  const SweepSpec plain = parse_sweep_text(text, "x.toml");
  const SweepSpec futile = parse_sweep_text(text + "futility = true\n", "x.toml");
  const Grid grid = expand_grid(futile);
  const auto with_ratio = [&](const std::function<double(int)>& ratio) {
    return adaptive_test::results_of(grid, [&](const RunConfig& run) {
      const double v = 1e-3 * (1.0 + run.seed);
      return run.integrator == IntegratorKind::kRk4 ? v * ratio(run.seed) : v;
    });
  };
  const auto swinging = with_ratio([](int seed) { return seed % 2 ? 3.0 : 1.0 / 3.0; });
  const auto leaning = with_ratio([](int seed) { return seed % 10 < 7 ? 2.0 : 0.8; });
  const AdaptiveState stopped = replay_adaptive_rounds(futile, grid, swinging.status, swinging.mse);
  EXPECT_TRUE(stopped.complete);
  EXPECT_EQ(adaptive_test::seeds_of(stopped, grid, IntegratorKind::kRk4), 10);
  EXPECT_EQ(adaptive_test::seeds_of(replay_adaptive_rounds(plain, grid, swinging.status, swinging.mse),
                                    grid, IntegratorKind::kRk4),
            20);
  const AdaptiveState grows = replay_adaptive_rounds(futile, grid, leaning.status, leaning.mse);
  EXPECT_GT(adaptive_test::seeds_of(grows, grid, IntegratorKind::kRk4), 10);
}

TEST(AdaptiveSweepFileTest, FourWayReadingOptionsAreCheckedAtTheirTable) {
  const std::string base =
      "max_seeds = 8\nbatch = 3\nrule = \"comparisons\"\n"
      "comparisons = [[\"harmonic/phnn-jr-rk2/25/small/none\", \"harmonic/phnn-jr-rk4/25/small/none\"]]\n";
  using adaptive_test::error_of;
  using adaptive_test::kTwoModels;
  using adaptive_test::sweep_text;
  EXPECT_TRUE(parse_sweep_text(sweep_text(kTwoModels, base + "reading = \"four-way\"\nfutility = true\n"),
                               "x.toml").adaptive.futility);
  EXPECT_THAT(error_of(sweep_text(kTwoModels, base + "delta = 2.0\n")),
              HasSubstr("delta is the margin of reading = \"four-way\""));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, base + "reading = \"four-way\"\ndelta = 1.0\n")),
              HasSubstr("delta expects a factor in (1, 100]"));
  EXPECT_THAT(error_of(sweep_text(kTwoModels, base + "reading = \"fourway\"\n")),
              HasSubstr("four-way"));
  EXPECT_EQ(parse_sweep_text(sweep_text(kTwoModels, base + "reading = \"four-way\"\ndelta = 2\n"), "x.toml")
                .adaptive.delta,
            2.0);
}

}  // namespace
}  // namespace phnn
