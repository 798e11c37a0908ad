// tests/sweep/grid_test.cpp — run ids, cells, costs and columns of expanded grids.
// Size: one test file per module; the pinned ids and ablation files are its contract.
#include "phnn/sweep/grid.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <sstream>
#include <string>

#include "phnn/sweep/work_plan.h"  // dry_run_summary

namespace phnn {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const std::string kSweeps = std::string(PHNN_SOURCE_DIR) + "/sweeps/";

// Cost-model results are sums of a few products of exact binary fractions.
constexpr double kCostTolerance = 1e-9;

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

Grid paper_grid() { return expand_grid(parse_sweep_file(kSweeps + "paper.toml")); }

TEST(GridTest, PaperSweepIs1200RunsIn120Cells) {
  const Grid grid = paper_grid();
  EXPECT_EQ(first_line(dry_run_summary(grid, /*ranks=*/{64})), "1200 runs in 120 cells");
  ASSERT_EQ(grid.runs.size(), 1200u);
  ASSERT_EQ(grid.cells.size(), 120u);
  ASSERT_EQ(grid.run_studies.size(), 1200u);
  std::set<int> covered;
  for (const Cell& cell : grid.cells) {
    ASSERT_EQ(cell.runs.size(), 10u) << cell.key;
    for (std::size_t i = 0; i < cell.runs.size(); ++i) {
      EXPECT_EQ(grid.runs[cell.runs[i]].seed, static_cast<int>(i)) << "seeds sorted 0..9";
      EXPECT_EQ(grid.runs[cell.runs[i]].cell_key(), cell.key);
      covered.insert(cell.runs[i]);
    }
  }
  EXPECT_EQ(covered.size(), 1200u) << "every run is in exactly one cell";
}

TEST(GridTest, PaperRunIdsAreUnique) {
  const Grid grid = paper_grid();
  std::set<std::string> ids, canonicals;
  for (const RunConfig& run : grid.runs) {
    ids.insert(run.id());
    canonicals.insert(run.canonical());
  }
  EXPECT_EQ(ids.size(), 1200u);
  EXPECT_EQ(canonicals.size(), 1200u);
}

TEST(GridTest, PaperStudiesHaveTheSpecRunCounts) {
  const Grid grid = paper_grid();
  ASSERT_EQ(grid.studies.size(), 3u);
  EXPECT_EQ(grid.studies[0].runs.size(), 450u);  // 3 systems x 5 models x 3 n_train x 10
  EXPECT_EQ(grid.studies[1].runs.size(), 450u);  // 3 x 5 x 3 sizes x 10
  EXPECT_EQ(grid.studies[2].runs.size(), 600u);  // 3 x 5 x 4 regularizers x 10
  std::set<int> all;
  for (const StudyTable& study : grid.studies) {
    EXPECT_EQ(std::set<int>(study.runs.begin(), study.runs.end()).size(), study.runs.size());
    all.insert(study.runs.begin(), study.runs.end());
  }
  EXPECT_EQ(all.size(), 1200u);
  const std::string summary = dry_run_summary(grid, /*ranks=*/{8});
  EXPECT_THAT(summary, HasSubstr("study I: 450 runs in 45 cells"));
  EXPECT_THAT(summary, HasSubstr("study II: 450 runs in 45 cells"));
  EXPECT_THAT(summary, HasSubstr("study III: 600 runs in 60 cells"));
}

TEST(GridTest, SharedRunIsTrainedOnceAndListsEveryStudy) {
  const Grid grid = paper_grid();
  // small, n_train 25, no regularizer: in Studies I, II and III.
  int shared = 0;
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    const RunConfig& run = grid.runs[i];
    const bool in_all =
        run.size == ModelSize::kSmall && run.n_train == 25 && run.regularizer == Regularizer::kNone;
    if (in_all) {
      EXPECT_THAT(grid.run_studies[i], ElementsAre("I", "II", "III"));
      ++shared;
    } else {
      EXPECT_EQ(grid.run_studies[i].size(), 1u);
    }
  }
  EXPECT_EQ(shared, 150);  // 3 systems x 5 models x 10 seeds
  // The first run is the first of Study I, nested system, model, ..., seed.
  EXPECT_EQ(grid.runs[0].system, SystemKind::kHarmonic);
  EXPECT_EQ(grid.runs[0].model, ModelKind::kNode);
  EXPECT_EQ(grid.runs[0].seed, 0);
  EXPECT_EQ(grid.runs[1].seed, 1);
  EXPECT_EQ(grid.runs[10].n_train, 100);
}

TEST(GridTest, StudyTablesHaveTheVariedAxisAsColumns) {
  const Grid grid = paper_grid();
  const std::vector<std::string> models = {"NODE-RK2", "PHNN-JR-DG", "PHNN-JR-RK2", "PHNN-S-DG",
                                           "PHNN-S-RK2"};
  EXPECT_EQ(grid.studies[0].varied_axis, "n_train");
  EXPECT_THAT(grid.studies[0].columns, ElementsAre("25", "100", "400"));
  EXPECT_EQ(grid.studies[1].varied_axis, "size");
  EXPECT_THAT(grid.studies[1].columns, ElementsAre("small", "medium", "large"));
  EXPECT_EQ(grid.studies[2].varied_axis, "regularizer");
  EXPECT_THAT(grid.studies[2].columns, ElementsAre("none", "cn", "sn", "sr"));
  for (const StudyTable& study : grid.studies) {
    EXPECT_EQ(study.rows, models);
    EXPECT_EQ(study.systems.size(), 3u);
    ASSERT_EQ(study.run_columns.size(), study.runs.size());
  }
  EXPECT_EQ(grid.studies[0].title, "Impact of the number of training points");
  // Column of a run follows its varied value.
  const StudyTable& study_i = grid.studies[0];
  for (std::size_t i = 0; i < study_i.runs.size(); ++i) {
    EXPECT_EQ(study_i.run_columns[i], std::to_string(grid.runs[study_i.runs[i]].n_train));
  }
}

TEST(GridTest, ExpansionIsDeterministic) {
  const SweepSpec spec = parse_sweep_file(kSweeps + "paper.toml");
  const Grid a = expand_grid(spec), b = expand_grid(spec);
  ASSERT_EQ(a.runs.size(), b.runs.size());
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    EXPECT_EQ(a.runs[i].canonical(), b.runs[i].canonical());
  }
  ASSERT_EQ(a.cells.size(), b.cells.size());
  for (std::size_t c = 0; c < a.cells.size(); ++c) {
    EXPECT_EQ(a.cells[c].key, b.cells[c].key);
    EXPECT_EQ(a.cells[c].runs, b.cells[c].runs);
  }
  EXPECT_EQ(dry_run_summary(a, {16}), dry_run_summary(b, {16}));
  // And from a fresh parse.
  const Grid c = paper_grid();
  EXPECT_EQ(c.runs.back().canonical(), a.runs.back().canonical());
}

TEST(GridTest, RunIdIsStableForAFixedConfig) {
  const Grid grid = paper_grid();
  const RunConfig& run = grid.runs[0];
  // Written by hand from the defaults of docs/METHOD.md: changing the canonical form
  // changes every run id and orphans existing results files.
  EXPECT_THAT(run.canonical(),
              StartsWith("system=harmonic;model=node;integrator=rk2;size=small;n_train=25;"
                         "regularizer=none;mass=0.16;stiffness=6.25;damping=0.14736"));
  EXPECT_THAT(run.canonical(), HasSubstr(";steps=50000;lr=0.001;"));
  EXPECT_THAT(run.canonical(), testing::EndsWith(";seed=0"));
  EXPECT_EQ(run.id(), hex64(fnv1a64(run.canonical())));
  // Published FNV-1a 64 test vector (Fowler, Noll, Vo): "a" -> af63dc4c8601ec8c.
  EXPECT_EQ(hex64(fnv1a64("a")), "af63dc4c8601ec8c");
}

// Every run id of every sweep file of sweeps/ at the time the ablation knobs
// (lambdas, loss_norm, dg_structure_point, energy_sampling) were added:
// their defaults must leave each canonical string byte-identical, or every
// existing results file would be orphaned. Digest = FNV-1a 64 of the ids of
// the file, one per line, in grid order.
TEST(GridTest, RunIdsOfTheShippedSweepsArePinned) {
  const Grid paper = paper_grid();
  EXPECT_EQ(paper.runs[0].id(), "fe1820216e4cb749");
  const std::vector<std::pair<std::string, std::string>> pinned = {
      {"paper.toml", "980f15989e65ba06"},         {"paper-table-damping.toml", "fb94529be8d2ca03"},
      {"paper-slice.toml", "86a0087e8cbaec74"},   {"fourth-order.toml", "82df5d4bc81062db"},
      {"time-vs-error.toml", "d68043d7c59b2363"},
      {"demo.toml", "69d411543944e1ff"},  // seeds 0-9 since 2026-11-28 (0-4: 3bf45058d8d33d5c; 0-1: bd0409c560e222b9)
      {"tiny.toml", "be8e6b56ff2112e5"}};
  for (const auto& [file, digest] : pinned) {
    std::string ids;
    for (const RunConfig& run : expand_grid(parse_sweep_file(kSweeps + file)).runs) {
      ids += run.id() + "\n";
    }
    EXPECT_EQ(hex64(fnv1a64(ids)), digest) << file;
  }
}

TEST(GridTest, CellsAreOrderedByCostLargestFirstThenKey) {
  const Grid grid = paper_grid();
  for (std::size_t c = 1; c < grid.cells.size(); ++c) {
    const Cell& prev = grid.cells[c - 1];
    const Cell& cell = grid.cells[c];
    EXPECT_TRUE(prev.estimated_cost_s > cell.estimated_cost_s ||
                (prev.estimated_cost_s == cell.estimated_cost_s && prev.key < cell.key))
        << c;
  }
  // Large models cost most: the first cell is a large PHNN (its networks
  // carry jets; NODE's do not).
  const RunConfig& first = grid.runs[grid.cells.front().runs.front()];
  EXPECT_EQ(first.size, ModelSize::kLarge);
  EXPECT_NE(first.model, ModelKind::kNode);
  double total = 0.0;
  for (const Cell& cell : grid.cells) total += cell.estimated_cost_s;
  EXPECT_NEAR(grid.estimated_cost_s, total, kCostTolerance * total);
}

TEST(GridTest, GroupCostFollowsTheDocumentedModel) {
  // The formula, with fixed constants (the defaults are placeholders to refit).
  const int jr = static_cast<int>(ModelKind::kPhnnJr), node = static_cast<int>(ModelKind::kNode);
  const int dg = static_cast<int>(IntegratorKind::kDg),
            rk2 = static_cast<int>(IntegratorKind::kRk2);
  CostModel model;
  model.fixed_us[jr][dg] = 500.0;
  model.member_us[jr][dg] = 100.0;
  model.fixed_us[node][rk2] = 40.0;
  model.member_us[node][rk2] = 30.0;
  model.fixed_size_factor[static_cast<int>(ModelSize::kLarge)] = 2.0;
  model.member_size_factor[static_cast<int>(ModelSize::kLarge)] = 10.0;
  model.regularizer_factor[node][rk2] = 1.6;
  model.regularizer_fixed_factor[node][rk2] = 2.0;
  model.float32_factor = 3.0;
  model.small_batch_saving = 0.0;  // the hand computation below is for full batches
  model.rollout_speedup = 20.0;
  model.dg_newton_factor = 4.0;
  RunConfig run;  // docs/METHOD.md defaults: 50000 steps, eval every 500, 2500 / 100 x 500
  run.model = ModelKind::kPhnnJr;
  run.integrator = IntegratorKind::kDg;
  // fixed  = 50000 x 500e-6 = 25 s;
  // member = (50000 + 101 x 2500/64 + 100 x 500 / 64 / 20 x 4) x 100e-6
  //        = (50000 + 3945.3125 + 156.25) x 100e-6 = 5.41015625 s.
  EXPECT_NEAR(estimate_group_cost_s(run, 1, model), 30.41015625, kCostTolerance);
  EXPECT_NEAR(estimate_group_cost_s(run, 3, model), 41.23046875, kCostTolerance);
  run.model = ModelKind::kNode;
  run.integrator = IntegratorKind::kRk2;
  run.size = ModelSize::kLarge;
  run.regularizer = Regularizer::kCn;
  // fixed  = 50000 x 40 x 2 x 2.0e-6 = 8 s (the regularizer's fixed factor);
  // member = (50000 + 3945.3125 + 39.0625) x 30 x 10 x 1.6e-6 = 25.9125 s.
  EXPECT_NEAR(estimate_group_cost_s(run, 10, model), 8.0 + 259.125, kCostTolerance);
  run.training.steps = 1050;  // evaluations at 0, 500, 1000 and 1050
  // 1050 x 160e-6 + 2 x (1050 + 4 x 2500/64 + 39.0625) x 480e-6 = 0.168 + 1.1955 s.
  EXPECT_NEAR(estimate_group_cost_s(run, 2, model), 1.3635, kCostTolerance);
  // float32 training: the training steps and validation x 3, the (float64) inference not:
  // 3 x 0.168 + 2 x (3 x (1050 + 4 x 2500/64) + 39.0625) x 480e-6 = 0.504 + 3.5115 s.
  run.training.precision = Precision::kFloat32;
  EXPECT_NEAR(estimate_group_cost_s(run, 2, model), 4.0155, kCostTolerance);
  EXPECT_THROW(estimate_group_cost_s(run, 0, model), std::invalid_argument);
}

TEST(GridTest, CellCostIsOneStackOfItsRunsAndStacksAreCheaperPerMember) {
  const Grid grid = paper_grid();
  for (const Cell& cell : grid.cells) {
    const RunConfig& head = grid.runs[cell.runs.front()];
    EXPECT_NEAR(cell.estimated_cost_s, estimate_group_cost_s(head, 10),
                kCostTolerance * cell.estimated_cost_s);
    EXPECT_NEAR(cell.cost_s(3), estimate_group_cost_s(head, 3), kCostTolerance * cell.cost_s(3));
    // The fixed per-step cost: ten single runs cost more than one stack.
    EXPECT_GT(10 * cell.cost_s(1), cell.cost_s(10)) << cell.key;
  }
}

TEST(GridTest, GreedyMakespanGivesLargestFirstToTheFirstFreeRank) {
  // 5 -> r0, 4 -> r1, 3 -> r1 (7), 3 -> r0 (8), 3 -> r1 (10).
  EXPECT_DOUBLE_EQ(greedy_makespan_s({3, 5, 3, 4, 3}, /*ranks=*/2), 10.0);
  EXPECT_DOUBLE_EQ(greedy_makespan_s({3, 5, 3, 4, 3}, /*ranks=*/1), 18.0);
  EXPECT_DOUBLE_EQ(greedy_makespan_s({3, 5, 3, 4, 3}, /*ranks=*/10), 5.0);
  EXPECT_THROW(greedy_makespan_s({1.0}, 0), std::invalid_argument);
}

TEST(GridTest, TableDampingPresetChangesOnlyTheDampedSystems) {
  const Grid paper = paper_grid();
  const Grid table = expand_grid(parse_sweep_file(kSweeps + "paper-table-damping.toml"));
  ASSERT_EQ(table.runs.size(), 1200u);
  ASSERT_EQ(table.cells.size(), 120u);
  for (std::size_t i = 0; i < paper.runs.size(); ++i) {
    const bool damped = paper.runs[i].system != SystemKind::kSelfSustained;
    EXPECT_EQ(paper.runs[i].id() != table.runs[i].id(), damped) << i;
  }
}

TEST(GridTest, DemoAndTinySweepsAreSmall) {
  const Grid demo = expand_grid(parse_sweep_file(kSweeps + "demo.toml"));
  EXPECT_EQ(first_line(dry_run_summary(demo, {2})), "200 runs in 20 cells");
  ASSERT_EQ(demo.studies.size(), 2u);
  EXPECT_EQ(demo.studies[0].varied_axis, "");
  EXPECT_THAT(demo.studies[0].columns, ElementsAre("MSE"));
  EXPECT_EQ(demo.studies[1].varied_axis, "regularizer");
  EXPECT_THAT(demo.studies[1].systems, ElementsAre("harmonic"));
  const Grid tiny = expand_grid(parse_sweep_file(kSweeps + "tiny.toml"));
  EXPECT_EQ(first_line(dry_run_summary(tiny, {1})), "6 runs in 2 cells");
  EXPECT_THAT(tiny.studies[0].rows, ElementsAre("PHNN-JR-RK2", "NODE-RK2"));
}

// `lambdas` multiplies the regularized runs only, sets the weight of their
// own regularizer, and gives each weight its own column (and cell).
TEST(GridTest, LambdasMultiplyRegularizedRunsIntoTheirOwnColumns) {
  const SweepSpec spec = parse_sweep_text(R"(name = "lambdas"
[grid]
systems = ["duffing"]
models = ["phnn-s-dg", "phnn-s-rk2"]
regularizers = ["none", "cn", "sr"]
lambdas = [1e-6, 1e-5]
seeds = [0, 1]
)",
                                          "lambdas.toml");
  const Grid grid = expand_grid(spec);
  EXPECT_EQ(grid.runs.size(), 2u * (1 + 2 + 2) * 2);
  EXPECT_EQ(grid.cells.size(), 2u * (1 + 2 + 2));
  const StudyTable& table = grid.studies[0];
  EXPECT_EQ(table.varied_axis, "regularizer/lambda");
  EXPECT_THAT(table.columns, ElementsAre("none", "cn/lambda=1e-06", "cn/lambda=1e-05",
                                         "sr/lambda=1e-06", "sr/lambda=1e-05"));
  const TrainerOptions defaults;
  for (std::size_t i = 0; i < table.runs.size(); ++i) {
    const RunConfig& run = grid.runs[table.runs[i]];
    const std::string& column = table.run_columns[i];
    const double weight = column.find("1e-05") != std::string::npos ? 1e-5 : 1e-6;
    EXPECT_EQ(run.training.lambda_cn,
              run.regularizer == Regularizer::kCn ? weight : defaults.lambda_cn);
    EXPECT_EQ(run.training.lambda_sr,
              run.regularizer == Regularizer::kSr ? weight : defaults.lambda_sr);
    EXPECT_EQ(run.training.lambda_sn, defaults.lambda_sn);
  }
  // No table cell (system, model, column) holds two runs of one seed.
  std::set<std::string> seen;
  for (std::size_t i = 0; i < table.runs.size(); ++i) {
    const RunConfig& run = grid.runs[table.runs[i]];
    EXPECT_TRUE(seen.insert(model_key(run.model, run.integrator) + "|" + table.run_columns[i] +
                            "|" + std::to_string(run.seed))
                    .second);
  }
}

// One weight is a replacement, not an axis: no column part; and a weight
// that does not read back from 6 digits still gets a label of its own.
TEST(GridTest, OneLambdaReplacesTheWeightAndCloseLambdasKeepDistinctLabels) {
  const std::string head =
      "name = \"l\"\n[grid]\nsystems = [\"harmonic\"]\n"
      "models = [\"node-rk2\"]\nregularizers = [\"sn\"]\nseeds = [0]\n";
  const Grid one = expand_grid(parse_sweep_text(head + "lambdas = [3e-6]\n", "l.toml"));
  ASSERT_EQ(one.runs.size(), 1u);
  EXPECT_EQ(one.runs[0].training.lambda_sn, 3e-6);
  EXPECT_THAT(one.studies[0].columns, ElementsAre("MSE"));
  EXPECT_THAT(one.runs[0].cell_key(), HasSubstr(";lambda=3.0000000000000001e-06;"));
  const Grid close =
      expand_grid(parse_sweep_text(head + "lambdas = [1e-6, 1.0000001e-6, 0]\n", "l.toml"));
  EXPECT_THAT(close.studies[0].columns,
              ElementsAre("lambda=1e-06", "lambda=1.0000001e-06", "lambda=0"));
}

// Sweep file `file` without its one-knob `line` is `*stripped`: the same
// runs in the same order, each cell key exactly `key_part` shorter.
void expect_only_the_knob_differs(const std::string& file, const std::string& line,
                                  const std::string& key_part, Grid* stripped) {
  const SweepSpec spec = parse_sweep_file(kSweeps + file);
  std::string text = spec.text;
  ASSERT_NE(text.find(line), std::string::npos) << file;
  text.erase(text.find(line), line.size());
  const Grid ablation = expand_grid(spec);
  *stripped = expand_grid(parse_sweep_text(text, "stripped.toml"));
  ASSERT_EQ(ablation.runs.size(), stripped->runs.size()) << file;
  for (std::size_t i = 0; i < ablation.runs.size(); ++i) {
    std::string key = ablation.runs[i].cell_key();
    const std::size_t at = key.find(key_part);
    ASSERT_NE(at, std::string::npos) << file << " run " << i;
    key.erase(at, key_part.size());
    EXPECT_EQ(key, stripped->runs[i].cell_key()) << file << " run " << i;
  }
}

// An ablation file of sweeps/ changes one knob of its baseline file by one
// line: without that line its runs are exactly the baseline's (whose seeds
// 0-9 are paper.toml's own), and with it each cell key differs by exactly
// `key_part`.
void expect_one_knob_ablation(const std::string& file, const std::string& line,
                              const std::string& key_part,
                              const std::string& baseline_file = "ablation-duffing-baseline.toml") {
  Grid stripped;
  ASSERT_NO_FATAL_FAILURE(expect_only_the_knob_differs(file, line, key_part, &stripped));
  const Grid baseline = expand_grid(parse_sweep_file(kSweeps + baseline_file));
  ASSERT_EQ(stripped.runs.size(), 240u);
  ASSERT_EQ(baseline.runs.size(), 240u);
  std::set<std::string> paper_ids;
  for (const RunConfig& run : paper_grid().runs) paper_ids.insert(run.id());
  for (std::size_t i = 0; i < 240; ++i) {
    EXPECT_EQ(stripped.runs[i].id(), baseline.runs[i].id()) << file << " run " << i;
    EXPECT_EQ(paper_ids.count(baseline.runs[i].id()), baseline.runs[i].seed < 10 ? 1u : 0u) << i;
  }
}

TEST(GridTest, AblationDuffingSweepChangesOnlyTheLossNorm) {
  expect_one_knob_ablation("ablation-duffing.toml", "loss_norm = \"mse\"\n", ";loss_norm=mse");
}

TEST(GridTest, AblationHarmonicSweepChangesOnlyTheEnergySampling) {
  expect_one_knob_ablation("ablation-harmonic-direct.toml", "energy_sampling = \"direct\"\n",
                           ";energy_sampling=direct", "ablation-harmonic-baseline.toml");
}

TEST(GridTest, AblationSelfSustainedSweepChangesOnlyTheEnergySampling) {
  expect_one_knob_ablation("ablation-self-sustained-direct.toml", "energy_sampling = \"direct\"\n",
                           ";energy_sampling=direct", "ablation-self-sustained-baseline.toml");
}

// Without its [training] line, the Study II ablation's runs are exactly the
// paper grid's Study II runs (results/paper.h5 is its baseline); with it,
// every cell key carries ";inference_weights=final".
TEST(GridTest, AblationStudy2SweepIsStudyTwoWithFinalWeights) {
  Grid stripped;
  ASSERT_NO_FATAL_FAILURE(expect_only_the_knob_differs("ablation-study2-final.toml",
                                                       "inference_weights = \"final\"\n",
                                                       ";inference_weights=final", &stripped));
  const Grid paper = paper_grid();
  std::set<std::string> study2;
  for (const StudyTable& study : paper.studies) {
    if (study.name != "II") continue;
    for (int r : study.runs) study2.insert(paper.runs[static_cast<std::size_t>(r)].id());
  }
  ASSERT_EQ(study2.size(), 450u);
  ASSERT_EQ(stripped.runs.size(), 450u);
  std::set<std::string> stripped_ids;
  for (const RunConfig& run : stripped.runs) stripped_ids.insert(run.id());
  EXPECT_EQ(stripped_ids, study2);
}

// A CN-weight study: `models` x (none + CN at 5 weights) x 30 seeds; its
// runs at the paper's lambda_CN = 1e-6 (and without regularizer) with seeds
// 0-9 are paper.toml's own runs, the other weights are new.
void expect_lambda_cn_study(const std::string& file, std::size_t models) {
  SCOPED_TRACE(file);
  const Grid grid = expand_grid(parse_sweep_file(kSweeps + file));
  ASSERT_EQ(grid.runs.size(), models * 6 * 30);
  ASSERT_EQ(grid.cells.size(), models * 6);
  std::set<std::string> paper_ids;
  for (const RunConfig& run : paper_grid().runs) paper_ids.insert(run.id());
  std::size_t shared = 0;
  for (const RunConfig& run : grid.runs) {
    const bool papers_weight =
        run.regularizer == Regularizer::kNone || run.training.lambda_cn == 1e-6;
    const bool expected = papers_weight && run.seed < 10;
    EXPECT_EQ(paper_ids.count(run.id()) == 1, expected) << run.cell_key() << " seed " << run.seed;
    shared += expected;
  }
  EXPECT_EQ(shared, models * 2 * 10);  // (none, CN 1e-6) x 10 seeds per model
}

TEST(GridTest, LambdaCnSweepsShareThePapersRunsAtItsWeight) {
  expect_lambda_cn_study("ablation-duffing-lambda-cn.toml", 4);
  expect_lambda_cn_study("ablation-harmonic-lambda-cn.toml", 5);
}

TEST(GridTest, AblationDuffingFloat32SweepChangesOnlyThePrecision) {
  expect_one_knob_ablation("ablation-duffing-float32.toml", "precision = \"float32\"\n",
                           ";precision=float32");
}

TEST(GridTest, SeveralVariedAxesGiveProductColumns) {
  const Grid grid = expand_grid(parse_sweep_text(R"(name = "two"
[grid]
systems = ["duffing"]
models = ["phnn-s-dg"]
sizes = ["small", "medium"]
n_train = [25, 50]
seeds = [0]
)",
                                                 "two.toml"));
  EXPECT_EQ(grid.studies[0].varied_axis, "size/n_train");
  EXPECT_THAT(grid.studies[0].columns,
              ElementsAre("small/25", "small/50", "medium/25", "medium/50"));
  EXPECT_EQ(grid.runs.size(), 4u);
}

}  // namespace
}  // namespace phnn
