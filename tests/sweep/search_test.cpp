// tests/sweep/search_test.cpp — [search] in sweep files (accepted forms,
// bad tables with FILE:LINE), its grid (configurations x rungs x seeds, run
// ids that differ only by the budget), and the rungs replayed from synthetic
// results: which configurations go on, a rung in progress, diverged and
// failed seeds, --round, and the cost estimate.
#include "phnn/sweep/search.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "phnn/report/tables.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// 2 models x learning_rate (2) x batch_size (2) = 8 configurations, 3 seeds,
// rungs 100/200/400 (eta 2: 8, 4, 2 configurations).
std::string search_text(const std::string& search = "", const std::string& training = "") {
  return "name = \"s\"\n"                                  // 1
         "[training]\n"                                    // 2
         "eval_every = 100\n" + training +                 // 3
         "[grid]\n"                                        // 4
         "systems = [\"harmonic\"]\n"                      // 5
         "models = [\"phnn-s-rk2\", \"node-rk2\"]\n"       // 6
         "seeds = \"0-2\"\n"                               // 7
         "[search]\n"                                      // 8
         "rungs = [100, 200, 400]\n"                       // 9
         "eta = 2\n"                                       // 10
         "learning_rate = [1e-3, 3e-3]\n"                  // 11
         "batch_size = [16, 64]\n" + search;               // 12
}

std::string error_of(const std::string& text) {
  try {
    parse_sweep_text(text, "x.toml");
  } catch (const SweepFileError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(SearchSweepFileTest, AxesExpandIntoVariantsAndRungsOwnTheSteps) {
  const SweepSpec spec = parse_sweep_text(search_text(), "x.toml");
  ASSERT_TRUE(spec.search.enabled);
  EXPECT_THAT(spec.search.rungs, ElementsAre(100, 200, 400));
  EXPECT_EQ(spec.search.eta, 2);
  EXPECT_THAT(spec.search.axes, ElementsAre("learning_rate", "batch_size"));
  ASSERT_EQ(spec.search.variants.size(), 4u);
  EXPECT_EQ(spec.search.variant_labels[1], "learning_rate=0.001/batch_size=64");
  EXPECT_EQ(spec.search.variants[1].learning_rate, 1e-3);
  EXPECT_EQ(spec.search.variants[1].batch_size, 64);
  EXPECT_EQ(spec.search.variants[2].learning_rate, 3e-3);
  EXPECT_EQ(spec.search.variants[2].batch_size, 16);
  EXPECT_EQ(spec.training.steps, 400);
  // A string-valued [training] key is an axis too.
  const SweepSpec norms = parse_sweep_text(search_text("loss_norm = [\"mean-l1\", \"mse\"]\n"), "x.toml");
  EXPECT_EQ(norms.search.variants.size(), 8u);
  EXPECT_EQ(norms.search.variants[1].loss_norm, LossNorm::kMse);
}

TEST(SearchSweepFileTest, BadTablesFailAtTheirLineWithTheFix) {
  EXPECT_THAT(error_of(search_text("rate = [1]\n")),
              AllOf(HasSubstr("x.toml:13:"), HasSubstr("unknown key \"rate\" in [search]")));
  EXPECT_THAT(error_of(search_text("steps = [100, 200]\n")),
              AllOf(HasSubstr("x.toml:13:"), HasSubstr("rungs = [...]")));
  EXPECT_THAT(error_of(search_text("adam_eps = 1e-8\n")),
              AllOf(HasSubstr("x.toml:13:"), HasSubstr("expects a list of values")));
  EXPECT_THAT(error_of(search_text("adam_beta1 = [0.9, \"x\"]\n")), HasSubstr("x.toml:13:"));
  EXPECT_THAT(error_of(search_text("adam_beta1 = [0.9, 0.9]\n")),
              AllOf(HasSubstr("x.toml:13:"), HasSubstr("twice")));
  EXPECT_THAT(error_of(search_text("", "steps = 400\n")),
              AllOf(HasSubstr("x.toml:4:"), HasSubstr("rungs are the step budgets")));
  // rungs: increasing, on validation steps; eta >= 1; rungs required.
  std::string text = search_text();
  const std::string rungs = "rungs = [100, 200, 400]";
  auto with_rungs = [&](const std::string& r) {
    std::string t = text;
    return t.replace(t.find(rungs), rungs.size(), r);
  };
  EXPECT_THAT(error_of(with_rungs("rungs = [200, 100]")),
              AllOf(HasSubstr("x.toml:9:"), HasSubstr("must increase")));
  EXPECT_THAT(error_of(with_rungs("rungs = [150, 300]")),
              AllOf(HasSubstr("x.toml:9:"), HasSubstr("multiple of eval_every")));
  EXPECT_THAT(error_of(with_rungs("# no rungs")),
              AllOf(HasSubstr("x.toml:8:"), HasSubstr("needs rungs")));
  std::string eta0 = text;
  eta0.replace(eta0.find("eta = 2"), 7, "eta = 0");
  EXPECT_THAT(error_of(eta0), AllOf(HasSubstr("x.toml:10:"), HasSubstr("[1, 1000]")));
  EXPECT_THAT(error_of(search_text("[adaptive]\nmax_seeds = 6\nbatch = 1\n")),
              HasSubstr("[search] and [adaptive]"));
  // A combination [training] refuses, named by its label.
  EXPECT_THAT(error_of(search_text("adam_beta2 = [0.999, 1.5]\n")),
              AllOf(HasSubstr("x.toml:8:"), HasSubstr("adam_beta2=1.5")));
}

TEST(SearchGridTest, ConfigurationsTimesRungsTimesSeedsWithIdsThatDifferByTheBudget) {
  const SweepSpec spec = parse_sweep_text(search_text(), "x.toml");
  const Grid grid = expand_grid(spec);
  EXPECT_EQ(grid.runs.size(), 2u * 4u * 3u * 3u);
  EXPECT_EQ(grid.cells.size(), 24u);
  const StudyTable& table = grid.studies[0];
  EXPECT_EQ(table.varied_axis, "settings/steps");
  EXPECT_EQ(table.columns.front(), "learning_rate=0.001/batch_size=16/steps=100");
  EXPECT_EQ(table.columns.size(), 12u);
  // The same configuration at two rungs: one key, two ids.
  const RunConfig& a = grid.runs[0];
  const RunConfig& b = grid.runs[3];
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.training.steps, 100);
  EXPECT_EQ(b.training.steps, 200);
  EXPECT_EQ(configuration_key(a), configuration_key(b));
  EXPECT_NE(a.id(), b.id());
  // Rungs before the last skip inference; a run of the last rung is the run
  // of a plain sweep of that budget: the same id.
  EXPECT_TRUE(a.training.skip_inference);
  EXPECT_TRUE(b.training.skip_inference);
  const RunConfig& c = grid.runs[6];
  ASSERT_EQ(c.training.steps, 400);
  EXPECT_FALSE(c.training.skip_inference);
  RunConfig plain = c;
  plain.training = TrainerOptions();
  plain.training.eval_every = 100;
  plain.training.steps = 400;
  plain.training.learning_rate = 1e-3;
  plain.training.batch_size = 16;
  EXPECT_EQ(plain.id(), c.id());
  // The tables hold the last rung's runs only: the others have no MSE.
  const std::vector<RunStatus> done(grid.runs.size(), RunStatus::kDone);
  const std::vector<double> no_mse(grid.runs.size(), std::numeric_limits<double>::quiet_NaN());
  const std::vector<TableEntry> entries = make_table_entries(grid, done, no_mse);
  EXPECT_EQ(entries.size(), 2u * 4u * 3u);
  for (const TableEntry& e : entries) EXPECT_THAT(e.column, HasSubstr("steps=400"));
}

constexpr double kInf = std::numeric_limits<double>::infinity();

// Synthetic results: every run done, its criterion from `loss(run)`.
struct Results {
  std::vector<RunStatus> status;
  std::vector<double> criterion, mse;
};
template <typename Loss>
Results results_of(const Grid& grid, const Loss& loss) {
  Results r;
  for (const RunConfig& run : grid.runs) {
    r.status.push_back(RunStatus::kDone);
    r.criterion.push_back(loss(run));
    r.mse.push_back(10 * loss(run));
  }
  return r;
}

// The configurations (labels) the replay kept after rung `r`.
std::vector<std::string> kept(const SearchReplay& replay, std::size_t r) {
  std::vector<std::string> out;
  for (const SearchEntry& e : replay.groups.at(0).rungs.at(r)) {
    if (e.kept) out.push_back(e.label);
  }
  return out;
}

TEST(SearchReplayTest, EachRungKeepsTheBestHalfByTheMedianCriterion) {
  const SweepSpec spec = parse_sweep_text(search_text(), "x.toml");
  const Grid grid = expand_grid(spec);
  // Lower is better: NODE 10x worse than PHNN-S, a smaller rate better at rung 0
  // and a larger batch better later; seed 2 an outlier that the median ignores.
  const auto loss = [](const RunConfig& run) {
    double v = run.model == ModelKind::kNode ? 10.0 : 1.0;
    v *= run.training.steps == 100 ? run.training.learning_rate * 1e3
                                   : 1.0 / run.training.batch_size;
    return run.seed == 2 ? 1e9 : v;
  };
  const Results res = results_of(grid, loss);
  const SearchReplay replay = replay_search(spec, grid, res.status, res.criterion, res.mse);
  ASSERT_TRUE(replay.state.complete);
  EXPECT_EQ(replay.state.round, 2);
  EXPECT_THAT(replay.state.cells_grown, ElementsAre(4, 2));
  EXPECT_EQ(replay.state.active_runs(), (8 + 4 + 2) * 3);
  // The models compete in one group (the study on harmonic): PHNN-S at
  // either rate (1, 3) beats NODE at any (10, 30).
  EXPECT_THAT(kept(replay, 0),
              ElementsAre("PHNN-S-RK2 learning_rate=0.001/batch_size=16",
                          "PHNN-S-RK2 learning_rate=0.001/batch_size=64",
                          "PHNN-S-RK2 learning_rate=0.003/batch_size=16",
                          "PHNN-S-RK2 learning_rate=0.003/batch_size=64"));
  // Rung 1: batch 64 wins; the tie between the rates goes by grid order.
  EXPECT_THAT(kept(replay, 1), ElementsAre("PHNN-S-RK2 learning_rate=0.001/batch_size=64",
                                           "PHNN-S-RK2 learning_rate=0.003/batch_size=64"));
  const SearchEntry& best = replay.groups[0].rungs[2].front();
  EXPECT_EQ(best.label, "PHNN-S-RK2 learning_rate=0.001/batch_size=64");
  EXPECT_DOUBLE_EQ(best.criterion, 1.0 / 64);
  EXPECT_DOUBLE_EQ(best.mse, 10.0 / 64);
  EXPECT_THAT(search_report(spec, replay),
              HasSubstr("Best: **PHNN-S-RK2 learning_rate=0.001/batch_size=64**"));
  // --round 0: the search as it stood after rung 0.
  const SearchReplay first = replay_search(spec, grid, res.status, res.criterion, res.mse, 0);
  EXPECT_FALSE(first.state.complete);
  EXPECT_EQ(first.state.active_runs(), 8 * 3);
  EXPECT_TRUE(kept(first, 0).empty());
}

TEST(SearchReplayTest, PendingRunsStopTheReplayAndOnlyAskedRunsDecide) {
  const SweepSpec spec = parse_sweep_text(search_text(), "x.toml");
  const Grid grid = expand_grid(spec);
  Results res = results_of(grid, [](const RunConfig& run) { return run.training.learning_rate; });
  // A rung-0 run pending: rung 0 in progress, nothing decided.
  std::vector<RunStatus> status = res.status;
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    if (grid.runs[i].training.steps == 100 && grid.runs[i].seed == 1) {
      status[i] = RunStatus::kPending;
      break;
    }
  }
  const SearchReplay waiting = replay_search(spec, grid, status, res.criterion, res.mse);
  EXPECT_EQ(waiting.state.round, 0);
  EXPECT_EQ(waiting.state.pending, 1);
  EXPECT_EQ(waiting.state.active_runs(), 24);
  // Runs no rung asks for never count: a rung-2 run of a configuration
  // dropped at rung 0 (learning rate 3e-3) with a criterion of -inf changes
  // nothing.
  const SearchReplay plain = replay_search(spec, grid, res.status, res.criterion, res.mse);
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    if (grid.runs[i].training.steps == 400 && grid.runs[i].training.learning_rate == 3e-3) {
      res.criterion[i] = -kInf;
    }
  }
  const SearchReplay same = replay_search(spec, grid, res.status, res.criterion, res.mse);
  EXPECT_EQ(same.state.active, plain.state.active);
}

TEST(SearchReplayTest, DivergedSeedsCountAsInfiniteAndFailedOnesAreLeftOut) {
  const SweepSpec spec = parse_sweep_text(search_text(), "x.toml");
  const Grid grid = expand_grid(spec);
  Results res = results_of(grid, [](const RunConfig& run) {
    return run.model == ModelKind::kNode ? 2.0 : 1.0;
  });
  // PHNN-S at rate 1e-3, batch 16: two of three seeds diverge -> median inf;
  // NODE at rate 3e-3, batch 64: two seeds fail, the third at 0.5 -> 0.5.
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    const RunConfig& run = grid.runs[i];
    if (run.training.steps != 100) continue;
    if (run.model == ModelKind::kPhnnS && run.training.learning_rate == 1e-3 &&
        run.training.batch_size == 16 && run.seed < 2) {
      res.status[i] = RunStatus::kDiverged;
    }
    if (run.model == ModelKind::kNode && run.training.learning_rate == 3e-3 &&
        run.training.batch_size == 64) {
      if (run.seed < 2) res.status[i] = RunStatus::kFailed;
      res.criterion[i] = 0.5;
    }
  }
  const SearchReplay replay = replay_search(spec, grid, res.status, res.criterion, res.mse, 0);
  const std::vector<SearchEntry>& rung0 = replay.groups[0].rungs[0];
  EXPECT_EQ(rung0.front().label, "NODE-RK2 learning_rate=0.003/batch_size=64");
  EXPECT_EQ(rung0.front().criterion, 0.5);
  EXPECT_EQ(rung0.back().label, "PHNN-S-RK2 learning_rate=0.001/batch_size=16");
  EXPECT_EQ(rung0.back().criterion, kInf);
  EXPECT_EQ(replay.state.failed, 2);
}

// Budgets of 5 000 to 45 000 steps: halving costs less than the full grid.
// (At the few hundred steps of the tests above, each rung's inference of the
// default 100 trajectories outweighs the steps it saves.)
TEST(SearchReplayTest, TheCostEstimateCountsOnlyTheStepsBeyondTheRungBefore) {
  std::string text = search_text();
  text.replace(text.find("rungs = [100, 200, 400]"), 23, "rungs = [5000, 15000, 45000]");
  const SweepSpec spec = parse_sweep_text(text, "x.toml");
  const Grid grid = expand_grid(spec);
  const SearchCost cost = estimate_search_cost(spec, grid);
  EXPECT_THAT(cost.configurations, ElementsAre(8, 4, 2));
  double full = 0.0, rung0 = 0.0;
  for (const Cell& c : grid.cells) {
    const int steps = grid.runs[static_cast<std::size_t>(c.runs.front())].training.steps;
    if (steps == 45000) full += c.estimated_cost_s;
    if (steps == 5000) rung0 += c.estimated_cost_s;
  }
  EXPECT_DOUBLE_EQ(cost.full_s, full);
  EXPECT_GT(cost.halving_s, rung0);
  EXPECT_LT(cost.halving_s, full);
  // eta = 1: every configuration at every rung, each going on from the one
  // before, the rungs before the last without inference: exactly the full
  // grid's cost (to round-off), though its lower rungs alone cost more.
  text.replace(text.find("eta = 2"), 7, "eta = 1");
  const SweepSpec all = parse_sweep_text(text, "x.toml");
  const Grid all_grid = expand_grid(all);
  const SearchCost every = estimate_search_cost(all, all_grid);
  EXPECT_THAT(every.configurations, ElementsAre(8, 8, 8));
  double lower = 0.0;
  for (const Cell& c : all_grid.cells) {
    if (all_grid.runs[static_cast<std::size_t>(c.runs.front())].training.steps < 45000) {
      lower += c.estimated_cost_s;
    }
  }
  EXPECT_NEAR(every.halving_s, every.full_s, 1e-9 * every.full_s);
  EXPECT_GT(lower, 0.0);
}

}  // namespace
}  // namespace phnn
