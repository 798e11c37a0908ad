// src/report/table_text.cpp — see table_text.h.
#include "report/table_text.h"

#include <cmath>
#include <cstdio>

namespace phnn {
namespace table_text {

bool counts_as_diverged(const TableEntry& e) {
  return e.status == RunStatus::kDiverged || (e.status == RunStatus::kDone && !std::isfinite(e.mse));
}

bool counts_as_done(const TableEntry& e) {
  return e.status == RunStatus::kDone && std::isfinite(e.mse);
}

std::string format_number(const char* format, double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (std::isnan(value)) return "nan";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

std::string annotations(int finished, int diverged, int missing, int expected) {
  std::string out;
  if (missing > 0) out += " (n=" + std::to_string(finished) + "/" + std::to_string(expected) + ")";
  if (diverged > 0) out += " (d=" + std::to_string(diverged) + ")";
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

CellIndex index_cells(const std::vector<TableEntry>& entries) {
  CellIndex by_cell;
  for (const TableEntry& e : entries) {
    by_cell[CellKey(e.study, e.system, e.row, e.column)].push_back(e);
  }
  return by_cell;
}


TableEntries gather_table(const StudyTable& study, const std::string& system,
                          const CellIndex& by_cell) {
  TableEntries t;
  t.study = &study;
  t.system = system;
  t.cells.assign(study.rows.size(), std::vector<std::vector<TableEntry>>(study.columns.size()));
  for (std::size_t r = 0; r < study.rows.size(); ++r) {
    for (std::size_t c = 0; c < study.columns.size(); ++c) {
      const auto it =
          by_cell.find(CellKey(study.name, system, study.rows[r], study.columns[c]));
      if (it != by_cell.end()) t.cells[r][c] = it->second;
    }
  }
  return t;
}

namespace {

std::string heading(const TextTable& t, const std::string& dash) {
  std::string h = "Study " + t.study->name + " " + dash + " " + t.system;
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

}  // namespace

void render_text(const TextTable& t, TableFormat format, std::ostringstream& out) {
  if (format == TableFormat::kMarkdown) render_markdown(t, out);
  if (format == TableFormat::kLatex) render_latex(t, out);
}

}  // namespace table_text
}  // namespace phnn
