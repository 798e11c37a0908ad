// tests/training/small_data.h — the small data sets the trainer tests train
// on: a built-in system's splits with 4 inference trajectories and N_train up
// to 100, made once per system and process.
#pragma once

#include <map>

#include "phnn/data/dataset.h"
#include "phnn/systems/oscillators.h"

namespace phnn {
namespace testing_util {

inline const SystemData& small_data(SystemKind kind) {
  static std::map<SystemKind, SystemData> cache;
  auto it = cache.find(kind);
  if (it == cache.end()) {
    DatasetOptions options;
    options.num_inference = 4;
    it = cache.emplace(kind, make_system_data(OscillatorOptions::defaults(kind), options, 100)).first;
  }
  return it->second;
}

}  // namespace testing_util
}  // namespace phnn
