// src/sweep/grid.cpp — deterministic expansion of a sweep into runs and cells.
#include "phnn/sweep/grid.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <queue>
#include <set>
#include <sstream>
#include <stdexcept>

namespace phnn {

double estimate_run_cost_s(const RunConfig& run, const CostModel& c) {
  const double member_step_us =
      c.base_us[static_cast<int>(run.model)][static_cast<int>(run.integrator)] *
      c.size_factor[static_cast<int>(run.size)] *
      (run.regularizer != Regularizer::kNone ? c.regularizer_factor : 1.0);
  const TrainerOptions& t = run.training;
  const int evaluations = 1 + t.steps / t.eval_every + (t.steps % t.eval_every != 0 ? 1 : 0);
  const double validation = evaluations * run.data.num_validation / c.reference_batch;
  const double inference = static_cast<double>(run.data.num_inference) *
                           run.data.num_inference_steps() / c.reference_batch / c.rollout_speedup *
                           (run.integrator == IntegratorKind::kDg ? c.dg_newton_factor : 1.0);
  const double batch_steps = t.steps + validation + inference;
  return batch_steps * member_step_us * 1e-6;
}

namespace {

// Varied axes of a study, in nesting order, and the label of a run's column.
struct ColumnAxes {
  bool size = false, n_train = false, regularizer = false;

  std::string name() const {
    std::vector<std::string> names;
    if (size) names.push_back("size");
    if (n_train) names.push_back("n_train");
    if (regularizer) names.push_back("regularizer");
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : "/") + n;
    return out;
  }

  std::string label(ModelSize s, int n, Regularizer r) const {
    std::vector<std::string> parts;
    if (size) parts.push_back(to_string(s));
    if (n_train) parts.push_back(std::to_string(n));
    if (regularizer) parts.push_back(to_string(r));
    if (parts.empty()) return "MSE";
    std::string out;
    for (const std::string& p : parts) out += (out.empty() ? "" : "/") + p;
    return out;
  }
};

}  // namespace

Grid expand_grid(const SweepSpec& spec, const CostModel& cost_model) {
  Grid grid;
  std::map<std::string, int> index_of;  // canonical() -> index in grid.runs
  for (const StudySpec& study : spec.studies) {
    StudyTable table;
    table.name = study.name;
    table.title = study.title;
    table.systems = study.systems;
    ColumnAxes axes;
    axes.size = study.sizes.size() > 1;
    axes.n_train = study.n_train.size() > 1;
    axes.regularizer = study.regularizers.size() > 1;
    table.varied_axis = axes.name();
    for (const auto& [model, integrator] : study.models) {
      table.rows.push_back(model_label(model, integrator));
    }
    for (ModelSize size : study.sizes) {
      for (int n : study.n_train) {
        for (Regularizer reg : study.regularizers) {
          const std::string label = axes.label(size, n, reg);
          if (std::find(table.columns.begin(), table.columns.end(), label) == table.columns.end()) {
            table.columns.push_back(label);
          }
        }
      }
    }

    for (SystemKind system : study.systems) {
      for (const auto& [model, integrator] : study.models) {
        for (ModelSize size : study.sizes) {
          for (int n : study.n_train) {
            for (Regularizer reg : study.regularizers) {
              for (int seed : study.seeds) {
                RunConfig run;
                run.system = system;
                run.model = model;
                run.integrator = integrator;
                run.size = size;
                run.n_train = n;
                run.regularizer = reg;
                run.seed = seed;
                run.physics = spec.physics.at(system);
                run.data = spec.data;
                run.training = spec.training;
                const auto [it, inserted] =
                    index_of.emplace(run.canonical(), static_cast<int>(grid.runs.size()));
                if (inserted) {
                  grid.runs.push_back(run);
                  grid.run_studies.emplace_back();
                }
                std::vector<std::string>& studies = grid.run_studies[it->second];
                if (std::find(studies.begin(), studies.end(), study.name) == studies.end()) {
                  studies.push_back(study.name);
                }
                table.runs.push_back(it->second);
                table.run_columns.push_back(axes.label(size, n, reg));
              }
            }
          }
        }
      }
    }
    grid.studies.push_back(std::move(table));
  }

  // Cells: runs with equal cell_key(), seeds ascending; largest cost first.
  std::map<std::string, int> cell_of;
  for (int i = 0; i < static_cast<int>(grid.runs.size()); ++i) {
    const std::string key = grid.runs[i].cell_key();
    const auto [it, inserted] = cell_of.emplace(key, static_cast<int>(grid.cells.size()));
    if (inserted) {
      grid.cells.emplace_back();
      grid.cells.back().key = key;
    }
    Cell& cell = grid.cells[it->second];
    cell.runs.push_back(i);
    cell.estimated_cost_s += estimate_run_cost_s(grid.runs[i], cost_model);
  }
  for (Cell& cell : grid.cells) {
    std::sort(cell.runs.begin(), cell.runs.end(),
              [&](int a, int b) { return grid.runs[a].seed < grid.runs[b].seed; });
  }
  std::sort(grid.cells.begin(), grid.cells.end(), [](const Cell& a, const Cell& b) {
    if (a.estimated_cost_s != b.estimated_cost_s) return a.estimated_cost_s > b.estimated_cost_s;
    return a.key < b.key;
  });
  for (const Cell& cell : grid.cells) grid.estimated_cost_s += cell.estimated_cost_s;
  return grid;
}

double greedy_makespan_s(std::vector<double> cell_costs_s, int ranks) {
  if (ranks < 1) {
    throw std::invalid_argument("greedy_makespan_s: ranks = " + std::to_string(ranks) +
                                "; need at least 1 rank");
  }
  std::sort(cell_costs_s.begin(), cell_costs_s.end(), std::greater<double>());
  // Min-heap of rank loads: each cell goes to the rank that is free first.
  std::priority_queue<double, std::vector<double>, std::greater<double>> loads;
  for (int r = 0; r < ranks; ++r) loads.push(0.0);
  double makespan = 0.0;
  for (double cost : cell_costs_s) {
    const double load = loads.top() + cost;
    loads.pop();
    loads.push(load);
    makespan = std::max(makespan, load);
  }
  return makespan;
}

namespace {

std::string format_duration(double seconds) {
  char buf[64];
  if (seconds < 10.0) {
    std::snprintf(buf, sizeof buf, "%.1f s", seconds);
  } else if (seconds < 120.0) {
    std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  } else if (seconds < 7200.0) {
    std::snprintf(buf, sizeof buf, "%.1f min", seconds / 60.0);
  } else {
    std::snprintf(buf, sizeof buf, "%.1f h", seconds / 3600.0);
  }
  return buf;
}

// "1 system", "3 systems".
std::string count(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

}  // namespace

std::string dry_run_summary(const Grid& grid, int ranks) {
  if (ranks < 1) {
    throw std::invalid_argument("dry_run_summary: ranks = " + std::to_string(ranks) +
                                "; need at least 1 rank");
  }
  std::vector<double> costs;
  for (const Cell& cell : grid.cells) costs.push_back(cell.estimated_cost_s);
  const double wall = greedy_makespan_s(costs, ranks);

  std::ostringstream out;
  out << grid.runs.size() << " runs in " << grid.cells.size() << " cells\n";
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.3g", grid.estimated_cost_s / 3600.0);
  out << "estimated cost: " << buf << " core-hours (" << format_duration(grid.estimated_cost_s)
      << " on one core); wall time on " << ranks << (ranks == 1 ? " rank: " : " ranks: ")
      << format_duration(wall)
      << " (largest cell first to the first free rank; cost model fit on one "
         "development machine, see include/phnn/sweep/grid.h)\n";
  if (!grid.cells.empty()) {
    out << "largest cell: " << format_duration(grid.cells.front().estimated_cost_s)
        << ", smallest: " << format_duration(grid.cells.back().estimated_cost_s) << "\n";
  }

  std::map<std::string, int> cell_index;  // cell_key -> index in grid.cells
  for (int c = 0; c < static_cast<int>(grid.cells.size()); ++c) cell_index[grid.cells[c].key] = c;
  for (const StudyTable& study : grid.studies) {
    std::set<int> runs(study.runs.begin(), study.runs.end());
    std::set<int> cells;
    int shared = 0;
    for (int r : runs) {
      cells.insert(cell_index[grid.runs[r].cell_key()]);
      if (grid.run_studies[r].size() > 1) ++shared;
    }
    out << "study " << study.name << ": " << runs.size() << " runs in " << cells.size()
        << " cells (" << count(study.systems.size(), "system") << " x "
        << count(study.rows.size(), "model") << " x " << count(study.columns.size(), "column");
    if (!study.varied_axis.empty()) out << " of " << study.varied_axis;
    out << "), " << shared << " shared with other studies";
    if (!study.title.empty()) out << " — " << study.title;
    out << "\n";
  }
  return out.str();
}

}  // namespace phnn
