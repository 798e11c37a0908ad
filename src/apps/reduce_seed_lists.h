// src/apps/reduce_seed_lists.h — `phnn reduce FILE --comparisons --seed-lists
// LISTS`: the comparisons of FILE's tables on each of several lists of seeds
// (bootstrap resamples of the seeds, drawn by the caller, e.g.
// analysis/paper_claims.py --reading four-way --stability N). Reads LISTS;
// the comparisons are report/table_comparisons.h's.
#pragma once

#include <string>
#include <vector>

#include "phnn/report/comparison.h"
#include "phnn/report/tables.h"
#include "phnn/sweep/grid.h"

namespace phnn {
namespace apps {

/// The lists of `path`: one per non-empty line, seeds separated by commas
/// (repeats allowed: "3,3,0,7"); a line starting with '#' is a comment.
/// Throws cli::UsageError naming path:line and the fix for an unreadable
/// file, a token that is not a seed, a seed that no entry has (`seeds`:
/// those the entries have), or a file without a list.
std::vector<std::vector<int>> read_seed_lists(const std::string& path,
                                              const std::vector<int>& seeds);

/// The comparisons CSV of every list (entries_for_seeds, compare_table_cells,
/// render_comparisons_csv with list = the list's number from 1): one header
/// starting "list,", then the records of list 1, 2, ...
std::string render_seed_list_comparisons(const Grid& grid, const std::vector<TableEntry>& entries,
                                         const std::vector<std::vector<int>>& lists,
                                         const ComparisonOptions& options);

}  // namespace apps
}  // namespace phnn
