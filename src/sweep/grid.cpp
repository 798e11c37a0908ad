// src/sweep/grid.cpp — deterministic expansion of a sweep into runs and cells.
#include "phnn/sweep/grid.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <queue>
#include <stdexcept>

#include "phnn/common/number_text.h"
#include "phnn/integrators/integrator.h"

namespace phnn {

namespace {

// The cost of a stack of E runs like `run` is fixed_s + E * member_s.
struct CostParts {
  double fixed_s = 0.0, member_s = 0.0;
};

// CostModel's formula (include/phnn/sweep/grid.h), split into its two parts.
CostParts cost_parts(const RunConfig& run, const CostModel& c) {
  const int m = static_cast<int>(run.model), i = static_cast<int>(run.integrator);
  const int s = static_cast<int>(run.size);
  const bool regularized = run.regularizer != Regularizer::kNone;
  const double reg = regularized ? c.regularizer_factor[m][i] : 1.0;
  const double reg_fixed = regularized ? c.regularizer_fixed_factor[m][i] : 1.0;
  const double precision =
      run.training.precision == Precision::kFloat32 ? c.float32_factor : 1.0;
  const double batch = std::min<double>(run.n_train, c.reference_batch);
  const double batch_scale = 1.0 - c.small_batch_saving * (c.reference_batch - batch) / c.reference_batch;
  const double fixed_us = c.fixed_us[m][i] * c.fixed_size_factor[s] * reg_fixed;
  const double member_us = c.member_us[m][i] * c.member_size_factor[s] * reg;
  const TrainerOptions& t = run.training;
  const int evaluations = 1 + t.steps / t.eval_every + (t.steps % t.eval_every != 0 ? 1 : 0);
  const double validation = evaluations * run.data.num_validation / c.reference_batch;
  // One rollout of the inference set per checkpoint before the last step,
  // plus the final one (none for a [search] rung before the last).
  const auto rollouts = t.skip_inference ? 0 : 1 + std::count_if(t.checkpoints.begin(), t.checkpoints.end(),
                                          [&](int step) { return step < t.steps; });
  const double inference = static_cast<double>(rollouts) * run.data.num_inference *
                           run.data.num_inference_steps() / c.reference_batch / c.rollout_speedup *
                           (is_discrete_gradient(run.integrator) ? c.dg_newton_factor : 1.0);
  // A system file's runs: the n-dimensional models (general_ph.h).
  const double general =
      !run.has_system_file()          ? 1.0
      : run.model == ModelKind::kNode ? c.general_node_factor
                                      : c.general_phnn_base + c.general_phnn_per_state2 * run.n_x * run.n_x;
  CostParts parts;
  parts.fixed_s = t.steps * fixed_us * precision * general * 1e-6;
  parts.member_s =
      ((t.steps * batch_scale + validation) * precision + inference) * member_us * general * 1e-6;
  return parts;
}

}  // namespace

double estimate_group_cost_s(const RunConfig& run, int members, const CostModel& cost_model) {
  if (members < 1) {
    throw std::invalid_argument("estimate_group_cost_s: members = " + std::to_string(members) +
                                "; need at least 1");
  }
  const CostParts parts = cost_parts(run, cost_model);
  return parts.fixed_s + members * parts.member_s;
}

namespace {

// Varied axes of a study, in nesting order, and the label of a run's column.
// The regularizer weight is a column part of regularized runs only
// ("cn/lambda=1e-05"; the "none" column has no weight), so runs of different
// weights never share a table cell.
struct ColumnAxes {
  bool size = false, n_train = false, regularizer = false, lambda = false;

  std::string name() const {
    std::vector<std::string> names;
    if (size) names.push_back("size");
    if (n_train) names.push_back("n_train");
    if (regularizer) names.push_back("regularizer");
    if (lambda) names.push_back("lambda");
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : "/") + n;
    return out;
  }

  std::string label(ModelSize s, int n, Regularizer r, double weight) const {
    std::vector<std::string> parts;
    if (size) parts.push_back(to_string(s));
    if (n_train) parts.push_back(std::to_string(n));
    if (regularizer) parts.push_back(to_string(r));
    if (lambda && r != Regularizer::kNone) parts.push_back("lambda=" + shortest_number(weight));
    if (parts.empty()) return "MSE";
    std::string out;
    for (const std::string& p : parts) out += (out.empty() ? "" : "/") + p;
    return out;
  }
};

// The [training] options and step budgets of a study's runs: [search]'s
// variants and rungs, else [training] and its steps. suffix() is the part
// of a column label they add: "learning_rate=0.001/steps=5000" ("" without
// [search]; the variant only when there are several).
struct Budgets {
  std::vector<TrainerOptions> variants;
  std::vector<std::string> labels;
  std::vector<int> steps;
  bool search = false;

  explicit Budgets(const SweepSpec& spec) : search(spec.search.enabled) {
    variants = search ? spec.search.variants : std::vector<TrainerOptions>{spec.training};
    labels = search ? spec.search.variant_labels : std::vector<std::string>{""};
    steps = search ? spec.search.rungs : std::vector<int>{spec.training.steps};
  }
  std::string suffix(std::size_t variant, int budget) const {
    if (!search) return "";
    const std::string v = variants.size() > 1 ? labels[variant] + "/" : "";
    return v + "steps=" + std::to_string(budget);
  }
  std::string axis_name() const {
    if (!search) return "";
    return variants.size() > 1 ? "settings/steps" : "steps";
  }
};

// "MSE" + "steps=5000" -> "steps=5000"; "small" + "" -> "small".
std::string join_label(const std::string& base, const std::string& suffix) {
  if (suffix.empty()) return base;
  return base == "MSE" ? suffix : base + "/" + suffix;
}

// The weights a run with `reg` is made with: the study's lambdas for a
// regularized run when it has any, else the [training] weight (one run).
std::vector<double> weights_of(const StudySpec& study, Regularizer reg,
                               const TrainerOptions& training) {
  if (reg == Regularizer::kNone || study.lambdas.empty()) return {training.weight(reg)};
  return study.lambdas;
}

}  // namespace

namespace {

// A study's table without its runs: rows (models); its columns (the varied
// axis) come with the runs (add_run), in the order the first model meets them.
StudyTable table_frame(const StudySpec& study, const ColumnAxes& axes, const Budgets& budgets) {
  StudyTable table;
  table.name = study.name;
  table.title = study.title;
  table.systems = study.systems;
  table.varied_axis = axes.name();
  if (!budgets.axis_name().empty()) {
    table.varied_axis += (table.varied_axis.empty() ? "" : "/") + budgets.axis_name();
  }
  for (const auto& [model, integrator] : study.models) {
    table.rows.push_back(model_label(model, integrator));
  }
  return table;
}

// Adds `run` to the grid once (index_of: canonical() -> index) and to `table`.
void add_run(const RunConfig& run, const std::string& column, Grid* grid, StudyTable* table,
             std::map<std::string, int>* index_of) {
  const auto [it, inserted] =
      index_of->emplace(run.canonical(), static_cast<int>(grid->runs.size()));
  if (inserted) {
    grid->runs.push_back(run);
    grid->run_studies.emplace_back();
  }
  std::vector<std::string>& studies = grid->run_studies[it->second];
  if (std::find(studies.begin(), studies.end(), table->name) == studies.end()) {
    studies.push_back(table->name);
  }
  table->runs.push_back(it->second);
  table->run_columns.push_back(column);
  if (std::find(table->columns.begin(), table->columns.end(), column) == table->columns.end()) {
    table->columns.push_back(column);
  }
}

// The system of `run`: a system file of the spec, or a built-in system and
// its [physics] parameters.
void set_system(const SweepSpec& spec, const std::string& name, RunConfig* run) {
  if (const SweepSystemFile* file = spec.system_file(name)) {
    run->system_file = file->name;
    run->system_file_hash = file->text_hash;
    run->n_x = file->n_x;
    run->n_w = file->n_w;
    run->n_u = file->n_u;
    run->data_inference = file->data_inference;
    run->data_inference_points = file->data_inference_points;
    run->system = SystemKind::kHarmonic;  // unused
    run->physics = OscillatorOptions();   // unused
    return;
  }
  run->system_file.clear();
  run->system_file_hash.clear();
  run->n_x = 2;
  run->n_w = 1;
  run->n_u = 1;
  run->data_inference = run->data_inference_points = 0;
  run->system = parse_system(name);
  run->physics = spec.physics.at(run->system);
}

// Every run of `study`, nested system, model, size, n_train, regularizer,
// [search] variant, lambda (regularized runs only), [search] rung, seed
// (seed fastest).
void expand_study(const SweepSpec& spec, const StudySpec& study, Grid* grid,
                  std::map<std::string, int>* index_of) {
  ColumnAxes axes;
  axes.size = study.sizes.size() > 1;
  axes.n_train = study.n_train.size() > 1;
  axes.regularizer = study.regularizers.size() > 1;
  axes.lambda = study.lambdas.size() > 1;
  const Budgets budgets(spec);
  StudyTable table = table_frame(study, axes, budgets);
  RunConfig run;
  run.data = spec.data;
  run.training = spec.training;
  for (const std::string& system : study.systems) {
    set_system(spec, system, &run);
    for (const auto& [model, integrator] : study.models) {
      run.model = model;
      run.integrator = integrator;
      for (ModelSize size : study.sizes) {
        run.size = size;
        for (int n : study.n_train) {
          run.n_train = n;
          for (Regularizer reg : study.regularizers) {
            run.regularizer = reg;
            for (std::size_t v = 0; v < budgets.variants.size(); ++v) {
              for (double weight : weights_of(study, reg, budgets.variants[v])) {
                for (int steps : budgets.steps) {
                  run.training = budgets.variants[v];
                  run.training.set_weight(reg, weight);
                  run.training.steps = steps;
                  // A rung before the last is decided on its validation loss.
                  run.training.skip_inference = budgets.search && steps != budgets.steps.back();
                  const std::string label =
                      join_label(axes.label(size, n, reg, weight), budgets.suffix(v, steps));
                  for (int seed : study.seeds) {
                    run.seed = seed;
                    add_run(run, label, grid, &table, index_of);
                  }
                }
              }
            }
          }
        }
      }
    }
  }
  grid->studies.push_back(std::move(table));
}

// Cells: runs with equal cell_key(), seeds ascending; largest cost first.
void form_cells(const CostModel& cost_model, Grid* grid) {
  std::map<std::string, int> cell_of;
  for (int i = 0; i < static_cast<int>(grid->runs.size()); ++i) {
    const std::string key = grid->runs[i].cell_key();
    const auto [it, inserted] = cell_of.emplace(key, static_cast<int>(grid->cells.size()));
    if (inserted) {
      grid->cells.emplace_back();
      grid->cells.back().key = key;
    }
    grid->cells[it->second].runs.push_back(i);
  }
  for (Cell& cell : grid->cells) {
    std::sort(cell.runs.begin(), cell.runs.end(),
              [&](int a, int b) { return grid->runs[a].seed < grid->runs[b].seed; });
    const CostParts parts = cost_parts(grid->runs[cell.runs.front()], cost_model);
    cell.fixed_cost_s = parts.fixed_s;
    cell.member_cost_s = parts.member_s;
    cell.estimated_cost_s = cell.cost_s(static_cast<int>(cell.runs.size()));
  }
  std::sort(grid->cells.begin(), grid->cells.end(), [](const Cell& a, const Cell& b) {
    if (a.estimated_cost_s != b.estimated_cost_s) return a.estimated_cost_s > b.estimated_cost_s;
    return a.key < b.key;
  });
  for (const Cell& cell : grid->cells) grid->estimated_cost_s += cell.estimated_cost_s;
}

}  // namespace

Grid expand_grid(const SweepSpec& spec, const CostModel& cost_model) {
  Grid grid;
  std::map<std::string, int> index_of;  // canonical() -> index in grid.runs
  for (const StudySpec& study : spec.studies) expand_study(spec, study, &grid, &index_of);
  form_cells(cost_model, &grid);
  return grid;
}

std::vector<int> cell_of_runs(const Grid& grid) {
  std::vector<int> cell_of(grid.runs.size(), -1);
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    for (int r : grid.cells[c].runs) cell_of[static_cast<std::size_t>(r)] = static_cast<int>(c);
  }
  return cell_of;
}

double greedy_makespan_s(std::vector<double> item_costs_s, int ranks) {
  if (ranks < 1) {
    throw std::invalid_argument("greedy_makespan_s: ranks = " + std::to_string(ranks) +
                                "; need at least 1 rank");
  }
  std::sort(item_costs_s.begin(), item_costs_s.end(), std::greater<double>());
  // Min-heap of rank loads: each item goes to the rank that is free first.
  std::priority_queue<double, std::vector<double>, std::greater<double>> loads;
  for (int r = 0; r < ranks; ++r) loads.push(0.0);
  double makespan = 0.0;
  for (double cost : item_costs_s) {
    const double load = loads.top() + cost;
    loads.pop();
    loads.push(load);
    makespan = std::max(makespan, load);
  }
  return makespan;
}

}  // namespace phnn
