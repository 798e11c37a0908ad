// src/report/seeds_summary.cpp — `phnn reduce --seeds-summary`: per cell,
// the seeds below / above the column's geometric midpoint, so a bimodal
// cell (a median that one seed can flip) is visible.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "phnn/report/tables.h"
#include "report/csv.h"
#include "report/table_text.h"

namespace phnn {
namespace {

using namespace table_text;
using internal::csv_field;

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
        out << csv_field(t.study->name) << "," << t.system << ","
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
    for (const std::string& system : study.systems) {
      render_seeds_table(gather_table(study, system, by_cell), format, expected_seeds, out);
    }
  }
  return out.str();
}

}  // namespace phnn
