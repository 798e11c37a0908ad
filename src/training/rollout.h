// src/training/rollout.h — the inference phase of a cell (private to
// src/training): autoregressive rollouts of every member of a stack over the
// inference set and the two figure trajectories, Eq. 31 per member, and the
// figure trajectories of a RunResult. Touches no file.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <torch/torch.h>

#include "phnn/config/run_result.h"
#include "phnn/models/dynamics_model.h"
#include "phnn/training/trainer.h"
#include "training/cell_data.h"

namespace phnn {

// The model a cell rolls out: float64, on the cell's network path
// (CellSpec::fused_networks), whatever the training precision (float32
// training hands over its best weights upcast, docs/DECISIONS.md), so the
// trainer's inference and `phnn eval` (load_member) build it alike.
ModelOptions inference_model_options(const CellSpec& cell, const CellData& data);

// The autoregressive rollouts of Eq. 31 for every member of the stack:
// the inference trajectories, then the two figure trajectories (rows B_inf,
// B_inf + 1; built-in systems only), from the model's current weights (a
// float64 model).
struct Rollouts {
  torch::Tensor sq_err;           // [E, B_inf]: sum over steps of |x - x_ref|^2
  torch::Tensor diverged;         // [E, B_inf + figures]
  torch::Tensor newton_failures;  // [E]
  torch::Tensor figure;           // [E, steps + 1, 2, n_x] (NaN after divergence); undefined
                                  // without figure trajectories
  int steps = 0;
};
// `stop`, when set, is asked every kRolloutStopEvery steps; true throws
// RolloutStopped (the rollouts are dropped: the caller saves what it needs
// to do them again).
struct RolloutStopped {};
inline constexpr int kRolloutStopEvery = 32;
Rollouts roll_out(const DynamicsModel& model, const CellSpec& cell, const CellData& data,
                  const std::function<bool()>& stop = {});

// Rows per chunk of a DG4 rollout step, or 0 (the default): dg4_chunk_rows.
// The bits do not depend on it (tests/training/rollout_test.cpp sets others).
void set_dg4_rollout_chunk(int64_t rows);

// Rows per chunk of DG4's op-by-op jets for `members` members, n_x states
// and n_u inputs (rollout.cpp): >= 16, 40 for n_x = 8 with 10 members.
int64_t dg4_chunk_rows(int64_t members, int64_t n_x, int64_t n_u);

// Eq. 31 per member from the rollouts: the mean over the inference
// trajectories of their mean squared error, +inf if any diverged.
std::vector<double> member_mse(const Rollouts& rollouts);

// Member e's inference results into r: Eq. 31 (`mse`), the per-trajectory
// errors (+inf for a diverged rollout), the diverged count and the Newton
// failures.
void fill_inference(const Rollouts& rollouts, int64_t e, double mse, RunResult* r);

// Member e's predicted figure trajectories (paper Figures 7 and 9) and the
// true ones (CellData::figure_references) into r; nothing without figures.
void fill_figures(const Rollouts& rollouts, int64_t e, const CellData& data, RunResult* r);

}  // namespace phnn
