// src/report/tables.cpp — median [IQR] (bootstrap interval) tables of the
// inference MSE with best/tie marks, and the seeds-per-mode view.
#include "phnn/report/tables.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "report/csv.h"

namespace phnn {

std::vector<TableEntry> make_table_entries(const Grid& grid, const std::vector<RunStatus>& status,
                                           const std::vector<double>& mse) {
  if (status.size() != grid.runs.size() || mse.size() != grid.runs.size()) {
    throw std::invalid_argument("make_table_entries: got " + std::to_string(status.size()) +
                                " statuses and " + std::to_string(mse.size()) +
                                " MSEs for a grid of " + std::to_string(grid.runs.size()) +
                                " runs; pass one of each per run");
  }
  std::vector<TableEntry> entries;
  for (const StudyTable& study : grid.studies) {
    for (std::size_t i = 0; i < study.runs.size(); ++i) {
      const int r = study.runs[i];
      const RunConfig& run = grid.runs[r];
      TableEntry e;
      e.study = study.name;
      e.system = run.system;
      e.row = model_label(run.model, run.integrator);
      e.column = study.run_columns[i];
      e.status = status[r];
      e.mse = mse[r];
      entries.push_back(std::move(e));
    }
  }
  return entries;
}

TableFormat parse_table_format(const std::string& name) {
  if (name == "markdown") return TableFormat::kMarkdown;
  if (name == "latex") return TableFormat::kLatex;
  if (name == "csv") return TableFormat::kCsv;
  throw std::invalid_argument("unknown table format \"" + name +
                              "\"; expected one of: markdown, latex, csv");
}

std::string to_string(TableFormat format) {
  switch (format) {
    case TableFormat::kMarkdown:
      return "markdown";
    case TableFormat::kLatex:
      return "latex";
    case TableFormat::kCsv:
      return "csv";
  }
  return "unknown";
}

namespace {

// A diverged run (or a done run whose MSE is not finite) enters the
// statistics as +inf: its error is +inf and counted.
bool counts_as_diverged(const TableEntry& e) {
  return e.status == RunStatus::kDiverged || (e.status == RunStatus::kDone && !std::isfinite(e.mse));
}

bool counts_as_done(const TableEntry& e) {
  return e.status == RunStatus::kDone && std::isfinite(e.mse);
}

}  // namespace

double CellSummary::iqr() const {
  if (std::isinf(q75) && q75 > 0) return q75;
  return q75 - q25;
}

CellSummary summarize_cell(const std::vector<TableEntry>& entries, int expected_seeds,
                           const BootstrapOptions& bootstrap) {
  CellSummary s;
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
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.median = s.q25 = s.q75 = nan;
    s.median_interval = Interval{nan, nan};
    return s;
  }
  std::sort(values.begin(), values.end());
  s.median = quantile_linear_sorted(values, 0.5);
  s.q25 = quantile_linear_sorted(values, 0.25);
  s.q75 = quantile_linear_sorted(values, 0.75);
  s.median_interval = bootstrap_median_interval(values, bootstrap);
  return s;
}

namespace {

const char* const kTieNote =
    "(tie): no clear best in this column: the bootstrap 95 % interval of its smallest median "
    "overlaps the intervals of the other cells marked (tie), so none is bold.";

std::string format_number(const char* format, double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (std::isnan(value)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

// " (n=7/10)", " (d=2)" as they apply.
std::string annotations(int finished, int diverged, int missing, int expected) {
  std::string out;
  if (missing > 0) out += " (n=" + std::to_string(finished) + "/" + std::to_string(expected) + ")";
  if (diverged > 0) out += " (d=" + std::to_string(diverged) + ")";
  return out;
}

std::string annotations(const CellSummary& s) {
  return annotations(s.finished(), s.diverged, s.missing, s.expected);
}

std::string latex_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '_':
      case '&':
      case '%':
      case '#':
      case '$':
      case '{':
      case '}':
        out += '\\';
        out += c;
        break;
      case '\\':
        out += "\\textbackslash{}";
        break;
      case '~':
        out += "\\textasciitilde{}";
        break;
      case '^':
        out += "\\textasciicircum{}";
        break;
      default:
        out += c;
    }
  }
  return out;
}

using internal::csv_field;

// (study, system, row, column) -> entries.
using CellKey = std::tuple<std::string, int, std::string, std::string>;
using CellIndex = std::map<CellKey, std::vector<TableEntry>>;

CellIndex index_cells(const std::vector<TableEntry>& entries) {
  CellIndex by_cell;
  for (const TableEntry& e : entries) {
    by_cell[CellKey(e.study, static_cast<int>(e.system), e.row, e.column)].push_back(e);
  }
  return by_cell;
}

// The entries of one table, [row][column].
struct TableEntries {
  const StudyTable* study = nullptr;
  SystemKind system = SystemKind::kHarmonic;
  std::vector<std::vector<std::vector<TableEntry>>> cells;
};

TableEntries gather_table(const StudyTable& study, SystemKind system, const CellIndex& by_cell) {
  TableEntries t;
  t.study = &study;
  t.system = system;
  t.cells.assign(study.rows.size(), std::vector<std::vector<TableEntry>>(study.columns.size()));
  for (std::size_t r = 0; r < study.rows.size(); ++r) {
    for (std::size_t c = 0; c < study.columns.size(); ++c) {
      const auto it =
          by_cell.find(CellKey(study.name, static_cast<int>(system), study.rows[r], study.columns[c]));
      if (it != by_cell.end()) t.cells[r][c] = it->second;
    }
  }
  return t;
}

// One table as text, for the Markdown and LaTeX layouts.
struct TextTable {
  const StudyTable* study = nullptr;
  SystemKind system = SystemKind::kHarmonic;
  std::vector<std::string> columns;             // column labels
  std::vector<std::vector<std::string>> cells;  // [row][column], already formatted
  std::string caption_tail;                     // LaTeX: what the cells are
  std::vector<std::string> notes;               // printed under the table
};

std::string heading(const TextTable& t, const std::string& dash) {
  std::string h = "Study " + t.study->name + " " + dash + " " + to_string(t.system);
  if (!t.study->varied_axis.empty()) h += " (columns: " + t.study->varied_axis + ")";
  return h;
}

void render_markdown(const TextTable& t, std::ostringstream& out) {
  out << "### " << heading(t, "—") << "\n\n";
  if (!t.study->title.empty()) out << "*" << t.study->title << "*\n\n";
  out << "| model |";
  for (const std::string& c : t.columns) out << " " << c << " |";
  out << "\n|---|";
  for (std::size_t c = 0; c < t.columns.size(); ++c) out << "---|";
  out << "\n";
  for (std::size_t r = 0; r < t.study->rows.size(); ++r) {
    out << "| " << t.study->rows[r] << " |";
    for (const std::string& cell : t.cells[r]) out << " " << cell << " |";
    out << "\n";
  }
  out << "\n";
  for (const std::string& note : t.notes) out << note << "\n\n";
}

void render_latex(const TextTable& t, std::ostringstream& out) {
  const std::size_t n = t.columns.size();
  out << "% " << heading(t, "---") << "\n";
  out << "\\begin{table}[ht]\n\\centering\n";
  out << "\\caption{" << latex_escape(heading(t, "---"));
  if (!t.study->title.empty()) out << ": " << latex_escape(t.study->title);
  out << ". " << t.caption_tail << "}\n";
  out << "\\begin{tabular}{l" << std::string(n, 'c') << "}\n\\hline\nModel";
  for (const std::string& c : t.columns) out << " & " << latex_escape(c);
  out << " \\\\\n\\hline\n";
  for (std::size_t r = 0; r < t.study->rows.size(); ++r) {
    out << latex_escape(t.study->rows[r]);
    for (const std::string& cell : t.cells[r]) out << " & " << cell;
    out << " \\\\\n";
  }
  out << "\\hline\n\\end{tabular}\n";
  for (const std::string& note : t.notes) {
    out << "\\par\\smallskip{\\footnotesize " << latex_escape(note) << "}\n";
  }
  out << "\\end{table}\n\n";
}

void render_text(const TextTable& t, TableFormat format, std::ostringstream& out) {
  if (format == TableFormat::kMarkdown) render_markdown(t, out);
  if (format == TableFormat::kLatex) render_latex(t, out);
}

enum class Mark { kNone, kBest, kTie };

// Best of one column (CellSummary order = rows): the smallest finite median
// is best if its interval overlaps no other finished cell's interval; else it
// and every cell overlapping it (or with an equal median) are a tie. A cell
// whose interval is [+inf, +inf] (all or nearly all runs diverged) cannot be
// smaller than anything: sharing the point +inf is no tie.
std::vector<Mark> mark_column(const std::vector<CellSummary>& column) {
  std::vector<Mark> marks(column.size(), Mark::kNone);
  int best = -1;
  for (std::size_t r = 0; r < column.size(); ++r) {
    const CellSummary& s = column[r];
    if (s.finished() == 0 || !std::isfinite(s.median)) continue;
    if (best < 0 || s.median < column[best].median) best = static_cast<int>(r);
  }
  if (best < 0) return marks;
  const CellSummary& b = column[best];
  bool tied = false;
  for (std::size_t r = 0; r < column.size(); ++r) {
    const CellSummary& s = column[r];
    if (static_cast<int>(r) == best || s.finished() == 0) continue;
    if (std::isinf(s.median_interval.low)) continue;
    if (s.median_interval.overlaps(b.median_interval) || s.median == b.median) {
      marks[r] = Mark::kTie;
      tied = true;
    }
  }
  marks[best] = tied ? Mark::kTie : Mark::kBest;
  return marks;
}

std::string summary_cell_text(const CellSummary& s, Mark mark, TableFormat format) {
  const std::string none = format == TableFormat::kMarkdown ? "—" : "--";
  if (s.finished() == 0) return none;                        // all missing
  // All diverged at +inf: median and interval say nothing more than the count.
  if (s.done == 0 && std::isinf(s.median) && std::isinf(s.median_interval.low)) {
    return "inf" + annotations(s);
  }
  std::string value = format_number("%.2e", s.median) + " [" + format_number("%.2e", s.iqr()) +
                      "] (" + format_number("%.2e", s.median_interval.low) + ", " +
                      format_number("%.2e", s.median_interval.high) + ")";
  if (mark == Mark::kBest) {
    value = format == TableFormat::kMarkdown ? "**" + value + "**" : "\\textbf{" + value + "}";
  }
  if (mark == Mark::kTie) value += " (tie)";
  return value + annotations(s);
}

void render_summary_csv(const TableEntries& t, const std::vector<std::vector<CellSummary>>& cells,
                        const std::vector<std::vector<Mark>>& marks, std::ostringstream& out) {
  for (std::size_t r = 0; r < t.study->rows.size(); ++r) {
    for (std::size_t c = 0; c < t.study->columns.size(); ++c) {
      const CellSummary& s = cells[r][c];
      const auto number = [&](double v) {
        return s.finished() > 0 ? format_number("%.6e", v) : std::string();
      };
      out << csv_field(t.study->name) << "," << to_string(t.system) << ","
          << csv_field(t.study->rows[r]) << "," << csv_field(t.study->varied_axis) << ","
          << csv_field(t.study->columns[c]) << "," << number(s.median) << "," << number(s.q25)
          << "," << number(s.q75) << "," << number(s.iqr()) << ","
          << number(s.median_interval.low) << "," << number(s.median_interval.high) << ","
          << s.done << "," << s.diverged << "," << s.missing << "," << s.expected << ","
          << (marks[r][c] == Mark::kBest ? 1 : 0) << "," << (marks[r][c] == Mark::kTie ? 1 : 0)
          << "\n";
    }
  }
}

void render_summary_table(const TableEntries& t, TableFormat format, int expected_seeds,
                          const BootstrapOptions& bootstrap, std::ostringstream& out) {
  const std::size_t rows = t.study->rows.size(), cols = t.study->columns.size();
  std::vector<std::vector<CellSummary>> cells(rows, std::vector<CellSummary>(cols));
  std::vector<std::vector<Mark>> marks(rows, std::vector<Mark>(cols, Mark::kNone));
  for (std::size_t c = 0; c < cols; ++c) {
    std::vector<CellSummary> column(rows);
    for (std::size_t r = 0; r < rows; ++r) {
      column[r] = cells[r][c] = summarize_cell(t.cells[r][c], expected_seeds, bootstrap);
    }
    const std::vector<Mark> column_marks = mark_column(column);
    for (std::size_t r = 0; r < rows; ++r) marks[r][c] = column_marks[r];
  }
  if (format == TableFormat::kCsv) return render_summary_csv(t, cells, marks, out);
  TextTable text{t.study, t.system, t.study->columns, {}, {}, {}};
  text.caption_tail =
      "Median [IQR] (bootstrap 95~\\% interval of the median) of the inference MSE over seeds.";
  bool any_tie = false;
  for (std::size_t r = 0; r < rows; ++r) {
    text.cells.emplace_back();
    for (std::size_t c = 0; c < cols; ++c) {
      text.cells[r].push_back(summary_cell_text(cells[r][c], marks[r][c], format));
      any_tie = any_tie || marks[r][c] == Mark::kTie;
    }
  }
  if (any_tie) text.notes.push_back(kTieNote);
  render_text(text, format, out);
}

}  // namespace

std::string render_tables(const std::vector<StudyTable>& studies,
                          const std::vector<TableEntry>& entries, TableFormat format,
                          int expected_seeds, const BootstrapOptions& bootstrap) {
  bootstrap.validate();
  const CellIndex by_cell = index_cells(entries);
  std::ostringstream out;
  if (format == TableFormat::kCsv) {
    out << "study,system,model,axis,column,median,q25,q75,iqr,ci_low,ci_high,done,diverged,"
           "missing,expected,best,tie\n";
  }
  for (const StudyTable& study : studies) {
    for (SystemKind system : study.systems) {
      render_summary_table(gather_table(study, system, by_cell), format, expected_seeds,
                           bootstrap, out);
    }
  }
  return out.str();
}

namespace {

struct SeedCounts {
  int below = 0, above = 0, diverged = 0, missing = 0, expected = 0;
};

// sqrt(min * max) of the finite positive MSEs of one column; NaN if none.
double geometric_midpoint(const TableEntries& t, std::size_t column) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (const auto& row : t.cells) {
    for (const TableEntry& e : row[column]) {
      if (!counts_as_done(e) || !(e.mse > 0.0)) continue;
      lo = std::min(lo, e.mse);
      hi = std::max(hi, e.mse);
    }
  }
  if (hi == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(lo) * std::sqrt(hi);  // no overflow or underflow of lo * hi
}

SeedCounts count_seeds(const std::vector<TableEntry>& entries, double midpoint,
                       int expected_seeds) {
  SeedCounts n;
  for (const TableEntry& e : entries) {
    if (counts_as_diverged(e)) {
      ++n.diverged;
      ++n.above;
    } else if (counts_as_done(e)) {
      ++(e.mse <= midpoint ? n.below : n.above);  // NaN midpoint: above
    }
  }
  n.expected = std::max(expected_seeds, static_cast<int>(entries.size()));
  n.missing = std::max(0, n.expected - n.below - n.above);
  return n;
}

void render_seeds_table(const TableEntries& t, TableFormat format, int expected_seeds,
                        std::ostringstream& out) {
  const std::size_t rows = t.study->rows.size(), cols = t.study->columns.size();
  std::vector<double> midpoints(cols);
  for (std::size_t c = 0; c < cols; ++c) midpoints[c] = geometric_midpoint(t, c);
  if (format == TableFormat::kCsv) {
    for (std::size_t r = 0; r < rows; ++r) {
      for (std::size_t c = 0; c < cols; ++c) {
        const SeedCounts n = count_seeds(t.cells[r][c], midpoints[c], expected_seeds);
        out << csv_field(t.study->name) << "," << to_string(t.system) << ","
            << csv_field(t.study->rows[r]) << "," << csv_field(t.study->varied_axis) << ","
            << csv_field(t.study->columns[c]) << ","
            << (std::isnan(midpoints[c]) ? "" : format_number("%.6e", midpoints[c])) << ","
            << n.below << "," << n.above << "," << n.diverged << "," << n.missing << ","
            << n.expected << "\n";
      }
    }
    return;
  }
  const std::string none = format == TableFormat::kMarkdown ? "—" : "--";
  TextTable text{t.study, t.system, {}, {}, {}, {}};
  for (std::size_t c = 0; c < cols; ++c) {
    text.columns.push_back(t.study->columns[c] + " (m=" +
                           (std::isnan(midpoints[c]) ? none : format_number("%.2e", midpoints[c])) +
                           ")");
  }
  text.caption_tail = "Seeds with inference MSE below / above the column's geometric midpoint m.";
  for (std::size_t r = 0; r < rows; ++r) {
    text.cells.emplace_back();
    for (std::size_t c = 0; c < cols; ++c) {
      const SeedCounts n = count_seeds(t.cells[r][c], midpoints[c], expected_seeds);
      text.cells[r].push_back(
          n.below + n.above == 0
              ? none
              : std::to_string(n.below) + " / " + std::to_string(n.above) +
                    annotations(n.below + n.above, n.diverged, n.missing, n.expected));
    }
  }
  text.notes.push_back(
      "below / above: seeds with MSE <= m / > m, m = sqrt(min * max) of the column's finite "
      "MSEs (all models); diverged runs (d=k) count above.");
  render_text(text, format, out);
}

}  // namespace

std::string render_seeds_summary(const std::vector<StudyTable>& studies,
                                 const std::vector<TableEntry>& entries, TableFormat format,
                                 int expected_seeds) {
  const CellIndex by_cell = index_cells(entries);
  std::ostringstream out;
  if (format == TableFormat::kCsv) {
    out << "study,system,model,axis,column,midpoint,below,above,diverged,missing,expected\n";
  }
  for (const StudyTable& study : studies) {
    for (SystemKind system : study.systems) {
      render_seeds_table(gather_table(study, system, by_cell), format, expected_seeds, out);
    }
  }
  return out.str();
}

}  // namespace phnn
