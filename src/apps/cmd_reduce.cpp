// src/apps/cmd_reduce.cpp — `phnn reduce results.h5`: the paper's Appendix-F
// tables (median [IQR] of the inference MSE over seeds) from a results file,
// complete or partial.
#include <algorithm>
#include <iostream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "phnn/report/tables.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/results_file.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace apps {

int run_reduce(int argc, char** argv, int first) {
  cli::Parser parser("reduce",
                     "Prints, for each study and system of the sweep that wrote FILE, a table with\n"
                     "rows = models, columns = the study's varied axis and cells = median [IQR] of\n"
                     "the inference MSE over seeds (quartiles: numpy's default linear\n"
                     "interpolation). Works on partial files: missing and diverged runs are counted.");
  parser.positional("FILE", "results file written by `phnn sweep`");
  parser.option("format", "markdown | latex | csv", "markdown");
  if (!parser.parse(argc, argv, first)) return 0;
  const TableFormat format = parse_table_format(parser.get("format"));
  const std::string path = parser.get("FILE");
  const ResultsFile file = ResultsFile::open_read_only(path);
  const SweepSpec spec = parse_sweep_text(file.sweep_text(), path + "@sweep_text");
  const Grid grid = expand_grid(spec);
  const auto ids = file.read_run_ids();
  if (ids.size() != grid.runs.size()) {
    throw std::runtime_error(path + ": holds " + std::to_string(ids.size()) +
                             " runs but its sweep text expands to " +
                             std::to_string(grid.runs.size()) +
                             "; was it written by another phnn version?");
  }
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] != grid.runs[i].id()) {
      throw std::runtime_error(path + ": run " + std::to_string(i) + " has id " + ids[i] +
                               " but the sweep text gives " + grid.runs[i].id() +
                               "; was it written by another phnn version?");
    }
  }
  const auto statuses = file.read_statuses();
  const auto mse = file.read_double_column("mse");
  int counts[4] = {0, 0, 0, 0};
  for (RunStatus s : statuses) ++counts[static_cast<int>(s)];
  std::size_t expected_seeds = 0;
  for (const StudySpec& s : spec.studies) expected_seeds = std::max(expected_seeds, s.seeds.size());
  if (format == TableFormat::kMarkdown) {
    std::cout << "# " << spec.name << " — " << path << "\n\n"
              << counts[1] << " done, " << counts[2] << " diverged, " << counts[3] << " failed, "
              << counts[0] << " pending of " << file.num_runs()
              << " runs. Cells: median [IQR] of the inference MSE (Eq. 31) over seeds; "
                 "**bold** = best median per column; (d=k) diverged runs, (n=k/N) finished "
                 "of expected.\n\n";
  }
  std::cout << render_tables(grid.studies, make_table_entries(grid, statuses, mse), format,
                             static_cast<int>(expected_seeds));
  return 0;
}

}  // namespace apps
}  // namespace phnn
