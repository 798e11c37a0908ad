// src/apps/sweep_data.cpp — the data sets of a sweep's systems
// (apps/sweep_data.h).
#include "apps/sweep_data.h"

#include <algorithm>
#include <stdexcept>

#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace apps {

void SweepDataSets::make(const std::string& system_name) {
  if (data_.count(system_name)) return;
  int max_train = 0;
  for (const RunConfig& run : grid_.runs) {
    if (run.system_name() == system_name) max_train = std::max(max_train, run.n_train);
  }
  DataSet d;
  const SweepSystemFile* file = spec_.system_file(system_name);
  if (file && file->is_data()) {
    // A `data` file: its splits as they are (the [data] table does not apply).
    d.system = compile_system(file->text, file->path);
    d.file = read_ph_dataset_file(file->path);
    if (data_set_checksum(*d.file) != file->data_checksum) {
      throw std::runtime_error("data-set file " + file->path + " changed while the sweep was "
                               "starting (its checksum differs); start the sweep again");
    }
  } else if (file) {
    d.system = compile_system(file->text, file->entry);
    d.file = make_ph_system_data(*d.system, spec_.data, max_train);
  } else {
    const SystemKind kind = parse_system(system_name);
    d.builtin = make_system_data(spec_.physics.at(kind), spec_.data, max_train);
  }
  data_.emplace(system_name, std::move(d));
}

const SweepDataSets::DataSet& SweepDataSets::at(const std::string& system_name) const {
  const auto it = data_.find(system_name);
  if (it == data_.end()) {
    throw std::logic_error("SweepDataSets: no data set of " + system_name + "; make() it first");
  }
  return it->second;
}

void SweepDataSets::store(const std::string& system_name, ResultsFile* results) const {
  const DataSet& d = at(system_name);
  if (d.builtin) {
    results->store_system_data(system_name, *d.builtin);
  } else {
    results->store_file_system_data(system_name, *d.file,
                                    spec_.system_file(system_name)->entry);
  }
}

std::vector<RunResult> SweepDataSets::train(const CellSpec& cell, const std::string& system_name,
                                            const ProgressCallback& progress,
                                            const CellCheckpointing* checkpointing) const {
  const DataSet& d = at(system_name);
  if (d.builtin) return train_cell(cell, *d.builtin, progress, nullptr, checkpointing);
  return train_cell(cell, *d.file, *d.system, progress, nullptr, checkpointing);
}

}  // namespace apps
}  // namespace phnn
