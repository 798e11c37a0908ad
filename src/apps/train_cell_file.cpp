// src/apps/train_cell_file.cpp — see train_cell_file.h.
#include "apps/train_cell_file.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "phnn/common/check.h"
#include "phnn/common/number_text.h"
#include "phnn/common/utc_time.h"
#include "phnn/config/training_settings.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/version.h"
#include "phnn/systems/builtin_systems.h"

namespace phnn {
namespace apps {
namespace {

// The [grid] table of a one-cell sweep on `system` (a name or a system file).
std::string grid_text(const CellSpec& cell, const std::string& system) {
  std::ostringstream s;
  s << "[grid]\nsystems = [\"" << system << "\"]\nmodels = [\"" << to_string(cell.model) << "-"
    << to_string(cell.integrator) << "\"]\nsizes = [\"" << to_string(cell.size)
    << "\"]\nn_train = [" << cell.n_train << "]\nregularizers = [\"" << to_string(cell.regularizer)
    << "\"]\nseeds = [";
  for (std::size_t i = 0; i < cell.seeds.size(); ++i) s << (i ? ", " : "") << cell.seeds[i];
  s << "]\n";
  return s.str();
}

// The cell's [training] table: the settings `phnn train` has flags for
// (phnn/config/training_settings.h), a choice only away from its default.
std::string training_text(const CellSpec& cell) {
  std::ostringstream s;
  s << "\n\n[training]";
  for (const TrainingSetting& setting : training_settings()) {
    if (*setting.flag == '\0') continue;
    if (setting.kind != TrainingSetting::Kind::kChoice) {
      s << "\n" << setting.key << " = " << setting.text(cell.training);
    } else if (!setting.is_default(cell.training)) {
      s << "\n" << setting.key << " = \"" << setting.text(cell.training) << "\"";
    }
  }
  return s.str();
}

// The [physics.NAME] table of a built-in system: every aliased key
// (builtin_systems.h) that applies to it.
std::string physics_text(const OscillatorOptions& physics) {
  std::ostringstream s;
  s << "\n\n[physics." << to_string(physics.kind) << "]";
  const auto& aliases = builtin_aliases(physics.kind);
  std::vector<double> z;
  for (const BuiltinAlias& a : aliases) {
    if (a.field) s << "\n" << a.physics_key << " = " << exact_number(physics.*a.field);
    if (!a.field) z.push_back(physics.z_coefficients[static_cast<std::size_t>(a.z_index)]);
  }
  if (!z.empty()) {
    s << "\nz_coefficients = [" << exact_number(z[0]) << ", " << exact_number(z[1]) << ", "
      << exact_number(z[2]) << "]";
  }
  return s.str();
}

}  // namespace

std::string cell_sweep_text(const CellSpec& cell, const PhSystemData& data,
                            const std::string& system_entry) {
  std::ostringstream s;
  s << "# written by `phnn train --out`\n"
    << "name = \"train-" << data.system_name << "-" << to_string(cell.model) << "-"
    << to_string(cell.integrator) << "\"\n\n[data]\nseed = " << data.options.data_seed;
  const bool builtin = !is_system_file_argument(system_entry);
  if (builtin && data.options.energy_sampling != EnergySampling::kAlgorithm1) {  // a --data file's
    s << "\nenergy_sampling = \"" << to_string(data.options.energy_sampling) << "\"";
  }
  s << training_text(cell);
  if (builtin) s << physics_text(builtin_physics(data.system_text, data.system_name + "@system_file"));
  s << "\n\n" << grid_text(cell, system_entry);
  return s.str();
}

void write_cell_file(const std::string& path, const CellSpec& cell, const std::string& text,
                     const SystemFileReader& read,
                     const std::function<void(ResultsFile*)>& store_data,
                     const std::vector<RunResult>& results, const Provenance& provenance,
                     const std::string& started) {
  const SweepSpec spec = parse_sweep_text(text, path + "@sweep_text", read);
  const Grid grid = expand_grid(spec);
  PHNN_CHECK(grid.runs.size() == results.size(), "cell sweep text expands to "
                                                     << grid.runs.size() << " runs, not "
                                                     << results.size());
  std::vector<std::string> studies(grid.runs.size(), "grid");
  ResultsFile file = ResultsFile::create(path, MPI_COMM_NULL, grid.runs, studies, spec.name, text,
                                         spec.text_hash, program_version(),
                                         ResultsLayout::for_runs(grid.runs));
  file.begin_session(provenance);
  store_data(&file);
  const std::string finished = utc_now();
  // Grid rows are ordered by seed, like the cell's members.
  for (std::size_t i = 0; i < grid.runs.size(); ++i) {
    const auto it = std::find(cell.seeds.begin(), cell.seeds.end(), grid.runs[i].seed);
    RunResult result = results[static_cast<std::size_t>(it - cell.seeds.begin())];
    result.started_utc = started;
    result.finished_utc = finished;
    file.write_run(static_cast<int>(i), result);
  }
  file.end_session(finished);
  file.close();
}

}  // namespace apps
}  // namespace phnn
