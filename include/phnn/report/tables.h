// include/phnn/report/tables.h — the paper's result tables (Appendix F) from
// run results: median (or IQM) [IQR] (bootstrap interval of the median or
// IQM) per cell, the
// best of a column only when the intervals separate it, and the seeds-per-mode
// view. Pure functions: no HDF5, no MPI.
#pragma once

#include <string>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/config/run_grid.h"
#include "phnn/config/run_result.h"
#include "phnn/report/statistics.h"
#include "phnn/systems/oscillators.h"

namespace phnn {

/// One run's outcome, placed in a table: study, system, row (model label,
/// e.g. "PHNN-JR-DG") and column (StudyTable::columns label). A run shared by
/// several studies has one entry per study.
struct TableEntry {
  std::string study;
  /// RunConfig::system_name(): "duffing", a system file's name.
  std::string system;
  std::string row;
  std::string column;
  RunStatus status = RunStatus::kPending;
  /// Inference MSE (Eq. 31); +inf for a diverged run (NaN is read as +inf);
  /// ignored unless done or diverged.
  double mse = 0.0;
  /// The run's seed and its index into Grid::runs (-1: not from a grid).
  int seed = 0, run = -1;
};

/// Entries for every run of every study of `grid`; status[i] and mse[i]
/// belong to grid.runs[i]. With `only`, just the runs i with only[i] != 0 (an
/// adaptive sweep's runs asked for so far, phnn/sweep/adaptive.h). Runs
/// without inference (TrainerOptions::skip_inference: a [search] rung before
/// the last) have no MSE and no entry. Throws std::invalid_argument if the
/// sizes differ.
std::vector<TableEntry> make_table_entries(const Grid& grid, const std::vector<RunStatus>& status,
                                           const std::vector<double>& mse,
                                           const std::vector<char>* only = nullptr);

/// Output format of render_tables().
enum class TableFormat { kMarkdown, kLatex, kCsv };
inline constexpr EnumNames<TableFormat, 3> kTableFormatNames{
    "table format",
    {{{TableFormat::kMarkdown, "markdown"}, {TableFormat::kLatex, "latex"}, {TableFormat::kCsv, "csv"}}}};
/// Throws std::invalid_argument listing the formats.
inline TableFormat parse_table_format(const std::string& name) { return kTableFormatNames.parse(name); }
inline std::string to_string(TableFormat format) { return kTableFormatNames.name(format); }

/// The statistic a table's cells show and rank by (`phnn reduce --stat`):
/// the median (the paper's), or the interquartile mean (interquartile_mean,
/// statistics.h) with its bootstrap interval.
enum class CellStatistic { kMedian, kIqm };
inline constexpr EnumNames<CellStatistic, 2> kCellStatisticNames{
    "statistic", {{{CellStatistic::kMedian, "median"}, {CellStatistic::kIqm, "iqm"}}}};
/// Throws std::invalid_argument listing the statistics.
inline CellStatistic parse_cell_statistic(const std::string& name) {
  return kCellStatisticNames.parse(name);
}
inline std::string to_string(CellStatistic statistic) { return kCellStatisticNames.name(statistic); }

/// Fewest finished seeds for which a table prints a cell's bootstrap
/// interval; a column marks a best (or a tie) only if every row has as
/// many. A bootstrap interval of 1-4 values says little (of 1: zero width).
constexpr int kMinSeedsForInterval = 5;

/// Statistics of one table cell.
struct CellSummary {
  /// Runs with status done (and a finite MSE).
  int done = 0;
  /// Runs with status diverged (or done with a non-finite MSE): counted, and
  /// their MSE (+inf for a diverged rollout) enters median, IQR and interval.
  int diverged = 0;
  /// expected - done - diverged (pending, failed or absent runs), >= 0.
  int missing = 0;
  /// max(expected_seeds, number of entries of the cell).
  int expected = 0;
  /// Median, 25 % and 75 % quantiles (quantile_linear: exact with +inf, so
  /// a cell whose runs all diverged has median +inf); NaN only if the cell
  /// has no finished run (done + diverged == 0).
  double median = 0.0, q25 = 0.0, q75 = 0.0;
  /// Percentile-bootstrap interval of the median (bootstrap_median_interval
  /// over the done and diverged runs); NaN ends if done + diverged == 0.
  Interval median_interval;
  /// Which statistic the cell shows; with kIqm, `iqm` is
  /// interquartile_mean over the done and diverged runs (+inf when more
  /// than floor(n / 4) of the n diverged) and `iqm_interval` its
  /// bootstrap_iqm_interval; with kMedian both are NaN (not computed).
  CellStatistic statistic = CellStatistic::kMedian;
  double iqm = 0.0;
  Interval iqm_interval;

  /// The shown statistic: median or iqm.
  double center() const { return statistic == CellStatistic::kIqm ? iqm : median; }
  /// Its interval: median_interval or iqm_interval.
  const Interval& center_interval() const {
    return statistic == CellStatistic::kIqm ? iqm_interval : median_interval;
  }
  /// Runs whose MSE enters the statistics.
  int finished() const { return done + diverged; }
  /// Whether the tables show the interval (and may mark a best): at least
  /// kMinSeedsForInterval finished runs.
  bool has_interval() const;
  /// q75 - q25; +inf if q75 is +inf (also when q25 is: the spread of a cell
  /// with that many diverged runs is unbounded, never NaN).
  double iqr() const;
};

/// Summarizes the MSEs of one cell's entries (the IQM and its interval only
/// with `statistic` kIqm).
CellSummary summarize_cell(const std::vector<TableEntry>& entries, int expected_seeds,
                           const BootstrapOptions& bootstrap = {},
                           CellStatistic statistic = CellStatistic::kMedian);

/// The paper's tables (Appendix F layout): for each study and each of its
/// systems, rows = StudyTable::rows (models, in order), columns =
/// StudyTable::columns (values of the varied axis), cells =
///
///   median [IQR] (low, high)   of the inference MSE over the finished runs,
///
/// all "%.2e" (e.g. "1.23e-03 [4.56e-04] (9.80e-04, 2.01e-03)"), IQR = q75 -
/// q25 with quantile_linear (numpy's default linear interpolation), (low,
/// high) the bootstrap 95 % interval of the median (bootstrap_median_interval
/// with `bootstrap`). Best per column: among the cells with a finite median,
/// the one with the smallest median is
///   - marked best (**bold** in Markdown, \textbf{} in LaTeX, best = 1 in
///     CSV) if its interval overlaps no other cell's interval of the column;
///   - otherwise marked " (tie)", together with every cell of the column whose
///     interval overlaps it (and any cell with the same median); nothing is
///     bold, and a note under the table explains the mark (tie = 1 in CSV).
///     A cell whose interval is [inf, inf] never ties (it shares only +inf).
/// Annotations, appended in this order:
///   " (n=7/10)"  fewer than `expected` runs finished (n = done + diverged;
///                pending, failed or absent runs are missing);
///   " (d=2)"     diverged runs; their MSE (+inf for a diverged rollout) is
///                included in the statistics (a diverged run's error is +inf
///                and counted), so IQR, median or interval may print as inf.
/// A cell without any finished run shows just "—" (Markdown) or "--"
/// (LaTeX); one whose runs all diverged shows "inf (d=10)".
/// expected = max(expected_seeds, entries of the cell).
///
/// Markdown: per table a heading "### Study I — harmonic (columns: n_train)",
/// the study title in italics if any, then a pipe table.
/// LaTeX: per table a `table` float with a `tabular` (\hline rules, no
/// packages needed) and the heading as caption; labels escaped.
/// CSV: one header line, then one line per (study, system, model, column):
///   study,system,model,axis,column,median,q25,q75,iqr,ci_low,ci_high,done,
///   diverged,missing,expected,best,tie
/// numbers "%.6e" ("inf" for +inf; empty when the cell has no finished run).
///
/// With `statistic` kIqm every "median" above reads "IQM" (the
/// interquartile mean and bootstrap_iqm_interval): cells "IQM [IQR] (low,
/// high)", best and tie by the IQMs and their intervals, the caption says
/// "IQM", and the CSV header names the column `iqm` instead of `median`
/// (ci_low, ci_high are then the IQM's interval). A cell with more diverged
/// runs than floor(n / 4) has IQM +inf and prints as a cell whose median is
/// +inf does.
///
/// Entries whose study, system, row or column is not in `studies` are ignored.
std::string render_tables(const std::vector<StudyTable>& studies,
                          const std::vector<TableEntry>& entries, TableFormat format,
                          int expected_seeds, const BootstrapOptions& bootstrap = {},
                          CellStatistic statistic = CellStatistic::kMedian);

/// A cell of a study table, by name.
struct TableCellName {
  std::string study, system, row, column;
};

/// The cells whose order in their column more seeds may settle (an adaptive
/// sweep's "column-best" rule), in table order: per column, the cells
/// render_tables() marks " (tie)" (same entries, expected_seeds and
/// bootstrap): the smallest median and every cell whose interval overlaps its
/// interval; in a column that marks nothing because a row has fewer than
/// kMinSeedsForInterval finished runs, the cells with fewer (no interval).
std::vector<TableCellName> undecided_cells(const std::vector<StudyTable>& studies,
                                           const std::vector<TableEntry>& entries,
                                           int expected_seeds,
                                           const BootstrapOptions& bootstrap = {});

/// The seeds behind each cell, to make a bimodal cell visible: for each
/// column of each table, the geometric midpoint of its finite positive MSEs
/// (all rows), m = sqrt(min * max), and per cell
///
///   below / above    runs with MSE <= m / runs with MSE > m (diverged
///                    runs, MSE +inf, count above and are also shown "(d=k)"),
///
/// with the same " (n=k/N)" annotation as render_tables. A column without a
/// finite positive MSE has no midpoint ("—"); all its finished runs count
/// above. Markdown and LaTeX: the render_tables layout, the midpoint in the
/// column label ("25 (m=3.16e-01)") and a note under each table. CSV:
///   study,system,model,axis,column,midpoint,below,above,diverged,missing,expected
std::string render_seeds_summary(const std::vector<StudyTable>& studies,
                                 const std::vector<TableEntry>& entries, TableFormat format,
                                 int expected_seeds);

}  // namespace phnn
