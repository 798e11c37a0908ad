// src/apps/reduce_records.h — the per-run records of `phnn reduce --per-run`
// (phnn/report/per_run.h) read from a results file: the scalar columns, the
// trace summary (first and last validation point) and the checkpoints.
#pragma once

#include <vector>

#include "phnn/report/per_run.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"

namespace phnn {
namespace apps {

/// One RunRecord per row of /runs, in row order, its configuration from
/// `grid` (the file's own, checked against /runs/id).
std::vector<RunRecord> read_run_records(const ResultsFile& file, const Grid& grid);

}  // namespace apps
}  // namespace phnn
