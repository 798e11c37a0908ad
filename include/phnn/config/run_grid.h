// include/phnn/config/run_grid.h — the runs of a sweep, grouped into cells
// and studies: what `expand_grid` (phnn/sweep/grid.h) makes of a sweep file
// and what the report's tables read. Plain data, no sweep-file parsing.
#pragma once

#include <string>
#include <vector>

#include "phnn/config/run_config.h"

namespace phnn {

/// Runs of one cell: the same configuration but the seed (equal
/// RunConfig::cell_key()). Its runs are trained as one stack, or split into
/// member groups (phnn/sweep/work_plan.h).
struct Cell {
  /// RunConfig::cell_key() of its runs.
  std::string key;
  /// Indices into Grid::runs, sorted by seed.
  std::vector<int> runs;
  /// estimate_group_cost_s(E) = fixed_cost_s + E * member_cost_s: a stack of
  /// E of its runs [s].
  double fixed_cost_s = 0.0, member_cost_s = 0.0;
  /// Cost of all its runs as one stack: cost_s(runs.size()).
  double estimated_cost_s = 0.0;

  /// Cost of a stack of `members` of its runs [s].
  double cost_s(int members) const { return fixed_cost_s + members * member_cost_s; }
};

/// What one study's tables are made of (paper Appendix F; docs/METHOD.md §6): one
/// table per system, rows = models, columns = values of the varied axis.
struct StudyTable {
  /// StudySpec::name and title.
  std::string name, title;
  /// The axis with more than one value, other than seeds, systems and
  /// models: "size", "n_train", "regularizer" or "lambda"; "" if none varies
  /// (then there is one column, "MSE"). If several vary, their names joined
  /// by "/" in nesting order (e.g. "size/n_train") and columns are their
  /// product.
  std::string varied_axis;
  /// Column labels in file order: "25", "100"; "small"; "none", "cn" (the
  /// sweep-file spelling of the values). When `lambdas` varies, regularized
  /// runs carry their weight ("cn/lambda=1e-05", the shortest spelling that
  /// reads back exactly) and unregularized ones do not ("none"), so runs of
  /// different weights never share a cell.
  std::vector<std::string> columns;
  /// Model labels in file order, e.g. "NODE-RK2", "PHNN-JR-DG".
  std::vector<std::string> rows;
  /// StudySpec::systems (built-in names and system files' names).
  std::vector<std::string> systems;
  /// Indices into Grid::runs of every run of the study (shared runs too), in
  /// expansion order.
  std::vector<int> runs;
  /// Column label of runs[i] (parallel to runs).
  std::vector<std::string> run_columns;
};

/// A sweep expanded into distinct runs.
///
///   const Grid grid = expand_grid(parse_sweep_file("sweeps/paper.toml"));
///   std::cout << grid.runs.size() << " runs in " << grid.cells.size() << " cells\n";
struct Grid {
  /// Distinct runs (by RunConfig::canonical()), in order of first appearance:
  /// studies in file order, then axes nested system, model, size, n_train,
  /// regularizer, lambda (regularized runs only), seed (seed fastest).
  std::vector<RunConfig> runs;
  /// Names of the studies containing runs[i], in study order.
  std::vector<std::vector<std::string>> run_studies;
  /// Cells sorted by estimated cost, largest first, ties by key: the order
  /// in which work is handed out (largest-first scheduling).
  std::vector<Cell> cells;
  /// One per study, in file order.
  std::vector<StudyTable> studies;
  /// Sum of Cell::estimated_cost_s (every cell unsplit) [core-seconds].
  double estimated_cost_s = 0.0;
};

}  // namespace phnn
