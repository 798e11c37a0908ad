// src/apps/sweep_data.cpp — the data sets of a sweep's systems
// (apps/sweep_data.h).
#include "apps/sweep_data.h"

#include <algorithm>
#include <cstring>
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
    d.data = read_ph_dataset_file(file->path);
    if (data_set_checksum(d.data) != file->data_checksum) {
      throw std::runtime_error("data-set file " + file->path + " changed while the sweep was "
                               "starting (its checksum differs); start the sweep again");
    }
  } else if (file) {
    d.system = compile_system(file->text, file->entry);
    d.data = make_ph_system_data(*d.system, spec_.data, max_train, stop_);
  } else {
    d.system = builtin_system(spec_.physics.at(parse_system(system_name)), spec_.data);
    d.data = make_ph_system_data(*d.system, spec_.data, max_train, stop_);
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
  const SweepSystemFile* file = spec_.system_file(system_name);
  results->store_system_data(system_name, at(system_name).data, file ? file->entry : "");
}

namespace {

// Bitwise equality of two states or inputs.
bool same_bits(const VecX& a, const VecX& b) {
  if (a.size() != b.size()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a(i), &b(i), sizeof(double)) != 0) return false;
  }
  return true;
}

// The first of `count` pairs (or inference trajectories) where a and b differ, or -1.
long first_different_pair(const PhPairSet& a, const PhPairSet& b, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!same_bits(a.x[i], b.x[i]) || !same_bits(a.x_next[i], b.x_next[i]) ||
        !same_bits(a.u[i], b.u[i])) {
      return static_cast<long>(i);
    }
  }
  return -1;
}
long first_different_trajectory(const PhInferenceSet& a, const PhInferenceSet& b) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.states[i].size() != b.states[i].size()) return static_cast<long>(i);
    for (std::size_t n = 0; n < a.states[i].size(); ++n) {
      if (!same_bits(a.states[i][n], b.states[i][n])) return static_cast<long>(i);
    }
  }
  return -1;
}

std::string data_difference(const PhSystemData& made, const PhSystemData& stored) {
  if (made.validation.size() != stored.validation.size() ||
      made.inference.size() != stored.inference.size()) {
    return "its validation or inference split has another size";
  }
  const std::size_t train = std::min(made.train.size(), stored.train.size());
  if (long i = first_different_pair(made.train, stored.train, train); i >= 0) {
    return "training pair " + std::to_string(i) + " differs";
  }
  if (long i = first_different_pair(made.validation, stored.validation, made.validation.size());
      i >= 0) {
    return "validation pair " + std::to_string(i) + " differs";
  }
  if (long i = first_different_trajectory(made.inference, stored.inference); i >= 0) {
    return "inference trajectory " + std::to_string(i) + " differs";
  }
  return "";
}

}  // namespace

std::string SweepDataSets::stored_data_problem(const std::string& system_name,
                                               const ResultsFile& results) const {
  const std::string what = data_difference(at(system_name).data, results.read_system_data(system_name));
  if (what.empty()) return "";
  return "the data this binary generates for " + system_name + " differ from the data set stored in "
         "the file (" + what + "): another phnn version or another C library generated it, and runs "
         "trained on the two would differ. Write to another file, or pass --mix-kernels to mix them "
         "anyway.";
}

std::vector<RunResult> SweepDataSets::train(const CellSpec& cell, const std::string& system_name,
                                            const ProgressCallback& progress,
                                            const CellCheckpointing* checkpointing) const {
  const DataSet& d = at(system_name);
  return train_cell(cell, d.data, *d.system, progress, nullptr, checkpointing);
}

}  // namespace apps
}  // namespace phnn
