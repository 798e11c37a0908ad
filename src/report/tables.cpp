// src/report/tables.cpp — median [IQR] tables of the inference MSE.
#include "phnn/report/tables.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace phnn {

double quantile_linear(std::vector<double> values, double q) {
  if (values.empty()) throw std::invalid_argument("quantile_linear: no values");
  if (!(q >= 0.0 && q <= 1.0)) {
    throw std::invalid_argument("quantile_linear: q = " + std::to_string(q) +
                                "; violated constraint: 0 <= q <= 1");
  }
  for (double v : values) {
    if (std::isnan(v)) throw std::invalid_argument("quantile_linear: values contain NaN");
  }
  std::sort(values.begin(), values.end());
  // numpy 'linear' (Hyndman & Fan type 7): h = (n - 1) q.
  const double h = static_cast<double>(values.size() - 1) * q;
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  const double frac = h - static_cast<double>(lo);
  if (frac == 0.0) return values[lo];
  return values[lo] + frac * (values[hi] - values[lo]);
}

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

CellSummary summarize_cell(const std::vector<TableEntry>& entries, int expected_seeds) {
  CellSummary s;
  // SPEC.md §5: a diverged run's error is +inf and counted, so it enters the
  // statistics (as numpy's median over the seeds' MSEs would); a cell with no
  // converged run shows no numbers.
  std::vector<double> values;
  for (const TableEntry& e : entries) {
    if (e.status == RunStatus::kDiverged ||
        (e.status == RunStatus::kDone && !std::isfinite(e.mse))) {
      ++s.diverged;
      values.push_back(std::isnan(e.mse) ? std::numeric_limits<double>::infinity() : e.mse);
    } else if (e.status == RunStatus::kDone) {
      ++s.done;
      values.push_back(e.mse);
    }
  }
  s.expected = std::max(expected_seeds, static_cast<int>(entries.size()));
  s.missing = std::max(0, s.expected - s.done - s.diverged);
  if (s.done == 0) {
    s.median = s.q25 = s.q75 = std::numeric_limits<double>::quiet_NaN();
  } else {
    s.median = quantile_linear(values, 0.5);
    s.q25 = quantile_linear(values, 0.25);
    s.q75 = quantile_linear(values, 0.75);
  }
  return s;
}

namespace {

std::string format_number(const char* format, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

// " (n=7/10)", " (d=2)" as they apply.
std::string annotations(const CellSummary& s) {
  std::string out;
  if (s.missing > 0) {
    out += " (n=" + std::to_string(s.done + s.diverged) + "/" + std::to_string(s.expected) + ")";
  }
  if (s.diverged > 0) out += " (d=" + std::to_string(s.diverged) + ")";
  return out;
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

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

// One table: summaries[row][column] and which are best.
struct TableData {
  const StudyTable* study = nullptr;
  SystemKind system = SystemKind::kHarmonic;
  std::vector<std::vector<CellSummary>> cells;
  std::vector<std::vector<bool>> best;
};

std::string heading(const TableData& t, const std::string& dash) {
  std::string h = "Study " + t.study->name + " " + dash + " " + to_string(t.system);
  if (!t.study->varied_axis.empty()) h += " (columns: " + t.study->varied_axis + ")";
  return h;
}

std::string cell_text(const CellSummary& s, bool best, TableFormat format) {
  const std::string none = format == TableFormat::kMarkdown ? "—" : "--";
  if (s.done == 0 && s.diverged == 0) return none;  // all missing
  if (s.done == 0) return none + annotations(s);    // all diverged
  std::string value = format_number("%.2e", s.median) + " [" + format_number("%.2e", s.iqr()) + "]";
  if (best) {
    value = format == TableFormat::kMarkdown ? "**" + value + "**" : "\\textbf{" + value + "}";
  }
  return value + annotations(s);
}

void render_markdown(const TableData& t, std::ostringstream& out) {
  out << "### " << heading(t, "—") << "\n\n";
  if (!t.study->title.empty()) out << "*" << t.study->title << "*\n\n";
  out << "| model |";
  for (const std::string& c : t.study->columns) out << " " << c << " |";
  out << "\n|---|";
  for (std::size_t c = 0; c < t.study->columns.size(); ++c) out << "---|";
  out << "\n";
  for (std::size_t r = 0; r < t.study->rows.size(); ++r) {
    out << "| " << t.study->rows[r] << " |";
    for (std::size_t c = 0; c < t.study->columns.size(); ++c) {
      out << " " << cell_text(t.cells[r][c], t.best[r][c], TableFormat::kMarkdown) << " |";
    }
    out << "\n";
  }
  out << "\n";
}

void render_latex(const TableData& t, std::ostringstream& out) {
  const std::size_t n = t.study->columns.size();
  out << "% " << heading(t, "---") << "\n";
  out << "\\begin{table}[ht]\n\\centering\n";
  out << "\\caption{" << latex_escape(heading(t, "---"));
  if (!t.study->title.empty()) out << ": " << latex_escape(t.study->title);
  out << ". Median [IQR] of the inference MSE over seeds.}\n";
  out << "\\begin{tabular}{l" << std::string(n, 'c') << "}\n\\hline\nModel";
  for (const std::string& c : t.study->columns) out << " & " << latex_escape(c);
  out << " \\\\\n\\hline\n";
  for (std::size_t r = 0; r < t.study->rows.size(); ++r) {
    out << latex_escape(t.study->rows[r]);
    for (std::size_t c = 0; c < n; ++c) {
      out << " & " << cell_text(t.cells[r][c], t.best[r][c], TableFormat::kLatex);
    }
    out << " \\\\\n";
  }
  out << "\\hline\n\\end{tabular}\n\\end{table}\n\n";
}

void render_csv(const TableData& t, std::ostringstream& out) {
  for (std::size_t r = 0; r < t.study->rows.size(); ++r) {
    for (std::size_t c = 0; c < t.study->columns.size(); ++c) {
      const CellSummary& s = t.cells[r][c];
      const auto number = [&](double v) {
        return s.done > 0 ? format_number("%.6e", v) : std::string();
      };
      out << csv_field(t.study->name) << "," << to_string(t.system) << ","
          << csv_field(t.study->rows[r]) << "," << csv_field(t.study->varied_axis) << ","
          << csv_field(t.study->columns[c]) << "," << number(s.median) << "," << number(s.q25)
          << "," << number(s.q75) << "," << number(s.iqr()) << "," << s.done << "," << s.diverged
          << "," << s.missing << "," << s.expected << "," << (t.best[r][c] ? 1 : 0) << "\n";
    }
  }
}

}  // namespace

std::string render_tables(const std::vector<StudyTable>& studies,
                          const std::vector<TableEntry>& entries, TableFormat format,
                          int expected_seeds) {
  // (study, system, row, column) -> entries.
  using Key = std::tuple<std::string, int, std::string, std::string>;
  std::map<Key, std::vector<TableEntry>> by_cell;
  for (const TableEntry& e : entries) {
    by_cell[Key(e.study, static_cast<int>(e.system), e.row, e.column)].push_back(e);
  }

  std::ostringstream out;
  if (format == TableFormat::kCsv) {
    out << "study,system,model,axis,column,median,q25,q75,iqr,done,diverged,missing,expected,"
           "best\n";
  }
  for (const StudyTable& study : studies) {
    for (SystemKind system : study.systems) {
      TableData t;
      t.study = &study;
      t.system = system;
      const std::size_t rows = study.rows.size(), cols = study.columns.size();
      t.cells.assign(rows, std::vector<CellSummary>(cols));
      t.best.assign(rows, std::vector<bool>(cols, false));
      for (std::size_t r = 0; r < rows; ++r) {
        for (std::size_t c = 0; c < cols; ++c) {
          const auto it = by_cell.find(
              Key(study.name, static_cast<int>(system), study.rows[r], study.columns[c]));
          t.cells[r][c] = summarize_cell(
              it == by_cell.end() ? std::vector<TableEntry>() : it->second, expected_seeds);
        }
      }
      // Best (smallest) median per column, among cells with a median.
      for (std::size_t c = 0; c < cols; ++c) {
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t r = 0; r < rows; ++r) {
          if (t.cells[r][c].done > 0) best = std::min(best, t.cells[r][c].median);
        }
        for (std::size_t r = 0; r < rows; ++r) {
          t.best[r][c] = t.cells[r][c].done > 0 && t.cells[r][c].median == best;
        }
      }
      switch (format) {
        case TableFormat::kMarkdown:
          render_markdown(t, out);
          break;
        case TableFormat::kLatex:
          render_latex(t, out);
          break;
        case TableFormat::kCsv:
          render_csv(t, out);
          break;
      }
    }
  }
  return out.str();
}

}  // namespace phnn
