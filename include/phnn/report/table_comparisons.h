// include/phnn/report/table_comparisons.h — the comparisons a study table
// invites (compare_cells of comparison.h, paired where cells_are_paired):
// within each column every pair of rows (models), within each row every
// pair of columns; and a table's entries seen through a list of seeds (a
// bootstrap resample). `phnn reduce --comparisons` prints them.
// Pure: no HDF5, no MPI.
#pragma once

#include <vector>

#include "phnn/report/comparison.h"
#include "phnn/report/tables.h"
#include "phnn/config/run_grid.h"

namespace phnn {

/// For each study of `grid` and each of its systems, in table order: per
/// column, rows i < j as (A = row i, B = row j); then per row, columns
/// k > 0 as (A = column k, B = column 0), followed by the row's other pairs
/// of columns k > l >= 1 as (A = column k, B = column l) (a 3-column row:
/// (1, 0), (2, 0), (2, 1)). A cell is the finished entries
/// (done or diverged) of its (study, system, row, column), by seed; a
/// comparison is made when both cells have a finished run. Names are
/// "study/system/row/column". Paired when cells_are_paired() holds for the
/// cells' first runs (entries need TableEntry::run).
std::vector<NamedComparison> compare_table_cells(const Grid& grid,
                                                 const std::vector<TableEntry>& entries,
                                                 const ComparisonOptions& options = {});

/// `entries` seen through a list of seeds, e.g. one bootstrap resample of a
/// results file's seeds (repeats allowed): for each slot j, a copy of every
/// entry whose seed is seeds[j], with TableEntry::seed = j. Slot j holds the
/// same seed in every cell, so runs paired by seed stay paired; a seed listed
/// twice enters twice, an unlisted seed not at all. compare_table_cells on the
/// result compares the cells on that resample.
///
///   entries_for_seeds(entries, {3, 3, 0})  // slots 0, 1: seed 3; slot 2: seed 0
std::vector<TableEntry> entries_for_seeds(const std::vector<TableEntry>& entries,
                                          const std::vector<int>& seeds);

}  // namespace phnn
