// include/phnn/report/table_comparisons.h — the comparisons a study table
// invites (compare_cells of comparison.h, paired where cells_are_paired):
// within each column every pair of rows (models), within each row every
// column against the first. `phnn reduce --comparisons` prints them.
// Pure: no HDF5, no MPI.
#pragma once

#include <vector>

#include "phnn/report/comparison.h"
#include "phnn/report/tables.h"
#include "phnn/sweep/grid.h"

namespace phnn {

/// For each study of `grid` and each of its systems, in table order: per
/// column, rows i < j as (A = row i, B = row j); then per row, columns
/// k > 0 as (A = column k, B = column 0). A cell is the finished entries
/// (done or diverged) of its (study, system, row, column), by seed; a
/// comparison is made when both cells have a finished run. Names are
/// "study/system/row/column". Paired when cells_are_paired() holds for the
/// cells' first runs (entries need TableEntry::run).
std::vector<NamedComparison> compare_table_cells(const Grid& grid,
                                                 const std::vector<TableEntry>& entries,
                                                 const ComparisonOptions& options = {});

}  // namespace phnn
