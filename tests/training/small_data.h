// tests/training/small_data.h — the small data sets the trainer tests train
// on: a built-in system (its shipped file) with its splits, 4 inference
// trajectories and N_train up to 100, made once per system and process.
#pragma once

#include <map>
#include <memory>

#include "phnn/data/ph_dataset.h"
#include "reference/oscillator.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace testing_util {

/// A data set with the system that made it.
struct SystemAndData {
  std::shared_ptr<const PhSystem> system;
  PhSystemData data;
};

/// A built-in system's data set (generated; `physics` defaults to `kind`'s).
inline SystemAndData builtin_data(const OscillatorOptions& physics, const DatasetOptions& options,
                                  int n_train) {
  SystemAndData d;
  d.system = builtin_system(physics, options);
  d.data = make_ph_system_data(*d.system, options, n_train);
  return d;
}

inline const SystemAndData& small_data(SystemKind kind) {
  static std::map<SystemKind, SystemAndData> cache;
  auto it = cache.find(kind);
  if (it == cache.end()) {
    DatasetOptions options;
    options.num_inference = 4;
    it = cache.emplace(kind, builtin_data(OscillatorOptions::defaults(kind), options, 100)).first;
  }
  return it->second;
}

/// train_cell on a data set and its system.
inline std::vector<RunResult> train_cell(const CellSpec& cell, const SystemAndData& d,
                                         const ProgressCallback& progress = {},
                                         std::unique_ptr<DynamicsModel>* trained = nullptr,
                                         const CellCheckpointing* checkpointing = nullptr) {
  return phnn::train_cell(cell, d.data, *d.system, progress, trained, checkpointing);
}

}  // namespace testing_util
}  // namespace phnn
