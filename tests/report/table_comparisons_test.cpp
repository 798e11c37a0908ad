// tests/report/table_comparisons_test.cpp — compare_table_cells on a grid
// expanded from a sweep text: which comparisons a table makes (every pair of
// models in a column, every pair of columns in a row), that each is
// compare_cells of the two cells' seeds, paired exactly where the runs share
// weights, batches and data (models of one kind, another integrator or
// regularizer: paired; another kind: unpaired), and that unfinished runs stay
// out; entries_for_seeds' slots.
#include "phnn/report/table_comparisons.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

const char* kSweep = R"(name = "cmp"
[training]
steps = 10
[grid]
systems = ["duffing"]
models = ["phnn-s-rk2", "phnn-s-dg", "node-rk2"]
n_train = [25]
seeds = "0-5"
[study.III]
regularizers = ["none", "cn"]
)";

// A made-up MSE for run i: distinct, positive, with a model effect.
double mse_of(const RunConfig& run) {
  const double model = run.model == ModelKind::kNode ? 10.0 : 1.0;
  const double integrator = run.integrator == IntegratorKind::kDg ? 0.5 : 1.0;
  return model * integrator * (1.0 + 0.1 * run.seed) *
         (run.regularizer == Regularizer::kCn ? 2.0 : 1.0);
}

TEST(TableComparisonsTest, PairsOfModelsAndColumnsPairedWhereTheRunsShareTheirSeedEffect) {
  const Grid grid = expand_grid(parse_sweep_text(kSweep, "cmp.toml"));
  std::vector<RunStatus> status(grid.runs.size(), RunStatus::kDone);
  std::vector<double> mse;
  for (const RunConfig& run : grid.runs) mse.push_back(mse_of(run));
  status[0] = RunStatus::kPending;  // a pending run stays out of its cell
  const std::vector<TableEntry> entries = make_table_entries(grid, status, mse);
  const std::vector<NamedComparison> out = compare_table_cells(grid, entries);
  // One table (study III, duffing): 2 columns x 3 pairs of rows, then 3 rows x 1 column pair.
  ASSERT_EQ(out.size(), 9u);
  EXPECT_EQ(out[0].a, "III/duffing/PHNN-S-RK2/none");
  EXPECT_EQ(out[0].b, "III/duffing/PHNN-S-DG/none");
  EXPECT_EQ(out[8].a, "III/duffing/NODE-RK2/cn");
  EXPECT_EQ(out[8].b, "III/duffing/NODE-RK2/none");
  for (const NamedComparison& c : out) {
    const bool node_a = c.a.find("NODE") != std::string::npos;
    const bool node_b = c.b.find("NODE") != std::string::npos;
    EXPECT_EQ(c.comparison.paired, node_a == node_b) << c.a << " vs " << c.b;
    // The same comparison from the cells' seeds directly.
    SeedResults a, b;
    for (const TableEntry& e : entries) {
      if (e.status != RunStatus::kDone) continue;
      const std::string name = e.study + "/" + e.system + "/" + e.row + "/" + e.column;
      if (name == c.a) a[e.seed] = e.mse;
      if (name == c.b) b[e.seed] = e.mse;
    }
    const Comparison direct = compare_cells(a, b, c.comparison.paired);
    EXPECT_EQ(c.comparison.reading, direct.reading) << c.a << " vs " << c.b;
    EXPECT_EQ(c.comparison.effect, direct.effect) << c.a << " vs " << c.b;
    if (!c.comparison.paired) {
      EXPECT_EQ(c.comparison.n_a, static_cast<int>(a.size()));
      EXPECT_EQ(c.comparison.n_b, static_cast<int>(b.size()));
    }
  }
  // Every DG seed has half its RK2 pair's error: paired, 6 pairs (5 where run 0 is pending).
  EXPECT_EQ(out[0].comparison.reading, ComparisonReading::kBBetter);
  EXPECT_NEAR(out[0].comparison.effect, std::log10(2.0), 1e-12);
  EXPECT_LE(out[0].comparison.n_pairs, 6);
  EXPECT_GE(out[0].comparison.n_pairs, 5);
}

const char* kThreeColumns = R"(name = "cmp3"
[training]
steps = 10
[grid]
systems = ["duffing"]
models = ["phnn-s-rk2", "phnn-s-dg"]
seeds = "0-5"
[study.I]
n_train = [25, 100, 400]
)";

// Three columns: per column 1 pair of rows (3), per row the columns against
// the first, (100, 25) and (400, 25), then (400, 100) (2 rows x 3).
TEST(TableComparisonsTest, EveryPairOfColumnsOfARow) {
  const Grid grid = expand_grid(parse_sweep_text(kThreeColumns, "cmp3.toml"));
  std::vector<RunStatus> status(grid.runs.size(), RunStatus::kDone);
  std::vector<double> mse;
  for (const RunConfig& run : grid.runs) mse.push_back(mse_of(run) / run.n_train);
  const std::vector<NamedComparison> out =
      compare_table_cells(grid, make_table_entries(grid, status, mse));
  ASSERT_EQ(out.size(), 9u);
  EXPECT_EQ(out[3].a, "I/duffing/PHNN-S-RK2/100");
  EXPECT_EQ(out[3].b, "I/duffing/PHNN-S-RK2/25");
  EXPECT_EQ(out[5].a, "I/duffing/PHNN-S-RK2/400");
  EXPECT_EQ(out[5].b, "I/duffing/PHNN-S-RK2/100");
  EXPECT_EQ(out[8].a, "I/duffing/PHNN-S-DG/400");
  EXPECT_EQ(out[8].b, "I/duffing/PHNN-S-DG/100");
  // Every seed's error falls 4x from 100 to 400 points: A better (unpaired:
  // another N_train is other data; the two columns do not overlap).
  EXPECT_FALSE(out[5].comparison.paired);
  EXPECT_EQ(out[5].comparison.reading, ComparisonReading::kABetter);
}

// Slots: {3, 3, 0} gives slots 0 and 1 seed 3's runs, slot 2 seed 0's, in
// every cell; unlisted seeds drop out; pairs of slots compare as pairs.
TEST(EntriesForSeedsTest, SlotsHoldTheListedSeedsInEveryCell) {
  const Grid grid = expand_grid(parse_sweep_text(kSweep, "cmp.toml"));
  std::vector<RunStatus> status(grid.runs.size(), RunStatus::kDone);
  std::vector<double> mse;
  for (const RunConfig& run : grid.runs) mse.push_back(mse_of(run));
  const std::vector<TableEntry> entries = make_table_entries(grid, status, mse);
  const std::vector<TableEntry> slots = entries_for_seeds(entries, {3, 3, 0});
  std::size_t seed3 = 0, seed0 = 0;
  for (const TableEntry& e : entries) {
    if (e.seed == 3) ++seed3;
    if (e.seed == 0) ++seed0;
  }
  ASSERT_EQ(slots.size(), 2 * seed3 + seed0);
  for (const TableEntry& e : slots) {
    ASSERT_GE(e.seed, 0);
    ASSERT_LE(e.seed, 2);
    const int original = e.seed == 2 ? 0 : 3;
    EXPECT_EQ(grid.runs[static_cast<std::size_t>(e.run)].seed, original);
    EXPECT_EQ(e.mse, mse_of(grid.runs[static_cast<std::size_t>(e.run)]));
  }
  ComparisonOptions one_pair;
  one_pair.min_seeds = 1;
  const std::vector<NamedComparison> out = compare_table_cells(grid, slots, one_pair);
  ASSERT_FALSE(out.empty());
  EXPECT_TRUE(out[0].comparison.paired);
  EXPECT_EQ(out[0].comparison.n_pairs, 3);  // a seed drawn twice is two pairs
  EXPECT_TRUE(entries_for_seeds(entries, {99}).empty());
}

}  // namespace
}  // namespace phnn
