// include/phnn/training/evaluate.h — one run reloaded from its stored
// best-validation weights (RunResult::weights) and evaluated again with the
// trainer's own inference code: the same rollouts, Eq. 31 and figure
// trajectories, plus the true and the learned energy along the figure
// trajectories. Touches no file.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "phnn/config/run_result.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/models/dynamics_model.h"
#include "phnn/training/trainer.h"

namespace phnn {

/// Energies along one figure trajectory (paper Figures 7, 9; a system
/// file's inference trajectories 0 and 1), one row per point: t [s], the
/// states of the model rollout (q, p for the built-in systems; a system
/// file's state names), the same of the true system (q_ref, p_ref, ...),
/// H(x), H(x_ref) (true Hamiltonian) [J], H_theta(x), H_theta(x_ref)
/// (learned; NaN for NODE, which has none) [J].
struct EnergyTrace {
  /// "t,q,p,q_ref,p_ref,H_true,H_true_ref,H_model,H_model_ref" for 2 states.
  std::string columns;
  std::vector<std::vector<double>> rows;
};

struct Evaluation {
  /// status, mse, trajectory_errors, diverged_rollouts, newton_failures and
  /// the figure trajectories, as the trainer computes them (bitwise, since
  /// stacking members is exact).
  RunResult result;
  /// Along the two figure trajectories (from H(x0) = 0.5 J and 0.75 J for
  /// the paper's systems).
  EnergyTrace energy_05, energy_075;
  /// H(x0) of the figure trajectories (PhSystem::figure_energies); empty
  /// when they are inference trajectories 0 and 1.
  std::vector<double> figure_energies;
};

/// Evaluates the run of `cell` (one seed) with its stored weights on
/// `data` of `system` (figure trajectories: ph_figure_set's, else
/// inference trajectories 0 and 1).
Evaluation evaluate_stored_run(const CellSpec& cell, const PhSystemData& data,
                               const PhSystem& system, const std::vector<double>& weights);

}  // namespace phnn
