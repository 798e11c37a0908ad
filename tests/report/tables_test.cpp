// tests/report/tables_test.cpp — the tables (median or IQM), their marks,
// the seeds summary and the cell summaries.
// Size: one fixture (TableTest) serves every table test, the IQM ones too.
#include "phnn/report/tables.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

constexpr double kInf = std::numeric_limits<double>::infinity();

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
// Column 25 has 5 finished seeds in every row; column 100 has 3 and 0: no
// interval for 3 seeds, no best marked in that column.
class TableTest : public ::testing::Test {
 protected:
  void SetUp() override {
    study_.name = "I";
    study_.title = "Impact of the number of training points";
    study_.varied_axis = "n_train";
    study_.columns = {"25", "100"};
    study_.rows = {"NODE-RK2", "PHNN-JR-DG"};
    study_.systems = {"harmonic"};
    for (double mse : {3e-3, 1e-3, 5e-3, 2e-3, 4e-3}) add("NODE-RK2", "25", RunStatus::kDone, mse);
    for (double mse : {2e-4, 1e-4, 3e-4}) add("PHNN-JR-DG", "25", RunStatus::kDone, mse);
    add("PHNN-JR-DG", "25", RunStatus::kDiverged, kInf);
    add("PHNN-JR-DG", "25", RunStatus::kDiverged, kInf);
    for (double mse : {7e-3, 5e-3, 6e-3}) add("NODE-RK2", "100", RunStatus::kDone, mse);
    add("NODE-RK2", "100", RunStatus::kPending, 0.0);
    add("NODE-RK2", "100", RunStatus::kFailed, 0.0);
    // Not in the table: another study, another system.
    add("NODE-RK2", "25", RunStatus::kDone, 1e-9, "II");
    add("NODE-RK2", "25", RunStatus::kDone, 1e-9, "I", "duffing");
  }

  void add(const std::string& row, const std::string& column, RunStatus status, double mse,
           const std::string& study = "I", const std::string& system = "harmonic") {
    entries_.push_back(TableEntry{study, system, row, column, status, mse});
  }

  std::string render(TableFormat format) const {
    return render_tables({study_}, entries_, format, /*expected_seeds=*/5);
  }

  StudyTable study_;
  std::vector<TableEntry> entries_;
};

// Intervals here are exact: with B = 100 000 resamples the 2.5 % and 97.5 %
// points fall on the smallest / largest value whenever each is the bootstrap
// median with probability well above 2.5 % (5 values: P(median = min) =
// P(>= 3 of 5 draws are the min) = 0.058; 3 values: 7/27).
TEST_F(TableTest, MarkdownShowsMedianIqrIntervalTieDivergedAndMissing) {
  // NODE-RK2/25: {1..5}e-3: median 3e-3, IQR 2e-3, interval [1e-3, 5e-3].
  // PHNN-JR-DG/25: {1, 2, 3}e-4 + 2 x inf: median 3e-4, q75 inf, interval
  //   [1e-4, inf] (P(median = inf) = P(>= 3 of 5 draws diverged) = 0.32):
  //   smallest median, but its interval overlaps NODE-RK2's: a tie.
  // NODE-RK2/100: {5, 6, 7}e-3 -> 6e-3 [1e-3], 3 of 5 finished: no interval,
  //   and no best in a column where PHNN-JR-DG has no run (it was bold from
  //   3 seeds before the honest-tables rule).
  EXPECT_EQ(render(TableFormat::kMarkdown),
            "### Study I — harmonic (columns: n_train)\n"
            "\n"
            "*Impact of the number of training points*\n"
            "\n"
            "| model | 25 | 100 |\n"
            "|---|---|---|\n"
            "| NODE-RK2 | 3.00e-03 [2.00e-03] (1.00e-03, 5.00e-03) (tie) | "
            "6.00e-03 [1.00e-03] (n=3/5) |\n"
            "| PHNN-JR-DG | 3.00e-04 [inf] (1.00e-04, inf) (tie) (d=2) | — |\n"
            "\n"
            "(tie): no clear best in this column: the bootstrap 95 % interval of its smallest "
            "median overlaps the intervals of the other cells marked (tie), so none is bold.\n"
            "\n"
            "No best marked where a row has fewer than 5 finished seeds (100: PHNN-JR-DG has no "
            "finished runs).\n"
            "\n"
            "Cells with fewer than 5 finished seeds show median [IQR] without an interval.\n"
            "\n");
}

TEST_F(TableTest, BestIsBoldOnlyWhenItsIntervalOverlapsNoOther) {
  entries_.clear();
  // Constant sample: interval [2e-4, 2e-4]; the runner-up's is [1e-3, 3e-3].
  for (int seed = 0; seed < 5; ++seed) add("PHNN-JR-DG", "25", RunStatus::kDone, 2e-4);
  for (double mse : {3e-3, 1e-3, 2e-3, 2.5e-3, 1.5e-3}) add("NODE-RK2", "25", RunStatus::kDone, mse);
  std::string markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | **2.00e-04 [0.00e+00] (2.00e-04, 2.00e-04)** |"));
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | 2.00e-03 [1.00e-03] (1.00e-03, 3.00e-03) |"));
  EXPECT_THAT(markdown, Not(HasSubstr("(tie)")));
  // Two runs of the runner-up as low as the best: the intervals now touch
  // (7 values, 2 of them 2e-4: P(bootstrap median = 2e-4) = 0.11 > 2.5 %).
  add("NODE-RK2", "25", RunStatus::kDone, 2e-4);
  add("NODE-RK2", "25", RunStatus::kDone, 2e-4);
  markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, Not(HasSubstr("**")));
  // (7 seeds against 5 now: each cell says its count.)
  EXPECT_THAT(markdown,
              HasSubstr("| PHNN-JR-DG | 2.00e-04 [0.00e+00] (2.00e-04, 2.00e-04) (tie) (n=5) |"));
  EXPECT_THAT(markdown, HasSubstr("(tie): no clear best in this column"));
}

TEST_F(TableTest, LatexBoldsTheBestMarksTiesAndEscapesLabels) {
  const std::string latex = render(TableFormat::kLatex);
  EXPECT_THAT(latex, HasSubstr("\\begin{tabular}{lcc}"));
  EXPECT_THAT(latex, HasSubstr("Study I --- harmonic (columns: n\\_train)"));
  EXPECT_THAT(latex, HasSubstr("Model & 25 & 100 \\\\"));
  EXPECT_THAT(latex, HasSubstr("NODE-RK2 & 3.00e-03 [2.00e-03] (1.00e-03, 5.00e-03) (tie) & "
                               "6.00e-03 [1.00e-03] (n=3/5) \\\\"));
  EXPECT_THAT(latex, Not(HasSubstr("\\textbf")));  // no best: a tie, and a column without
  EXPECT_THAT(latex, HasSubstr("PHNN-JR-DG & 3.00e-04 [inf] (1.00e-04, inf) (tie) (d=2) & -- \\\\"));
  EXPECT_THAT(latex, HasSubstr("\\par\\smallskip{\\footnotesize (tie): no clear best in this "
                               "column: the bootstrap 95 \\% interval"));
  EXPECT_THAT(latex, Not(HasSubstr("—")));
  EXPECT_THAT(latex, HasSubstr("\\end{table}"));
}

TEST_F(TableTest, CsvHasOneLinePerCellWithIntervalBestAndTieColumns) {
  const std::string csv = render(TableFormat::kCsv);
  EXPECT_THAT(csv, StartsWith("study,system,model,axis,column,median,q25,q75,iqr,ci_low,ci_high,"
                              "done,diverged,missing,expected,best,tie\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,25,3.000000e-03,2.000000e-03,"
                             "4.000000e-03,2.000000e-03,1.000000e-03,5.000000e-03,5,0,0,5,0,1\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,PHNN-JR-DG,n_train,25,3.000000e-04,2.000000e-04,"
                             "inf,inf,1.000000e-04,inf,3,2,0,5,0,1\n"));
  // 3 finished seeds: no interval, and no best in the column.
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,100,6.000000e-03,5.500000e-03,"
                             "6.500000e-03,1.000000e-03,,,3,0,2,5,0,0\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,PHNN-JR-DG,n_train,100,,,,,,,0,0,5,5,0,0\n"));
  // Header + 4 cells.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
}

TEST(CellStatisticTest, ParsesMedianAndIqmAndListsThemOnError) {
  EXPECT_EQ(parse_cell_statistic("median"), CellStatistic::kMedian);
  EXPECT_EQ(parse_cell_statistic("iqm"), CellStatistic::kIqm);
  EXPECT_EQ(to_string(CellStatistic::kIqm), "iqm");
  EXPECT_THAT([] { parse_cell_statistic("mean"); },
              testing::ThrowsMessage<std::invalid_argument>(
                  HasSubstr("\"mean\" (did you mean \"median\"?); expected one of: median, iqm")));
}

// --stat iqm: NODE-RK2/25 {1..5}e-3 has IQM (2 + 3 + 4) / 3 e-3 = 3e-3;
// PHNN-JR-DG/25 {1, 2, 3}e-4 + 2 x inf keeps 2e-4, 3e-4 and one inf: IQM inf
// (two of five diverged, only floor(5/4) = 1 trimmed). The CSV names the
// column iqm; the text says IQM.
TEST_F(TableTest, IqmCellsNameTheirStatisticAndKeepUntrimmedDivergedRuns) {
  const std::string csv = render_tables({study_}, entries_, TableFormat::kCsv, 5, {},
                                        CellStatistic::kIqm);
  EXPECT_THAT(csv, StartsWith("study,system,model,axis,column,iqm,q25,q75,iqr,ci_low,ci_high,"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,25,3.000000e-03,2.000000e-03,"
                             "4.000000e-03,2.000000e-03,"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,PHNN-JR-DG,n_train,25,inf,2.000000e-04,inf,inf,"));
  // 3 finished seeds in NODE-RK2/100: g = 0, the mean of {5, 6, 7}e-3.
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,100,6.000000e-03,"));
  const std::string markdown = render_tables({study_}, entries_, TableFormat::kMarkdown, 5, {},
                                             CellStatistic::kIqm);
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | inf [inf] ("));
  EXPECT_THAT(markdown, HasSubstr("show IQM [IQR] without an interval"));
  EXPECT_THAT(render_tables({study_}, entries_, TableFormat::kLatex, 5, {}, CellStatistic::kIqm),
              HasSubstr("IQM [IQR] (bootstrap 95~\\% interval of the IQM)"));
}

// Best and tie by the IQM's interval, not the median's: NODE-RK2
// {2, 2}e-4 + 5 x 1e-2 has median 1e-2 with interval [2e-4, 1e-2]
// (P(bootstrap median = 2e-4) = P(>= 4 of 7 draws small) = 0.108), touching
// PHNN-JR-DG's constant 2e-4: a tie by the median. Its IQM (2e-4 + 4 x
// 1e-2) / 5 = 8.04e-3 is 2e-4 in a resample only with >= 6 small draws
// (P = 0.0029 < 2.5 %), so its IQM interval starts at 2.16e-3 or above:
// PHNN-JR-DG is bold by the IQM.
TEST_F(TableTest, IqmMarksTheBestByTheIqmInterval) {
  entries_.clear();
  for (double mse : {2e-4, 2e-4, 1e-2, 1e-2, 1e-2, 1e-2, 1e-2}) {
    add("NODE-RK2", "25", RunStatus::kDone, mse);
  }
  for (int seed = 0; seed < 5; ++seed) add("PHNN-JR-DG", "25", RunStatus::kDone, 2e-4);
  const std::string iqm = render_tables({study_}, entries_, TableFormat::kMarkdown, 5, {},
                                        CellStatistic::kIqm);
  EXPECT_THAT(iqm, HasSubstr("| NODE-RK2 | 8.04e-03 [4.90e-03] ("));
  EXPECT_THAT(iqm, HasSubstr("| PHNN-JR-DG | **2.00e-04 [0.00e+00] (2.00e-04, 2.00e-04)**"));
  EXPECT_THAT(iqm, Not(HasSubstr("(tie)")));
  const std::string median = render(TableFormat::kMarkdown);
  EXPECT_THAT(median, HasSubstr("| NODE-RK2 | 1.00e-02 [4.90e-03] (2.00e-04, 1.00e-02) (tie)"));
  EXPECT_THAT(median, HasSubstr("| PHNN-JR-DG | 2.00e-04 [0.00e+00] (2.00e-04, 2.00e-04) (tie)"));
}

TEST_F(TableTest, AllDivergedCellShowsInfinityAndCountNeverNan) {
  entries_.clear();
  for (int i = 0; i < 5; ++i) add("NODE-RK2", "25", RunStatus::kDiverged, kInf);
  for (int i = 0; i < 5; ++i) add("PHNN-JR-DG", "25", RunStatus::kDone, 1e-3);
  const std::string markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | inf (d=5) | — |"));
  // The diverged cell's interval [inf, inf] overlaps nothing finite.
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | **1.00e-03 [0.00e+00] (1.00e-03, 1.00e-03)** |"));
  const std::string csv = render(TableFormat::kCsv);
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,25,inf,inf,inf,inf,inf,inf,0,5,0,5,0,0\n"));
  EXPECT_THAT(markdown + csv + render(TableFormat::kLatex), Not(HasSubstr("nan")));
}

TEST_F(TableTest, AllDivergedCellIsNoTieForABestWhoseIntervalReachesInfinity) {
  entries_.clear();
  // {1, 1.5, 2, 2.5}e-3 + inf: median 2e-3, IQR 1e-3, interval [1e-3, inf]
  // (P(median = inf) = P(median = 1e-3) = 0.058).
  for (double mse : {1e-3, 1.5e-3, 2e-3, 2.5e-3, kInf}) add("NODE-RK2", "25", RunStatus::kDone, mse);
  for (int i = 0; i < 5; ++i) add("PHNN-JR-DG", "25", RunStatus::kDiverged, kInf);
  const std::string markdown = render_tables({study_}, entries_, TableFormat::kMarkdown, 5);
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | **2.00e-03 [1.00e-03] (1.00e-03, inf)** (d=1) | — |"));
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | inf (d=5) | — |"));
  EXPECT_THAT(markdown, Not(HasSubstr("(tie)")));
}

TEST_F(TableTest, DivergedRunsWithAFiniteMseShowTheirNumbers) {
  entries_.clear();
  add("NODE-RK2", "25", RunStatus::kDiverged, 5e-3);  // e.g. a training loss that went NaN
  const std::string markdown = render(TableFormat::kMarkdown);
  // One seed: its numbers, no interval, not bold.
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | 5.00e-03 [0.00e+00] (n=1/5) (d=1) |"));
}

// Every way +inf meets a quantile: neighbours both +inf, a median between a
// finite value and +inf, an IQR with q75 = +inf, q25 = q75 = +inf.
TEST_F(TableTest, InfiniteMsesNeverPrintNan) {
  entries_.clear();
  // {1, 2} + 2 x inf: median between 2 and inf -> inf; q25 1.75; q75 inf.
  for (double mse : {1e-3, 2e-3}) add("NODE-RK2", "25", RunStatus::kDone, mse);
  for (int i = 0; i < 2; ++i) add("NODE-RK2", "25", RunStatus::kDiverged, kInf);
  // {1} + 4 x inf: q25 between inf and inf -> inf, IQR inf (not inf - inf).
  add("PHNN-JR-DG", "25", RunStatus::kDone, 1e-3);
  for (int i = 0; i < 4; ++i) add("PHNN-JR-DG", "25", RunStatus::kDiverged, kInf);
  // A done run with a NaN MSE counts as diverged (+inf).
  add("NODE-RK2", "100", RunStatus::kDone, std::nan(""));
  add("NODE-RK2", "100", RunStatus::kDone, 1e-3);
  const std::string markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | inf [inf] (n=4/5) (d=2) | "
                                  "inf [inf] (n=2/5) (d=1) |"));
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | inf [inf] (1.00e-03, inf) (d=4) | — |"));
  EXPECT_THAT(markdown + render(TableFormat::kCsv) + render(TableFormat::kLatex),
              Not(HasSubstr("nan")));
}

TEST_F(TableTest, EqualBestMediansAreATie) {
  entries_.clear();
  for (int i = 0; i < 5; ++i) {
    add("NODE-RK2", "25", RunStatus::kDone, 1e-3);
    add("PHNN-JR-DG", "25", RunStatus::kDone, 1e-3);
  }
  const std::string markdown = render_tables({study_}, entries_, TableFormat::kMarkdown, 5);
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | 1.00e-03 [0.00e+00] (1.00e-03, 1.00e-03) (tie) | — |"));
  EXPECT_THAT(markdown,
              HasSubstr("| PHNN-JR-DG | 1.00e-03 [0.00e+00] (1.00e-03, 1.00e-03) (tie) | — |"));
}

// Honest tables: a best from 1 seed with a zero-width "interval", or a best
// in a column where another model has no runs, was bold; neither is now, and
// the note says why. With 5 seeds in every row the best is bold again.
TEST_F(TableTest, NoBestFromFewSeedsOrBesideAMissingRow) {
  entries_.clear();
  add("PHNN-JR-DG", "25", RunStatus::kDone, 1e-4);  // 1 seed, far below the other row
  for (int i = 0; i < 5; ++i) add("NODE-RK2", "25", RunStatus::kDone, 1e-2 * (i + 1));
  for (int i = 0; i < 5; ++i) add("NODE-RK2", "100", RunStatus::kDone, 1e-3);  // alone in 100
  std::string markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, Not(HasSubstr("**")));
  EXPECT_THAT(markdown, Not(HasSubstr("(tie)")));
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | 1.00e-04 [0.00e+00] (n=1/5) | — |"));
  EXPECT_THAT(markdown, HasSubstr("No best marked where a row has fewer than 5 finished seeds "
                                  "(25: PHNN-JR-DG has 1 finished seed; 100: PHNN-JR-DG has no "
                                  "finished runs)."));
  for (int i = 0; i < 4; ++i) add("PHNN-JR-DG", "25", RunStatus::kDone, 1e-4);
  markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | **1.00e-04 [0.00e+00] (1.00e-04, 1.00e-04)** | — |"));
  EXPECT_THAT(markdown, HasSubstr("(100: PHNN-JR-DG has no finished runs)"));
  const std::string csv = render(TableFormat::kCsv);
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,100,1.000000e-03,1.000000e-03,"
                             "1.000000e-03,0.000000e+00,1.000000e-03,1.000000e-03,5,0,0,5,0,0\n"));
}

// Cells with different seed counts (an adaptive sweep's) each say theirs,
// and the statistics use every seed.
TEST_F(TableTest, CellsWithDifferentSeedCountsSayTheirs) {
  entries_.clear();
  for (int i = 0; i < 5; ++i) add("NODE-RK2", "25", RunStatus::kDone, 1e-3 * (i + 1));
  for (int i = 0; i < 8; ++i) add("PHNN-JR-DG", "25", RunStatus::kDone, 1e-4 * (i + 1));
  const std::string markdown = render(TableFormat::kMarkdown);
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | 3.00e-03 [2.00e-03] (1.00e-03, 5.00e-03) (n=5) |"));
  // Median of 1..8 (x 1e-4) = 4.5e-4: all eight seeds enter.
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | **4.50e-04 [3.50e-04] "));
  EXPECT_THAT(markdown, HasSubstr("(n=8) |"));
  EXPECT_THAT(markdown, HasSubstr("Cells hold different numbers of seeds"));
  // Equal counts: no (n=k) anywhere.
  for (int i = 0; i < 3; ++i) add("NODE-RK2", "25", RunStatus::kDone, 1e-3);
  EXPECT_THAT(render(TableFormat::kMarkdown), Not(HasSubstr("(n=8)")));
}

TEST_F(TableTest, SeedsSummaryCountsSeedsBelowAndAboveTheColumnMidpoint) {
  entries_.clear();
  // Column 25: finite MSEs 1e-2 .. 1e2 -> m = sqrt(1e-2 * 1e2) = 1.
  for (double mse : {1e-2, 2e-2, 50.0, 1e2}) add("NODE-RK2", "25", RunStatus::kDone, mse);
  add("NODE-RK2", "25", RunStatus::kDiverged, kInf);
  for (double mse : {0.5, 0.9, 3e-2}) add("PHNN-JR-DG", "25", RunStatus::kDone, mse);
  const std::string markdown =
      render_seeds_summary({study_}, entries_, TableFormat::kMarkdown, /*expected_seeds=*/5);
  EXPECT_THAT(markdown, HasSubstr("| model | 25 (m=1.00e+00) | 100 (m=—) |"));
  EXPECT_THAT(markdown, HasSubstr("| NODE-RK2 | 2 / 3 (d=1) | — |"));
  EXPECT_THAT(markdown, HasSubstr("| PHNN-JR-DG | 3 / 0 (n=3/5) | — |"));
  EXPECT_THAT(markdown, HasSubstr("below / above: seeds with MSE <= m / > m"));
  const std::string csv =
      render_seeds_summary({study_}, entries_, TableFormat::kCsv, /*expected_seeds=*/5);
  EXPECT_THAT(csv, StartsWith("study,system,model,axis,column,midpoint,below,above,diverged,"
                              "missing,expected\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,NODE-RK2,n_train,25,1.000000e+00,2,3,1,0,5\n"));
  EXPECT_THAT(csv, HasSubstr("\nI,harmonic,PHNN-JR-DG,n_train,100,,0,0,0,5,5\n"));
  EXPECT_THAT(render_seeds_summary({study_}, entries_, TableFormat::kLatex, 5),
              HasSubstr("NODE-RK2 & 2 / 3 (d=1) & -- \\\\"));
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
  // Diverged runs count as +inf: {1, inf, inf} has median inf.
  EXPECT_EQ(s.median, kInf);
  EXPECT_EQ(s.q25, kInf);  // numpy: 1 + 0.5 (inf - 1)
  EXPECT_EQ(s.q75, kInf);  // numpy: nan (inf + 0.5 (inf - inf))
  EXPECT_EQ(s.iqr(), kInf);
  EXPECT_EQ(s.median_interval.low, 1.0);
  EXPECT_EQ(s.median_interval.high, kInf);
}

TEST(CellSummaryTest, AllDivergedHasInfiniteStatisticsAndNoRunsHasNan) {
  std::vector<TableEntry> entries(3);
  for (TableEntry& e : entries) {
    e.status = RunStatus::kDiverged;
    e.mse = kInf;
  }
  const CellSummary all = summarize_cell(entries, /*expected_seeds=*/3);
  EXPECT_EQ(all.diverged, 3);
  EXPECT_EQ(all.median, kInf);
  EXPECT_EQ(all.iqr(), kInf);
  EXPECT_EQ(all.median_interval.low, kInf);
  EXPECT_EQ(all.median_interval.high, kInf);
  const CellSummary none = summarize_cell({}, /*expected_seeds=*/3);
  EXPECT_EQ(none.missing, 3);
  EXPECT_TRUE(std::isnan(none.median));
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
