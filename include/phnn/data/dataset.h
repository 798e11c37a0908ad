// include/phnn/data/dataset.h — the options of data sets (sizes, timing,
// splits, energy intervals, the DG generator's Newton) and the built-in
// systems they configure. Generation: ph_dataset.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/integrators/step_options.h"
#include "phnn/systems/builtin_systems.h"

namespace phnn {

/// Initial energy E0 of Algorithm 1 (harmonic and self-sustained initial
/// conditions; docs/METHOD.md §2), from r ~ U(E_min, E_max):
///   kAlgorithm1 (default): E0 = sqrt(r), as the paper's Algorithm 1 prints it
///                          (so H(x0) lies in [sqrt(E_min), sqrt(E_max)]);
///   kDirect:               E0 = r (H(x0) in I_E0 = [E_min, E_max], as the
///                          paper's text asks).
/// Duffing's Algorithm 2 samples H(x0) in I_E0 by rejection and ignores it.
enum class EnergySampling { kAlgorithm1 = 0, kDirect = 1 };
inline constexpr EnumNames<EnergySampling, 2> kEnergySamplingNames{
    "energy sampling", {{{EnergySampling::kAlgorithm1, "algorithm1"}, {EnergySampling::kDirect, "direct"}}}};
inline std::string to_string(EnergySampling sampling) { return kEnergySamplingNames.name(sampling); }
/// Every EnergySampling, default first.
inline std::vector<EnergySampling> all_energy_samplings() { return kEnergySamplingNames.all(); }

/// Data-set options (paper §5.2, Appendix E; docs/METHOD.md §2). Defaults: docs/METHOD.md.
struct DatasetOptions {
  /// Keys every random stream with (data_seed, system, trajectory, purpose).
  std::uint64_t data_seed = 0;
  /// Generation step h_gen = 1 / sr_gen [s] (sr_gen = 400 f0).
  double generation_step = 1.0 / 400.0;
  /// Nominal period T0 = 1 / f0 [s].
  double period = 1.0;
  /// D = beta T0: trajectory (and inference) duration [s].
  double beta = 5.0;
  /// D_train = alpha T0: training pairs have t_{n+1} <= alpha T0.
  double alpha = 0.31;
  /// sr_train = sr_infer [Hz]: pairs and inference are sub-sampled to it.
  double sample_rate = 100.0;
  /// I_E0 = [energy_min, energy_max] [J] of the initial conditions.
  double energy_min = 0.1;
  double energy_max = 1.0;
  /// E0 from r in Algorithm 1 (harmonic, self-sustained).
  EnergySampling energy_sampling = EnergySampling::kAlgorithm1;
  /// I_Eeq [J] of the controlled equilibria (harmonic, Duffing).
  double equilibrium_energy_min = 0.1;
  double equilibrium_energy_max = 1.0;
  /// Number of addressable trajectories N_traj.
  int num_trajectories = 12500;
  /// Splits by index: train [0, num_train_max), validation
  /// [num_train_max, num_train_max + num_validation), inference after.
  int num_train_max = 400;
  int num_validation = 2500;
  int num_inference = 100;
  /// Newton options of the DG generator.
  DiscreteGradientOptions newton;

  /// Sub-sampling stride sr_gen / sr_train (4); throws if not an integer.
  int stride() const;
  /// Pairs (x_n, x_{n+1}) at sr_train with t_{n+1} <= alpha T0: n in [0, count).
  int num_pair_positions() const;
  /// Inference steps at sr_train over D (500).
  int num_inference_steps() const;
  int validation_begin() const { return num_train_max; }
  int inference_begin() const { return num_train_max + num_validation; }

  /// Throws std::invalid_argument naming the field, value and constraint.
  void validate() const;
};

/// The energy intervals options set in a built-in system's designs
/// (I_E0 = [energy_min, energy_max], I_Eeq = [equilibrium_energy_min, max]).
BuiltinEnergies builtin_energies(const DatasetOptions& options);

/// The built-in system `physics.kind` (its shipped system file,
/// builtin_systems.h) with the energy intervals of `options`.
std::unique_ptr<PhSystem> builtin_system(const OscillatorOptions& physics,
                                         const DatasetOptions& options);

}  // namespace phnn
