// include/phnn/data/dataset.h
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "phnn/integrators/discrete_gradient.h"
#include "phnn/systems/oscillators.h"

namespace phnn {

/// Initial energy E0 of Algorithm 1 (harmonic and self-sustained initial
/// conditions; docs/METHOD.md §2), from r ~ U(E_min, E_max):
///   kAlgorithm1 (default): E0 = sqrt(r), as the paper's Algorithm 1 prints it
///                          (so H(x0) lies in [sqrt(E_min), sqrt(E_max)]);
///   kDirect:               E0 = r (H(x0) in I_E0 = [E_min, E_max], as the
///                          paper's text asks).
/// Duffing's Algorithm 2 samples H(x0) in I_E0 by rejection and ignores it.
enum class EnergySampling { kAlgorithm1 = 0, kDirect = 1 };
/// "algorithm1", "direct".
std::string to_string(EnergySampling sampling);
/// Every EnergySampling, default first.
std::vector<EnergySampling> all_energy_samplings();

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

/// What defines a trajectory: its initial state and constant input.
struct TrajectorySpec {
  Vec2 x0 = Vec2::Zero();
  double u = 0.0;
};

/// Initial state by Algorithm 1 (harmonic, self-sustained; *as written*:
/// r ~ U(E_min, E_max), E0 = sqrt(r), or E0 = r with EnergySampling::kDirect)
/// or Algorithm 2 (Duffing: rejection in
/// the box |q| <= q_max, |p| <= sqrt(2 m E_max), H(q_max, 0) = E_max), and
/// input by Algorithm 3 (harmonic, Duffing: E_eq ~ U(I_Eeq), sign of q* +-1)
/// or Algorithm 4 (self-sustained: w ~ U(I_w), u = -w). Depends only on
/// (data_seed, system, index).
TrajectorySpec trajectory_spec(const Oscillator& system,
                               const DatasetOptions& options,
                               std::int64_t index);

/// A trajectory at the generation rate: states[n] = x(n h_gen), n = 0..steps.
struct Trajectory {
  std::int64_t index = 0;
  double u = 0.0;
  std::vector<Vec2> states;
};

/// Generates trajectory `index` for `num_steps` DG steps at h_gen. Throws
/// std::runtime_error naming system, trajectory and step if Newton fails.
Trajectory generate_trajectory(const Oscillator& system,
                               const DatasetOptions& options,
                               std::int64_t index, int num_steps);

/// Training or validation pairs (x_n, u, x_{n+1}) at sr_train, one per
/// trajectory, uniform over positions with t_{n+1} <= alpha T0.
struct PairSet {
  std::vector<Vec2> x;
  std::vector<Vec2> x_next;
  std::vector<double> u;
  std::vector<std::int64_t> trajectory;  // index in [0, N_traj)
  std::vector<int> position;             // n at sr_train
  double step = 0.01;                    // h = 1 / sr_train
  std::size_t size() const { return x.size(); }
};

/// Pairs from trajectories [first, first + count). The pair drawn from a
/// trajectory depends only on (data_seed, system, index).
PairSet make_pairs(const Oscillator& system, const DatasetOptions& options,
                   std::int64_t first, int count);

/// Training pairs: the first n_train trajectories of the train split.
PairSet training_pairs(const Oscillator& system, const DatasetOptions& options,
                       int n_train);
/// The validation split's pairs.
PairSet validation_pairs(const Oscillator& system,
                         const DatasetOptions& options);

/// Inference trajectories at sr_infer: states[i][n], n = 0..num_inference_steps.
struct InferenceSet {
  std::vector<std::int64_t> trajectory;
  std::vector<double> u;
  std::vector<std::vector<Vec2>> states;
  double step = 0.01;
  std::size_t size() const { return u.size(); }
};
InferenceSet inference_set(const Oscillator& system,
                           const DatasetOptions& options);

/// Everything one system contributes to an experiment: the training pairs
/// (first n_train of them are used by a run), validation pairs and inference
/// trajectories (docs/METHOD.md §2).
struct SystemData {
  OscillatorOptions system;
  DatasetOptions options;
  PairSet train;
  PairSet validation;
  InferenceSet inference;
};

/// Generates a system's splits. `num_train` pairs of the train split (at most
/// options.num_train_max) are generated; only what is asked is computed.
SystemData make_system_data(const OscillatorOptions& system,
                            const DatasetOptions& options, int num_train);

}  // namespace phnn
