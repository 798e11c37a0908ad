// include/phnn/training/trainer.h — trains one cell: all seeds of one
// configuration as one stacked model (issue 3), then evaluates it.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/config/model_config.h"
#include "phnn/config/run_config.h"
#include "phnn/config/run_result.h"
#include "phnn/config/trainer_options.h"
#include "phnn/data/ph_dataset.h"

namespace phnn {

class DynamicsModel;  // phnn/models/dynamics_model.h

/// One cell: runs that differ only by the model seed.
struct CellSpec {
  ModelKind model = ModelKind::kPhnnJr;
  IntegratorKind integrator = IntegratorKind::kRk2;
  ModelSize size = ModelSize::kSmall;
  int n_train = 25;
  Regularizer regularizer = Regularizer::kNone;
  std::vector<int> seeds = {0};
  TrainerOptions training;
  /// Networks through the fused autograd node (default) or the op-by-op
  /// reference path (ModelOptions::fused_networks): same results to
  /// round-off, for tests and side-by-side benchmarks. Float32 training
  /// (TrainerOptions::precision) always trains on the reference path; this
  /// then selects the path of its float64 inference only.
  bool fused_networks = true;

  /// Throws std::invalid_argument naming the field (e.g. NODE with DG, an
  /// n_train above the data's training pairs, non-finite data).
  void validate(const PhSystemData& data) const;
};

/// The cell of `run` (its model, size, N_train, regularizer and training
/// settings) with the given member seeds: a whole cell, a member group of
/// it, or one run (`phnn eval`).
CellSpec cell_spec_for(const RunConfig& run, const std::vector<int>& seeds);

/// Called at every validation point and at the end of evaluation.
struct TrainProgress {
  int step = 0;
  int total_steps = 0;
  double elapsed_s = 0.0;
  double best_validation_loss = 0.0;  // median over live members
};
using ProgressCallback = std::function<void(const TrainProgress&)>;

/// Saved training states inside a cell, so a stopped or killed cell goes on
/// from its last state and ends bitwise as if never interrupted
/// (docs/DECISIONS.md, "Preemptible cells"). The state is opaque bytes:
/// weights, Adam moments and step count, each member's batch order and
/// stream position, best-validation weights and losses, frozen members, the
/// trace so far. Timings (trace elapsed_s, train seconds) go on from the
/// saved ones; a repeated stretch of training is not counted twice.
///
///   CellCheckpointing c;
///   c.interval_s = 300;
///   c.resume_from = read_state_or_empty();
///   c.save = [&](const std::string& state, int step) { write_atomically(state); };
///   c.stop_requested = [] { return g_signal != 0; };
///   try { results = train_cell(cell, data, progress, nullptr, &c); }
///   catch (const CellInterrupted& e) { /* state of step e.step saved */ }
struct CellCheckpointing {
  /// Saves the state after the first step that ends this many seconds of
  /// wall time after the previous save (or the start); <= 0: only when
  /// stopped.
  double interval_s = 0.0;
  /// A state `save` received earlier for this same cell (spec, seeds and
  /// data), or `save_final` received for it at a smaller step budget that is
  /// a validation step of this one (a [search] rung: training goes on to
  /// the larger budget, bitwise as training straight through); empty: start
  /// at step 0. One that does not fit the cell throws std::invalid_argument
  /// before any training.
  std::string resume_from;
  /// Receives each state and the step it ends; required.
  std::function<void(const std::string& state, int step)> save;
  /// Polled after every step and, once training is over, before and every
  /// 32 steps during the final inference rollouts (keep it cheap); true:
  /// save the state (of the last step: a cell stopped in its inference goes
  /// on from there straight to inference) and throw CellInterrupted.
  std::function<bool()> stop_requested;
  /// When set, receives the state after the last step (before inference):
  /// what a cell of the same runs at a larger step budget goes on from.
  std::function<void(const std::string& state, int step)> save_final;
};

/// Thrown by train_cell when CellCheckpointing::stop_requested said stop,
/// after the state of the last finished step was saved.
struct CellInterrupted : std::runtime_error {
  CellInterrupted(int step, int total_steps);
  int step = 0;
};

/// Trains the cell on `data` (the first n_train training pairs, the
/// validation pairs), keeps each member's best-validation weights, rolls all
/// members out over the inference set (docs/METHOD.md §5) and the two figure
/// trajectories. Result e belongs to seeds[e] and depends on nothing but the
/// cell, the data and that seed. A member whose loss turns non-finite is
/// frozen and reported as diverged; the others go on. With
/// training.precision = kFloat32 training runs in float32 and the rollouts
/// in float64 from the best weights upcast (docs/DECISIONS.md); the stored
/// RunResult::weights are those float64 values.
/// If `trained` is given it receives the (float64) model stack the rollouts
/// used, with the best weights.
/// With `checkpointing`, training states are saved and resumed as it says.
std::vector<RunResult> train_cell(const CellSpec& cell, const PhSystemData& data,
                                  const PhSystem& system, const ProgressCallback& progress = {},
                                  std::unique_ptr<DynamicsModel>* trained = nullptr,
                                  const CellCheckpointing* checkpointing = nullptr);

/// The structure the n-dimensional models of a system use (its S and J,
/// row-major, and n_x, n_w, n_u).
ModelStructure model_structure(const PhSystem& system);

}  // namespace phnn
