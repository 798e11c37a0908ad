// src/training/cell_data.h — what a cell trains and rolls out on, in any
// dimension (private to src/training): the pairs and inference trajectories
// as flat row-major arrays, the model structure (the system's S and J), and
// the two figure trajectories. Made from a data set and its system.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "phnn/config/model_config.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/systems/ph_system.h"

namespace phnn {

// Pairs (x_n, u, x_{n+1}) as [count][n_x], [count][n_u].
struct FlatPairs {
  std::vector<double> x, x_next, u;
  std::size_t count = 0;
};

struct CellData {
  int n_x = 2, n_u = 1;
  double step = 0.01;  // h of the pairs
  FlatPairs train, validation;
  // Inference: states [count][steps + 1][n_x], inputs [count][n_u].
  std::vector<double> inference_states, inference_u;
  // Time-varying inputs: u_n of every step, [count][steps][n_u] (u_n held
  // over step n -> n + 1); empty when the inputs are constant.
  std::vector<double> inference_inputs;
  std::size_t inference_count = 0;
  int inference_steps = 0;
  double inference_step = 0.01;
  // The two figure trajectories: their x0 (n_x), input (n_u) and true
  // trajectory ([steps + 1][n_x]): ph_figure_set's (the paper's three: from
  // H(x0) = 0.5 J and 0.75 J), else inference trajectories 0 and 1.
  bool has_figures = false;
  std::array<std::vector<double>, 2> figure_x0, figure_u;
  std::array<std::vector<double>, 2> figure_inputs;  // [steps][n_u] as inference_inputs
  std::array<std::vector<double>, 2> figure_references;
  // The structure of the models (the system's S and J).
  std::shared_ptr<const ModelStructure> general;
};

struct CellSpec;  // phnn/training/trainer.h

// CellSpec::validate on any data: options, n_train against the pairs, seeds,
// finite data; std::invalid_argument naming the field and the fix.
void validate_cell(const CellSpec& cell, const CellData& data);

// The splits of `data` alone (no structure, no figure trajectories): what
// validate_cell reads.
CellData make_split_data(const PhSystemData& data);
// A data set of `system`. Its figure trajectories: ph_figure_set's when
// the system has figure energies (generated here), else inference
// trajectories 0 and 1 (the only one twice; none without any).
CellData make_cell_data(const PhSystemData& data, const PhSystem& system);

}  // namespace phnn
