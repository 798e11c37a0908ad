// include/phnn/sweep/run_config.h — one run of a sweep, fully resolved.
#pragma once

#include <cstdint>
#include <string>

#include "phnn/data/dataset.h"
#include "phnn/models/model_config.h"
#include "phnn/systems/oscillators.h"
#include "phnn/training/trainer_options.h"

namespace phnn {

/// Everything that determines a run's result (and nothing else: not the rank
/// that runs it, not the other runs). Two runs with equal canonical() are the
/// same run and are trained once.
struct RunConfig {
  SystemKind system = SystemKind::kHarmonic;
  ModelKind model = ModelKind::kNode;
  IntegratorKind integrator = IntegratorKind::kRk2;
  ModelSize size = ModelSize::kSmall;
  int n_train = 25;
  Regularizer regularizer = Regularizer::kNone;
  int seed = 0;
  OscillatorOptions physics;
  DatasetOptions data;
  TrainerOptions training;

  /// "key=value;..." with every field that affects the result, in a fixed
  /// order, numbers printed with 17 significant digits.
  std::string canonical() const;
  /// canonical() without the seed: runs with equal cell_key() form a cell.
  std::string cell_key() const;
  /// 64-bit FNV-1a hash of canonical(), as 16 hex digits.
  std::string id() const;
};

/// 64-bit FNV-1a of a string.
std::uint64_t fnv1a64(const std::string& text);
/// 16 lower-case hex digits.
std::string hex64(std::uint64_t value);

}  // namespace phnn
