// include/phnn/report/tables.h — the paper's result tables (Appendix F) from
// run results. Pure functions: no HDF5, no MPI.
#pragma once

#include <string>
#include <vector>

#include "phnn/sweep/grid.h"
#include "phnn/systems/oscillators.h"
#include "phnn/training/run_result.h"

namespace phnn {

/// The q-quantile of `values` with numpy's default ("linear") method:
///
///   h = (n - 1) q,   Q(q) = s[floor h] + (h - floor h) (s[floor h + 1] - s[floor h])
///
/// over the sorted values s (Hyndman & Fan type 7). E.g. {1, 2, 3, 4}:
/// Q(0.25) = 1.75, Q(0.5) = 2.5, Q(0.75) = 3.25. Throws std::invalid_argument
/// if `values` is empty, contains a NaN, or q is outside [0, 1].
double quantile_linear(std::vector<double> values, double q);

/// One run's outcome, placed in a table: study, system, row (model label,
/// e.g. "PHNN-JR-DG") and column (StudyTable::columns label). A run shared by
/// several studies has one entry per study.
struct TableEntry {
  std::string study;
  SystemKind system = SystemKind::kHarmonic;
  std::string row;
  std::string column;
  RunStatus status = RunStatus::kPending;
  /// Inference MSE (Eq. 31); +inf for a diverged run; ignored unless done.
  double mse = 0.0;
};

/// Entries for every run of every study of `grid`; status[i] and mse[i]
/// belong to grid.runs[i]. Throws std::invalid_argument if the sizes differ.
std::vector<TableEntry> make_table_entries(const Grid& grid, const std::vector<RunStatus>& status,
                                           const std::vector<double>& mse);

/// Output format of render_tables().
enum class TableFormat { kMarkdown, kLatex, kCsv };
/// "markdown", "latex", "csv"; throws std::invalid_argument listing them.
TableFormat parse_table_format(const std::string& name);
/// "markdown", "latex", "csv".
std::string to_string(TableFormat format);

/// Statistics of one table cell.
struct CellSummary {
  /// Runs with status done (and a finite MSE).
  int done = 0;
  /// Runs with status diverged (or done with a non-finite MSE): counted, and
  /// their MSE (+inf for a diverged rollout) enters median and IQR.
  int diverged = 0;
  /// expected - done - diverged (pending, failed or absent runs), >= 0.
  int missing = 0;
  /// max(expected_seeds, number of entries of the cell).
  int expected = 0;
  /// Median, 25 % and 75 % quantiles (quantile_linear); NaN if done == 0.
  double median = 0.0, q25 = 0.0, q75 = 0.0;
  /// q75 - q25.
  double iqr() const { return q75 - q25; }
};

/// Summarizes the MSEs of one cell's entries.
CellSummary summarize_cell(const std::vector<TableEntry>& entries, int expected_seeds);

/// The paper's tables (Appendix F layout, SPEC.md §6): for each study and
/// each of its systems, rows = StudyTable::rows (models, in order), columns =
/// StudyTable::columns (values of the varied axis), cells =
///
///   median [IQR]   of the inference MSE over the runs with status done,
///
/// both printed "%.2e" (e.g. "1.23e-03 [4.56e-04]"), IQR = q75 - q25 with
/// quantile_linear (numpy's default linear interpolation). The best
/// (smallest) median of each column is marked: **bold** in Markdown,
/// \textbf{} in LaTeX, best = 1 in CSV (ties all marked). Annotations,
/// appended in this order:
///   " (n=7/10)"  fewer than `expected` runs finished (n = done + diverged;
///                pending, failed or absent runs are missing);
///   " (d=2)"     diverged runs; their MSE (+inf for a diverged rollout) is
///                included in median and IQR (SPEC.md §5: "its error is +inf
///                and counted"), so IQR or median may print as inf.
/// A cell without any finished run shows just "—" (Markdown) or "--"
/// (LaTeX); one whose runs all diverged shows "— (d=10)".
/// expected = max(expected_seeds, entries of the cell).
///
/// Markdown: per table a heading "### Study I — harmonic (columns: n_train)",
/// the study title in italics if any, then a pipe table.
/// LaTeX: per table a `table` float with a `tabular` (\hline rules, no
/// packages needed) and the heading as caption; labels escaped.
/// CSV: one header line, then one line per (study, system, model, column):
///   study,system,model,axis,column,median,q25,q75,iqr,done,diverged,missing,expected,best
/// numbers "%.6e" (empty when done = 0), best = 1 for the marked cells else 0.
///
/// Entries whose study, system, row or column is not in `studies` are ignored.
std::string render_tables(const std::vector<StudyTable>& studies,
                          const std::vector<TableEntry>& entries, TableFormat format,
                          int expected_seeds);

}  // namespace phnn
