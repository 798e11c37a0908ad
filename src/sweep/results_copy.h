// src/sweep/results_copy.h — internal to src/sweep: copying finished rows,
// provenance and layouts between results files (new versions of a grown
// sweep, merged shards), and the bitwise comparison of two results.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"

namespace phnn {
namespace results_copy {

/// Every field of both equal, doubles bit for bit (their journal encodings),
/// but the clocks: wall times of the run, its trace and its checkpoints,
/// and its run times.
bool same_result(const RunResult& a, const RunResult& b);

/// The layout that holds rows of both.
ResultsLayout wider_layout(const ResultsLayout& a, const ResultsLayout& b);

/// Appends `from`'s provenance sessions, in order, to `to` (serial files).
void copy_sessions(const ResultsFile& from, ResultsFile* to);

/// The one way rows move between results files (merge, a grown sweep):
/// copies each (row of `from`, row of `to`) pair whose row is intact (the
/// check of `phnn verify`: ResultsFile::row_damaged), result and run times.
/// A damaged row is never copied as it stands (write_run would give the
/// wrong values a valid checksum): its pair is returned, its row of `to`
/// left pending, and the caller repairs it from a journal, takes another
/// copy, or names it.
std::vector<std::pair<int, int>> copy_rows(const ResultsFile& from,
                                           const std::vector<std::pair<int, int>>& rows,
                                           ResultsFile* to);

/// The studies of each run of `grid`, joined for ResultsFile::create ("I,II").
std::vector<std::string> joined_studies(const Grid& grid);

}  // namespace results_copy
}  // namespace phnn
