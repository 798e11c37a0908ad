// src/report/table_text.h — shared by tables.cpp and seeds_summary.cpp
// only: how runs are indexed into table cells, how a cell counts diverged
// runs, and the Markdown/LaTeX text layout of one table.
#pragma once

#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "phnn/report/tables.h"

namespace phnn {
namespace table_text {

/// A diverged run (or a done run whose MSE is not finite) enters the
/// statistics as +inf: its error is +inf and counted.
bool counts_as_diverged(const TableEntry& e);
bool counts_as_done(const TableEntry& e);

/// printf of one number; "inf", "-inf", "nan" spelled out.
std::string format_number(const char* format, double value);
/// " (n=7/10)", " (d=2)" as they apply.
std::string annotations(int finished, int diverged, int missing, int expected);
std::string latex_escape(const std::string& text);

/// (study, system, row, column) -> entries.
using CellKey = std::tuple<std::string, std::string, std::string, std::string>;
using CellIndex = std::map<CellKey, std::vector<TableEntry>>;
CellIndex index_cells(const std::vector<TableEntry>& entries);

/// The entries of one table, [row][column].
struct TableEntries {
  const StudyTable* study = nullptr;
  std::string system;
  std::vector<std::vector<std::vector<TableEntry>>> cells;
};
TableEntries gather_table(const StudyTable& study, const std::string& system,
                          const CellIndex& by_cell);

/// One table as text, for the Markdown and LaTeX layouts.
struct TextTable {
  const StudyTable* study = nullptr;
  std::string system;
  std::vector<std::string> columns;             // column labels
  std::vector<std::vector<std::string>> cells;  // [row][column], already formatted
  std::string caption_tail;                     // LaTeX: what the cells are
  std::vector<std::string> notes;               // printed under the table
};
/// Markdown or LaTeX (CSV is written by the callers).
void render_text(const TextTable& t, TableFormat format, std::ostringstream& out);

}  // namespace table_text
}  // namespace phnn
