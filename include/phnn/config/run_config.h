// include/phnn/config/run_config.h — one run of a sweep, fully resolved.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "phnn/config/model_config.h"
#include "phnn/config/trainer_options.h"
#include "phnn/data/dataset.h"
#include "phnn/systems/oscillators.h"

namespace phnn {

/// Everything that determines a run's result (and nothing else: not the rank
/// that runs it, not the other runs). Two runs with equal canonical() are the
/// same run and are trained once.
struct RunConfig {
  /// A built-in system; unused when system_file is set.
  SystemKind system = SystemKind::kHarmonic;
  /// A system file's `name` and hex64 text hash (SweepSystemFile), or empty
  /// for a built-in system. The hash is part of the run's identity: a
  /// changed system file makes different runs.
  std::string system_file, system_file_hash;
  /// The system's states, dissipation ports and inputs (the cost model's
  /// and the results layout's; not part of the identity, which the file's
  /// hash fixes).
  int n_x = 2, n_w = 1, n_u = 1;
  /// A data-set file's inference trajectories and the samples of the
  /// longest (the results layout's; 0 when the data are generated, whose
  /// sizes `data` gives; not part of the identity either).
  int data_inference = 0, data_inference_points = 0;
  ModelKind model = ModelKind::kNode;
  IntegratorKind integrator = IntegratorKind::kRk2;
  ModelSize size = ModelSize::kSmall;
  int n_train = 25;
  Regularizer regularizer = Regularizer::kNone;
  int seed = 0;
  OscillatorOptions physics;
  DatasetOptions data;
  TrainerOptions training;

  /// system_file, or the built-in system's name ("duffing").
  std::string system_name() const;
  bool has_system_file() const { return !system_file.empty(); }

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
/// FNV-1a 64 continued over `size` more bytes, from `hash` (kFnv1a64Basis
/// to start): fnv1a64(a + b) == fnv1a64_update(fnv1a64(a), b.data(),
/// b.size()), so a hash of many pieces needs no string of them all.
constexpr std::uint64_t kFnv1a64Basis = 0xcbf29ce484222325ULL;
std::uint64_t fnv1a64_update(std::uint64_t hash, const void* data, std::size_t size);
/// 16 lower-case hex digits.
std::string hex64(std::uint64_t value);

}  // namespace phnn
