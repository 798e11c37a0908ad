// src/apps/eval_on_data.cpp — `phnn eval RESULTS --data FILE`
// (apps/eval_on_data.h): each run keeps its own system (structure, from the
// results file's /data) and weights; only the inference trajectories are
// the other file's. "Trained on sines, tested on a chirp" in one command.
#include "apps/eval_on_data.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>

#include "apps/cli.h"
#include "phnn/common/counted.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/store/scratch_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/systems/system_file.h"
#include "phnn/training/evaluate.h"

namespace phnn {
namespace apps {

std::map<std::string, RunConfig> stored_run_configs(const ResultsFile& results) {
  const SweepSpec spec = parse_sweep_text(results.sweep_text(), results.path() + " (sweep_text)",
                                          results.stored_system_files());
  std::map<std::string, RunConfig> out;
  for (const RunConfig& run : expand_grid(spec).runs) out.emplace(run.id(), run);
  return out;
}

namespace {

// "" when the data set has the system's states and inputs (names in
// order); else why not.
std::string mismatch(const PhSystemData& stored, const PhSystemData& data) {
  if (stored.state_names == data.state_names && stored.input_names == data.input_names) return "";
  const auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& n : v) s += (s.empty() ? "" : ",") + n;
    return "[" + s + "]";
  };
  return "states " + join(data.state_names) + " and inputs " + join(data.input_names) +
         " where system " + stored.system_name + " has " + join(stored.state_names) + " and " +
         join(stored.input_names);
}

// What the CSV needs of one evaluated run.
struct Evaluated {
  std::string id;
  RunConfig run;
  double mse;
  std::vector<double> trajectory_errors;
};

// A system of the results file: its stored data set (names, text) and the
// system compiled from it once, for all its runs.
struct StoredSystem {
  PhSystemData data;
  std::unique_ptr<PhSystem> system;
};

void write_errors_csv(const std::string& path, const std::vector<Evaluated>& all,
                      const PhSystemData& data) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write the CSV; is the directory writable?");
  out << "run_id,system,model,integrator,size,n_train,regularizer,seed,trajectory,position,error,mse\n";
  char buf[40];
  for (const Evaluated& v : all) {
    for (std::size_t k = 0; k < v.trajectory_errors.size(); ++k) {
      std::snprintf(buf, sizeof buf, "%.17g", v.trajectory_errors[k]);
      out << v.id << "," << v.run.system_name() << "," << to_string(v.run.model) << ","
          << to_string(v.run.integrator) << "," << to_string(v.run.size) << "," << v.run.n_train
          << "," << to_string(v.run.regularizer) << "," << v.run.seed << ","
          << data.inference.trajectory[k] << ","
          << (data.inference.position.empty() ? 0 : data.inference.position[k]) << "," << buf;
      std::snprintf(buf, sizeof buf, "%.17g", v.mse);
      out << "," << buf << "\n";
    }
  }
  if (!out.flush()) throw std::runtime_error(path + ": write failed; is the disk full?");
}

// The run's cell on `data`: n_train only sizes the training split, which
// inference does not read; capped to the data set's pairs.
CellSpec cell_on(const RunConfig& run, const PhSystemData& data) {
  CellSpec cell = cell_spec_for(run, {run.seed});
  cell.n_train = std::max(1, std::min(cell.n_train, static_cast<int>(data.train.size())));
  return cell;
}

}  // namespace

int eval_on_data(const ResultsFile& results, const EvalOnDataOptions& o) {
  const PhSystemData data = read_ph_dataset_file(o.data_path);
  const std::map<std::string, RunConfig> configs = stored_run_configs(results);
  const std::vector<std::string> ids = results.read_run_ids();
  std::vector<int> rows = o.rows;
  if (rows.empty()) {
    const std::vector<RunStatus> statuses = results.read_statuses();
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (statuses[i] == RunStatus::kDone || statuses[i] == RunStatus::kDiverged) rows.push_back(static_cast<int>(i));
    }
  }
  std::map<std::string, StoredSystem> systems;
  std::vector<Evaluated> all;
  std::string skipped;
  for (int row : rows) {
    const std::string& id = ids[static_cast<std::size_t>(row)];
    const auto found = configs.find(id);
    if (found == configs.end()) continue;
    const RunConfig& run = found->second;
    StoredSystem& stored = systems[run.system_name()];
    if (!stored.system) {
      stored.data = results.read_system_data(run.system_name());
      stored.system = compile_system(stored.data.system_text, results.path() + "@/data/" + run.system_name());
    }
    const std::string why = mismatch(stored.data, data);
    if (!why.empty()) {
      if (!o.rows.empty()) throw cli::UsageError{"phnn eval: --data " + o.data_path + " has " + why};
      skipped = why;
      continue;
    }
    const RunResult result = results.read_run(row);
    if (result.weights.empty()) continue;
    const RunResult r =
        evaluate_stored_run(cell_on(run, data), data, *stored.system, result.weights).result;
    all.push_back({id, run, r.mse, r.trajectory_errors});
    std::printf("phnn eval: run %s (%s %s seed %d): mse %.6e on %s (%s; %.6e on its own data)\n",
                id.c_str(), run.system_name().c_str(), model_label(run.model, run.integrator).c_str(),
                run.seed, r.mse, o.data_path.c_str(),
                counted(static_cast<long long>(data.inference.size()), "trajectory", "trajectories").c_str(), result.mse);
  }
  if (all.empty()) {
    throw cli::UsageError{"phnn eval: no finished run of " + results.path() + " fits --data " +
                          o.data_path + (skipped.empty() ? "" : ": it has " + skipped)};
  }
  if (!o.errors_path.empty()) {
    write_atomically(o.errors_path, "writing", [&](const std::string& p) { write_errors_csv(p, all, data); });
    std::printf("phnn eval: errors per inference trajectory -> %s\n", o.errors_path.c_str());
  }
  return 0;
}

}  // namespace apps
}  // namespace phnn
