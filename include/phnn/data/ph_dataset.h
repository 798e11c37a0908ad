// include/phnn/data/ph_dataset.h — data sets of any PhSystem (n_x states,
// n_u inputs): initial states and inputs drawn by the system's designs from
// the counter-based RNG, trajectories by the n-dimensional Gonzalez DG,
// training / validation pairs and inference trajectories split by index as
// for the built-in systems (dataset.h, docs/METHOD.md §2). In memory only.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/data/dataset.h"
#include "phnn/systems/ph_system.h"

namespace phnn {

/// Initial state and input of trajectory `index`: u is constant, or, for a
/// time-varying control design, `inputs` holds u at every sample k = 0..K
/// (K the inference steps; held over [t_k, t_{k+1})) and u = inputs[0].
struct PhTrajectorySpec {
  VecX x0, u;
  std::vector<VecX> inputs;
  /// The input held over sample k.
  const VecX& input(std::size_t k) const { return inputs.empty() ? u : inputs[k]; }
};

/// Draws x0 by the system's InitialConditionDesign (stream
/// kInitialCondition) and u by its ControlDesign (stream kControl), keyed by
/// (data_seed, system.rng_id(), index) only. For the built-in systems'
/// designs (Algorithms 1-4) the draws are those of trajectory_spec().
/// Throws std::invalid_argument naming the system file's line when H is
/// negative or not finite at a drawn state, or when 1e6 draws of the energy
/// method find no state with H in the interval.
PhTrajectorySpec ph_trajectory_spec(const PhSystem& system, const DatasetOptions& options,
                                    std::int64_t index);

struct PhTrajectory {
  std::int64_t index = 0;
  VecX u;
  std::vector<VecX> states;  // at the generation rate, n = 0..steps
  std::vector<VecX> inputs;  // time-varying inputs: u per sample (steps / stride + 1); else empty
  /// The input held over sample k.
  const VecX& input(std::size_t k) const { return inputs.empty() ? u : inputs[k]; }
};

/// `num_steps` DG steps at h_gen. Throws std::runtime_error naming system,
/// trajectory and step if Newton fails.
PhTrajectory ph_generate_trajectory(const PhSystem& system, const DatasetOptions& options,
                                    std::int64_t index, int num_steps);

/// Asked between trajectories of a long generation (every 64th): true ends
/// it with GenerationStopped (a stop signal during a sweep's set-up).
using GenerationStop = std::function<bool()>;
struct GenerationStopped : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Pairs (x_n, u, x_{n+1}) at sr_train, one per trajectory (PairSet's rules).
struct PhPairSet {
  std::vector<VecX> x, x_next, u;
  std::vector<std::int64_t> trajectory;
  std::vector<int> position;
  double step = 0.01;
  std::size_t size() const { return x.size(); }
};
PhPairSet ph_make_pairs(const PhSystem& system, const DatasetOptions& options,
                        std::int64_t first, int count, const GenerationStop& stop = {});

struct PhInferenceSet {
  std::vector<std::int64_t> trajectory;
  std::vector<VecX> u;  // the input at the first sample
  /// Time-varying inputs: [trajectory][n], u_n held over step n -> n + 1
  /// (n = 0..steps, the last for the final sample); empty when every
  /// trajectory's input is constant.
  std::vector<std::vector<VecX>> inputs;
  std::vector<std::vector<VecX>> states;  // [trajectory][n], n = 0..steps at sr_infer
  /// Windows of recordings (split_in_blocks, data/measured.h): the sample of
  /// its recording each starts at; empty when every trajectory starts at 0.
  std::vector<std::int64_t> position;
  double step = 0.01;
  std::size_t size() const { return u.size(); }
};
PhInferenceSet ph_inference_set(const PhSystem& system, const DatasetOptions& options,
                                const GenerationStop& stop = {});

/// The figure trajectories of a system with figure energies
/// (PhSystem::figure_energies; the paper's Figures 4-6): x0 = s e_1 with
/// H(x0) = E, u the control design's central input (limit-cycle: -(w1 +
/// w2) / 2, the middle of Algorithm 4's I_w; else 0), at sr_infer over D as
/// the inference trajectories (trajectory index -1). Empty without energies.
PhInferenceSet ph_figure_set(const PhSystem& system, const DatasetOptions& options);

/// A system's three splits with what names them.
struct PhSystemData {
  std::string system_name, system_text;  // text: the system file ("" built-in)
  std::vector<std::string> state_names, state_units, input_names;
  int n_w = 0;
  DatasetOptions options;
  PhPairSet train, validation;
  PhInferenceSet inference;
  /// Measurement noise added to the pairs ("" = none), e.g. "relative 0.01:
  /// sigma q=0.0021 p=0.0034" (add_measurement_noise, data/measured.h).
  std::string noise;
  /// How recordings were split when not one pair per trajectory, e.g.
  /// "blocks: train 0.6, validation 0.2, inference 0.2 of each recording;
  /// windows of 10 s" ("" = one pair per trajectory).
  std::string split;
};

/// A data set of `system` with no splits yet: its name, text, state and
/// input names and units, n_w (what every data set of it carries).
PhSystemData labelled_ph_system_data(const PhSystem& system);

/// Generates the splits; `num_train` <= options.num_train_max training pairs.
PhSystemData make_ph_system_data(const PhSystem& system, const DatasetOptions& options,
                                 int num_train, const GenerationStop& stop = {});

}  // namespace phnn
