// tests/report/table_comparisons_test.cpp — compare_table_cells on a grid
// expanded from a sweep text: which comparisons a table makes (every pair of
// models in a column, every column against the first in a row), that each is
// compare_cells of the two cells' seeds, paired exactly where the runs share
// weights, batches and data (models of one kind, another integrator or
// regularizer: paired; another kind: unpaired), and that unfinished runs stay
// out.
#include "phnn/report/table_comparisons.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

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

}  // namespace
}  // namespace phnn
