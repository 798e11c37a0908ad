// tests/report/tables_test.cpp
#include "phnn/report/tables.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// Quantiles of a handful of values: a few ulps of round-off at most.
constexpr double kQuantileTolerance = 1e-12;
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(QuantileTest, MatchesNumpyLinearOnEvenCount) {
  // numpy.quantile([1, 2, 3, 4], [.25, .5, .75]) = [1.75, 2.5, 3.25].
  const std::vector<double> values = {4.0, 1.0, 3.0, 2.0};
  EXPECT_NEAR(quantile_linear(values, 0.25), 1.75, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear(values, 0.5), 2.5, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear(values, 0.75), 3.25, kQuantileTolerance);
  EXPECT_EQ(quantile_linear(values, 0.0), 1.0);
  EXPECT_EQ(quantile_linear(values, 1.0), 4.0);
}

TEST(QuantileTest, MatchesNumpyLinearOnOddCount) {
  // h = 2 q: [5, 1, 3] -> q25 = 1 + 0.5 (3 - 1) = 2, median 3, q75 = 4.
  EXPECT_NEAR(quantile_linear({5.0, 1.0, 3.0}, 0.25), 2.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({5.0, 1.0, 3.0}, 0.5), 3.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({5.0, 1.0, 3.0}, 0.75), 4.0, kQuantileTolerance);
  // h = 4 q lands on elements: [1, 2, 3, 4, 10] -> 2, 3, 4.
  EXPECT_NEAR(quantile_linear({10.0, 1.0, 2.0, 3.0, 4.0}, 0.25), 2.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({10.0, 1.0, 2.0, 3.0, 4.0}, 0.5), 3.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({10.0, 1.0, 2.0, 3.0, 4.0}, 0.75), 4.0, kQuantileTolerance);
  EXPECT_EQ(quantile_linear({7.0}, 0.25), 7.0);
}

TEST(QuantileTest, RejectsEmptyValuesAndQOutsideUnitInterval) {
  EXPECT_THROW(quantile_linear({}, 0.5), std::invalid_argument);
  EXPECT_THROW(quantile_linear({1.0}, 1.5), std::invalid_argument);
  EXPECT_THROW(quantile_linear({1.0}, -0.1), std::invalid_argument);
  EXPECT_THROW(quantile_linear({1.0, std::nan("")}, 0.5), std::invalid_argument);
}

TEST(TableFormatTest, ParsesTheThreeFormatsAndListsThemOnError) {
  EXPECT_EQ(parse_table_format("markdown"), TableFormat::kMarkdown);
  EXPECT_EQ(parse_table_format("latex"), TableFormat::kLatex);
  EXPECT_EQ(parse_table_format("csv"), TableFormat::kCsv);
  EXPECT_THAT([] { parse_table_format("html"); },
              testing::ThrowsMessage<std::invalid_argument>(
                  HasSubstr("\"html\"; expected one of: markdown, latex, csv")));
}

// A 2 x 2 table, 5 seeds per cell:
//            25                              100
// NODE-RK2   1..5e-3 (done)                  5,6,7e-3 + pending + failed
// PHNN-JR-DG 1,2,3e-4 + 2 diverged           (nothing)
class TableTest : public ::testing::Test {
 protected:
  void SetUp() override {
    study_.name = "I";
    study_.title = "Impact of the number of training points";
    study_.varied_axis = "n_train";
    study_.columns = {"25", "100"};
    study_.rows = {"NODE-RK2", "PHNN-JR-DG"};
    study_.systems = {SystemKind::kHarmonic};
    for (double mse : {3e-3, 1e-3, 5e-3, 2e-3, 4e-3}) add("NODE-RK2", "25", RunStatus::kDone, mse);
    for (double mse : {2e-4, 1e-4, 3e-4}) add("PHNN-JR-DG", "25", RunStatus::kDone, mse);
    add("PHNN-JR-DG", "25", RunStatus::kDiverged, kInf);
    add("PHNN-JR-DG", "25", RunStatus::kDiverged, kInf);
    for (double mse : {7e-3, 5e-3, 6e-3}) add("NODE-RK2", "100", RunStatus::kDone, mse);
    add("NODE-RK2", "100", RunStatus::kPending, 0.0);
    add("NODE-RK2", "100", RunStatus::kFailed, 0.0);
    // Not in the table: another study, another system.
    add("NODE-RK2", "25", RunStatus::kDone, 1e-9, "II");
    add("NODE-RK2", "25", RunStatus::kDone, 1e-9, "I", SystemKind::kDuffing);
  }

  void add(const std::string& row, const std::string& column, RunStatus status, double mse,
           const std::string& study = "I", SystemKind system = SystemKind::kHarmonic) {
    entries_.push_back(TableEntry{study, system, row, column, status, mse});
  }

  std::string render(TableFormat format) const {
    return render_tables({study_}, entries_, format, /*expected_seeds=*/5);
  }

  StudyTable study_;
  std::vector<TableEntry> entries_;
};

TEST_F(TableTest, MarkdownShowsMedianIqrBestDivergedAndMissing) {
  // NODE-RK2/25: median 3e-3, q25 2e-3, q75 4e-3, IQR 2e-3.
  // PHNN-JR-DG/25: {1, 2, 3}e-4 + 2 x inf -> median 3e-4, q25 2e-4, q75 inf: best.
  // NODE-RK2/100: {5, 6, 7}e-3 -> 6e-3 [1e-3], 3 of 5 finished; best (alone).
  EXPECT_EQ(render(TableFormat::kMarkdown),
            "### Study I — harmonic (columns: n_train)\n"
            "\n"
            "*Impact of the number of training points*\n"
            "\n"
            "| model | 25 | 100 |\n"
            "|---|---|---|\n"
            "| NODE-RK2 | 3.00e-03 [2.00e-03] | **6.00e-03 [1.00e-03]** (n=3/5) |\n"
            "| PHNN-JR-DG | **3.00e-04 [inf]** (d=2) | — |\n"
            "\n");
}

TEST_F(TableTest, LatexBoldsTheBestAndEscapesLabels) {
  const std::string latex = render(TableFormat::kLatex);
  EXPECT_THAT(latex, HasSubstr("\\begin{tabular}{lcc}"));
  EXPECT_THAT(latex, HasSubstr("Study I --- harmonic (columns: n\\_train)"));
  EXPECT_THAT(latex, HasSubstr("Model & 25 & 100 \\\\"));
  EXPECT_THAT(latex, HasSubstr("NODE-RK2 & 3.00e-03 [2.00e-03] & \\textbf{6.00e-03 [1.00e-03]} "
                               "(n=3/5) \\\\"));
  EXPECT_THAT(latex, HasSubstr("PHNN-JR-DG & \\textbf{3.00e-04 [inf]} (d=2) & -- \\\\"));
  EXPECT_THAT(latex, Not(HasSubstr("—")));
  EXPECT_THAT(latex, HasSubstr("\\end{table}"));
}

TEST_F(TableTest, CsvHasOneLinePerCellWithABestColumn) {
  const std::string csv = render(TableFormat::kCsv);
  EXPECT_THAT(csv, StartsWith("study,system,model,axis,column,median,q25,q75,iqr,done,diverged,"
                              "missing,expected,best\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,25,3.000000e-03,2.000000e-03,"
                             "4.000000e-03,2.000000e-03,5,0,0,5,0\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,PHNN-JR-DG,n_train,25,3.000000e-04,2.000000e-04,"
                             "inf,inf,3,2,0,5,1\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,100,6.000000e-03,5.500000e-03,"
                             "6.500000e-03,1.000000e-03,3,0,2,5,1\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,PHNN-JR-DG,n_train,100,,,,,0,0,5,5,0\n"));
  // Header + 4 cells.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
}

TEST_F(TableTest, AllDivergedCellShowsDashAndCount) {
  entries_.clear();
  for (int i = 0; i < 5; ++i) add("NODE-RK2", "25", RunStatus::kDiverged, kInf);
  const std::string markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | — (d=5) | — |"));
}

TEST_F(TableTest, TiedBestMediansAreAllMarked) {
  entries_.clear();
  add("NODE-RK2", "25", RunStatus::kDone, 1e-3);
  add("PHNN-JR-DG", "25", RunStatus::kDone, 1e-3);
  const std::string markdown = render_tables({study_}, entries_, TableFormat::kMarkdown, 1);
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | **1.00e-03 [0.00e+00]** | — |"));
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | **1.00e-03 [0.00e+00]** | — |"));
}

TEST(CellSummaryTest, CountsDoneDivergedAndMissing) {
  std::vector<TableEntry> entries(4);
  entries[0].status = RunStatus::kDone;
  entries[0].mse = 1.0;
  entries[1].status = RunStatus::kDone;
  entries[1].mse = kInf;  // done but non-finite counts as diverged
  entries[2].status = RunStatus::kDiverged;
  entries[2].mse = kInf;
  entries[3].status = RunStatus::kFailed;
  const CellSummary s = summarize_cell(entries, /*expected_seeds=*/10);
  EXPECT_EQ(s.done, 1);
  EXPECT_EQ(s.diverged, 2);
  EXPECT_EQ(s.missing, 7);
  EXPECT_EQ(s.expected, 10);
  // Diverged runs count as +inf (SPEC.md §5): {1, inf, inf} has median inf.
  EXPECT_EQ(s.median, kInf);
  EXPECT_EQ(s.q25, kInf);  // numpy: 1 + 0.5 (inf - 1)
}

TEST(TableEntriesTest, OneEntryPerRunAndStudyFromTheGrid) {
  const Grid grid = expand_grid(parse_sweep_text(R"(name = "e"
[grid]
systems = ["harmonic"]
models = ["node-rk2", "phnn-s-dg"]
seeds = [0, 1]
[study.a]
n_train = [25, 50]
[study.b]
sizes = ["small", "medium"]
)",
                                                 "e.toml"));
  ASSERT_EQ(grid.runs.size(), 12u);  // 8 + 8 - 4 shared
  std::vector<RunStatus> status(grid.runs.size(), RunStatus::kDone);
  std::vector<double> mse(grid.runs.size(), 1e-3);
  const std::vector<TableEntry> entries = make_table_entries(grid, status, mse);
  EXPECT_EQ(entries.size(), 16u);
  EXPECT_EQ(entries[0].study, "a");
  EXPECT_EQ(entries[0].row, "NODE-RK2");
  EXPECT_EQ(entries[0].column, "25");
  EXPECT_EQ(entries.back().study, "b");
  EXPECT_EQ(entries.back().row, "PHNN-S-DG");
  EXPECT_EQ(entries.back().column, "medium");
  const std::string markdown =
      render_tables(grid.studies, entries, TableFormat::kMarkdown, /*expected_seeds=*/2);
  EXPECT_THAT(markdown, HasSubstr("### Study a — harmonic (columns: n_train)"));
  EXPECT_THAT(markdown, HasSubstr("### Study b — harmonic (columns: size)"));
  EXPECT_THAT(markdown, HasSubstr("| model | small | medium |"));
  EXPECT_THAT(markdown, Not(HasSubstr("(n=")));
  status.pop_back();
  EXPECT_THROW(make_table_entries(grid, status, mse), std::invalid_argument);
}

}  // namespace
}  // namespace phnn
