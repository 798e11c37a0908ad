// src/report/tables.cpp — median or IQM [IQR] (bootstrap interval) tables
// of the inference MSE with best/tie marks. The seeds-per-mode view:
// seeds_summary.cpp; the shared text layout: table_text.cpp.
#include "phnn/report/tables.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "report/csv.h"
#include "report/table_text.h"

namespace phnn {

using namespace table_text;
using internal::csv_field;

std::vector<TableEntry> make_table_entries(const Grid& grid, const std::vector<RunStatus>& status,
                                           const std::vector<double>& mse,
                                           const std::vector<char>* only) {
  if (status.size() != grid.runs.size() || mse.size() != grid.runs.size() ||
      (only && only->size() != grid.runs.size())) {
    throw std::invalid_argument("make_table_entries: got " + std::to_string(status.size()) +
                                " statuses and " + std::to_string(mse.size()) +
                                " MSEs for a grid of " + std::to_string(grid.runs.size()) +
                                " runs; pass one of each per run");
  }
  std::vector<TableEntry> entries;
  for (const StudyTable& study : grid.studies) {
    for (std::size_t i = 0; i < study.runs.size(); ++i) {
      const int r = study.runs[i];
      if (only && !(*only)[static_cast<std::size_t>(r)]) continue;
      const RunConfig& run = grid.runs[r];
      if (run.training.skip_inference) continue;  // a [search] rung before the last: no MSE
      TableEntry e;
      e.study = study.name;
      e.system = run.system_name();
      e.row = model_label(run.model, run.integrator);
      e.column = study.run_columns[i];
      e.status = status[r];
      e.mse = mse[r];
      e.seed = run.seed;
      e.run = r;
      entries.push_back(std::move(e));
    }
  }
  return entries;
}

double CellSummary::iqr() const {
  if (std::isinf(q75) && q75 > 0) return q75;
  return q75 - q25;
}

CellSummary summarize_cell(const std::vector<TableEntry>& entries, int expected_seeds,
                           const BootstrapOptions& bootstrap, CellStatistic statistic) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CellSummary s;
  s.statistic = statistic;
  s.iqm = nan;
  s.iqm_interval = Interval{nan, nan};
  std::vector<double> values;
  for (const TableEntry& e : entries) {
    if (counts_as_diverged(e)) {
      ++s.diverged;
      values.push_back(std::isnan(e.mse) ? std::numeric_limits<double>::infinity() : e.mse);
    } else if (counts_as_done(e)) {
      ++s.done;
      values.push_back(e.mse);
    }
  }
  s.expected = std::max(expected_seeds, static_cast<int>(entries.size()));
  s.missing = std::max(0, s.expected - s.finished());
  if (values.empty()) {
    s.median = s.q25 = s.q75 = nan;
    s.median_interval = Interval{nan, nan};
    return s;
  }
  std::sort(values.begin(), values.end());
  s.median = quantile_linear_sorted(values, 0.5);
  s.q25 = quantile_linear_sorted(values, 0.25);
  s.q75 = quantile_linear_sorted(values, 0.75);
  s.median_interval = bootstrap_median_interval(values, bootstrap);
  if (statistic == CellStatistic::kIqm) {
    s.iqm = interquartile_mean_sorted(values);
    s.iqm_interval = bootstrap_iqm_interval(values, bootstrap);
  }
  return s;
}

bool CellSummary::has_interval() const { return finished() >= kMinSeedsForInterval; }

namespace {

// "median" or "IQM", as the table text names the statistic.
std::string statistic_name(CellStatistic statistic) {
  return statistic == CellStatistic::kIqm ? "IQM" : "median";
}

std::string tie_note(CellStatistic statistic) {
  return "(tie): no clear best in this column: the bootstrap 95 % interval of its smallest " +
         statistic_name(statistic) +
         " overlaps the intervals of the other cells marked (tie), so none is bold.";
}

std::string few_seeds_note(CellStatistic statistic) {
  return "Cells with fewer than " + std::to_string(kMinSeedsForInterval) + " finished seeds show " +
         statistic_name(statistic) + " [IQR] without an interval.";
}

std::string annotations(const CellSummary& s) {
  return table_text::annotations(s.finished(), s.diverged, s.missing, s.expected);
}

enum class Mark { kNone, kBest, kTie };

// Why a column marks no best (empty: it may): a row without runs or with
// fewer than kMinSeedsForInterval finished ones.
std::string unmarkable(const std::vector<CellSummary>& column, const std::vector<std::string>& rows) {
  for (std::size_t r = 0; r < column.size(); ++r) {
    if (column[r].finished() == 0) return rows[r] + " has no finished runs";
  }
  for (std::size_t r = 0; r < column.size(); ++r) {
    if (!column[r].has_interval()) {
      return rows[r] + " has " + std::to_string(column[r].finished()) + " finished seed" +
             (column[r].finished() == 1 ? "" : "s");
    }
  }
  return "";
}

// Best of one column (CellSummary order = rows), if unmarkable() allows: the
// smallest finite center() (median or IQM) is best if its interval overlaps
// no other cell's interval; else it and every cell overlapping it (or with
// an equal center) are a tie. A cell whose interval is [+inf, +inf] (all or nearly all runs
// diverged) cannot be smaller than anything: sharing the point +inf is no tie.
std::vector<Mark> mark_column(const std::vector<CellSummary>& column) {
  std::vector<Mark> marks(column.size(), Mark::kNone);
  int best = -1;
  for (std::size_t r = 0; r < column.size(); ++r) {
    const CellSummary& s = column[r];
    if (!std::isfinite(s.center())) continue;
    if (best < 0 || s.center() < column[best].center()) best = static_cast<int>(r);
  }
  if (best < 0) return marks;
  const CellSummary& b = column[best];
  bool tied = false;
  for (std::size_t r = 0; r < column.size(); ++r) {
    const CellSummary& s = column[r];
    if (static_cast<int>(r) == best) continue;
    if (std::isinf(s.center_interval().low)) continue;
    if (s.center_interval().overlaps(b.center_interval()) || s.center() == b.center()) {
      marks[r] = Mark::kTie;
      tied = true;
    }
  }
  marks[best] = tied ? Mark::kTie : Mark::kBest;
  return marks;
}

// One column of a table judged as render_tables() marks it: each row's
// summary, then either why nothing is marked or the marks.
struct ColumnJudgement {
  std::vector<CellSummary> cells;  // per row
  std::string unmarkable;          // "" if the column may mark a best
  std::vector<Mark> marks;         // per row; kNone throughout when unmarkable
};

ColumnJudgement judge_column(const TableEntries& t, std::size_t c, int expected_seeds,
                             const BootstrapOptions& bootstrap, CellStatistic statistic) {
  const std::size_t rows = t.study->rows.size();
  ColumnJudgement j;
  j.cells.resize(rows);
  for (std::size_t r = 0; r < rows; ++r) {
    j.cells[r] = summarize_cell(t.cells[r][c], expected_seeds, bootstrap, statistic);
  }
  j.unmarkable = unmarkable(j.cells, t.study->rows);
  j.marks = j.unmarkable.empty() ? mark_column(j.cells) : std::vector<Mark>(rows, Mark::kNone);
  return j;
}

// " (n=k)" when `counts` and the cell is complete (an incomplete one says
// " (n=k/N)" in its annotations).
std::string own_count(const CellSummary& s, bool counts) {
  return counts && s.missing == 0 ? " (n=" + std::to_string(s.finished()) + ")" : "";
}

// `counts`: the table's cells hold different numbers of seeds (e.g. an
// adaptive sweep's), so every cell says its own " (n=k)".
std::string summary_cell_text(const CellSummary& s, Mark mark, TableFormat format, bool counts) {
  const std::string none = format == TableFormat::kMarkdown ? "—" : "--";
  if (s.finished() == 0) return none;                        // all missing
  // All diverged at +inf: median (IQM) and interval say nothing more than the count.
  if (s.done == 0 && std::isinf(s.center()) && std::isinf(s.center_interval().low)) {
    return "inf" + own_count(s, counts) + annotations(s);
  }
  std::string value =
      format_number("%.2e", s.center()) + " [" + format_number("%.2e", s.iqr()) + "]";
  if (s.has_interval()) {
    value += " (" + format_number("%.2e", s.center_interval().low) + ", " +
             format_number("%.2e", s.center_interval().high) + ")";
  }
  if (mark == Mark::kBest) {
    value = format == TableFormat::kMarkdown ? "**" + value + "**" : "\\textbf{" + value + "}";
  }
  if (mark == Mark::kTie) value += " (tie)";
  return value + own_count(s, counts) + annotations(s);
}

void render_summary_csv(const TableEntries& t, const std::vector<std::vector<CellSummary>>& cells,
                        const std::vector<std::vector<Mark>>& marks, std::ostringstream& out) {
  for (std::size_t r = 0; r < t.study->rows.size(); ++r) {
    for (std::size_t c = 0; c < t.study->columns.size(); ++c) {
      const CellSummary& s = cells[r][c];
      const auto number = [&](double v) {
        return s.finished() > 0 ? format_number("%.6e", v) : std::string();
      };
      const auto bound = [&](double v) { return s.has_interval() ? number(v) : std::string(); };
      out << csv_field(t.study->name) << "," << t.system << ","
          << csv_field(t.study->rows[r]) << "," << csv_field(t.study->varied_axis) << ","
          << csv_field(t.study->columns[c]) << "," << number(s.center()) << ","
          << number(s.q25) << "," << number(s.q75) << "," << number(s.iqr()) << ","
          << bound(s.center_interval().low) << "," << bound(s.center_interval().high) << ","
          << s.done << "," << s.diverged << "," << s.missing << "," << s.expected << ","
          << (marks[r][c] == Mark::kBest ? 1 : 0) << "," << (marks[r][c] == Mark::kTie ? 1 : 0)
          << "\n";
    }
  }
}

void render_summary_table(const TableEntries& t, TableFormat format, int expected_seeds,
                          const BootstrapOptions& bootstrap, CellStatistic statistic,
                          std::ostringstream& out) {
  const std::size_t rows = t.study->rows.size(), cols = t.study->columns.size();
  std::vector<std::vector<CellSummary>> cells(rows, std::vector<CellSummary>(cols));
  std::vector<std::vector<Mark>> marks(rows, std::vector<Mark>(cols, Mark::kNone));
  std::vector<std::string> unmarked;  // "column: why", for the note under the table
  for (std::size_t c = 0; c < cols; ++c) {
    const ColumnJudgement j = judge_column(t, c, expected_seeds, bootstrap, statistic);
    for (std::size_t r = 0; r < rows; ++r) {
      cells[r][c] = j.cells[r];
      marks[r][c] = j.marks[r];
    }
    if (!j.unmarkable.empty()) {
      unmarked.push_back((cols > 1 ? t.study->columns[c] + ": " : std::string()) + j.unmarkable);
    }
  }
  if (format == TableFormat::kCsv) return render_summary_csv(t, cells, marks, out);
  TextTable text{t.study, t.system, t.study->columns, {}, {}, {}};
  const std::string name = statistic_name(statistic);
  text.caption_tail = (statistic == CellStatistic::kIqm ? "IQM" : "Median") +
                      std::string(" [IQR] (bootstrap 95~\\% interval of the ") + name +
                      ") of the inference MSE over seeds.";
  std::set<int> seed_counts;
  for (const auto& row : cells) {
    for (const CellSummary& s : row) {
      if (s.finished() > 0) seed_counts.insert(s.expected);
    }
  }
  const bool counts = seed_counts.size() > 1;
  bool any_tie = false;
  for (std::size_t r = 0; r < rows; ++r) {
    text.cells.emplace_back();
    for (std::size_t c = 0; c < cols; ++c) {
      text.cells[r].push_back(summary_cell_text(cells[r][c], marks[r][c], format, counts));
      any_tie = any_tie || marks[r][c] == Mark::kTie;
    }
  }
  if (any_tie) text.notes.push_back(tie_note(statistic));
  if (counts) {
    text.notes.push_back("Cells hold different numbers of seeds: (n=k) gives each cell's; its " +
                         name + ", IQR and interval use every one of them.");
  }
  if (!unmarked.empty()) {
    std::string note = "No best marked where a row has fewer than " +
                       std::to_string(kMinSeedsForInterval) + " finished seeds (";
    for (std::size_t k = 0; k < unmarked.size(); ++k) note += (k ? "; " : "") + unmarked[k];
    text.notes.push_back(note + ").");
  }
  bool few = false;
  for (const auto& row : cells) {
    for (const CellSummary& s : row) few = few || (s.finished() > 0 && !s.has_interval());
  }
  if (few) text.notes.push_back(few_seeds_note(statistic));
  render_text(text, format, out);
}

}  // namespace

std::vector<TableCellName> undecided_cells(const std::vector<StudyTable>& studies,
                                           const std::vector<TableEntry>& entries,
                                           int expected_seeds, const BootstrapOptions& bootstrap) {
  bootstrap.validate();
  const CellIndex by_cell = index_cells(entries);
  std::vector<TableCellName> tied;
  for (const StudyTable& study : studies) {
    for (const std::string& system : study.systems) {
      const TableEntries t = gather_table(study, system, by_cell);
      for (std::size_t c = 0; c < study.columns.size(); ++c) {
        const ColumnJudgement j =
            judge_column(t, c, expected_seeds, bootstrap, CellStatistic::kMedian);
        for (std::size_t r = 0; r < study.rows.size(); ++r) {
          // Unmarkable: no intervals to compare, the cells without one are undecided.
          const bool undecided = j.unmarkable.empty() ? j.marks[r] == Mark::kTie
                                                      : !j.cells[r].has_interval();
          if (undecided) tied.push_back({study.name, system, study.rows[r], study.columns[c]});
        }
      }
    }
  }
  return tied;
}

std::string render_tables(const std::vector<StudyTable>& studies,
                          const std::vector<TableEntry>& entries, TableFormat format,
                          int expected_seeds, const BootstrapOptions& bootstrap,
                          CellStatistic statistic) {
  bootstrap.validate();
  const CellIndex by_cell = index_cells(entries);
  std::ostringstream out;
  if (format == TableFormat::kCsv) {
    out << "study,system,model,axis,column," << to_string(statistic)
        << ",q25,q75,iqr,ci_low,ci_high,done,diverged,missing,expected,best,tie\n";
  }
  for (const StudyTable& study : studies) {
    for (const std::string& system : study.systems) {
      render_summary_table(gather_table(study, system, by_cell), format, expected_seeds,
                           bootstrap, statistic, out);
    }
  }
  return out.str();
}

}  // namespace phnn
