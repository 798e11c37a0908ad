// src/apps/reduce_rule.cpp — `phnn reduce --rule`: maps another sweep file's
// runs onto a results file's rows by run id (a run's id is its configuration
// and seed; the sweep's name, output and [adaptive] table are not part of it).
#include "apps/reduce_rule.h"

#include <algorithm>
#include <sstream>
#include <unordered_map>

#include "apps/cli.h"

namespace phnn {
namespace apps {

RuleView rule_view(const ResultsFile& file, const std::string& rule_path) {
  RuleView view;
  view.spec = parse_sweep_file(rule_path);
  if (!view.spec.adaptive.enabled) {
    throw cli::UsageError{"phnn reduce: --rule " + rule_path +
                          ": the sweep file has no [adaptive] table, so there is no rule to "
                          "replay; give a sweep file with one"};
  }
  view.grid = expand_grid(view.spec);
  std::unordered_map<std::string, int> row_of;
  const std::vector<std::string> ids = file.read_run_ids();
  for (std::size_t r = 0; r < ids.size(); ++r) row_of.emplace(ids[r], static_cast<int>(r));
  view.row.assign(view.grid.runs.size(), -1);
  for (std::size_t i = 0; i < view.grid.runs.size(); ++i) {
    const auto it = row_of.find(view.grid.runs[i].id());
    if (it != row_of.end()) view.row[i] = it->second;
  }
  const auto lacking = std::count(view.row.begin(), view.row.end(), -1);
  if (lacking == static_cast<std::ptrdiff_t>(view.row.size())) {
    throw cli::UsageError{"phnn reduce: --rule " + rule_path + ": none of its " +
                          std::to_string(view.row.size()) + " runs is in " + file.path() +
                          "; the rule must expand to the grid (or part of it) that wrote the "
                          "file — only its [adaptive] table may differ"};
  }
  return view;
}

std::string named_cells_csv(const SweepSpec& spec, const Grid& grid, const AdaptiveState* state,
                            const std::vector<RunStatus>& status, const std::vector<double>& mse,
                            const std::string& path) {
  if (state == nullptr || spec.adaptive.rule != AdaptiveRule::kComparisons) {
    throw cli::UsageError{"phnn reduce: --named: " + path +
                          " is not an adaptive sweep of the comparisons rule; drop --named"};
  }
  const auto named = comparison_named_cells(spec, grid, state->active, status, mse);
  std::ostringstream out;
  out << "comparison,line,cell\n";
  for (std::size_t j = 0; j < named.size(); ++j) {
    for (int c : named[j]) {
      const RunConfig& run =
          grid.runs[static_cast<std::size_t>(grid.cells[static_cast<std::size_t>(c)].runs.front())];
      out << j + 1 << "," << spec.adaptive.comparisons[j].line << "," << run.system_name() << "/"
          << model_key(run.model, run.integrator) << "/" << run.n_train << "/"
          << to_string(run.size) << "/" << to_string(run.regularizer) << "\n";
    }
  }
  return out.str();
}

}  // namespace apps
}  // namespace phnn
