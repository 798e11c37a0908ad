// src/training/cell_data.h — what a cell trains and rolls out on, in any
// dimension (private to src/training): the pairs and inference trajectories
// as flat row-major arrays, the model structure (a built-in system's kind,
// or a file-defined system's S and J), and the paper's figure trajectories
// where the system has them (built-in systems). Made from a built-in
// SystemData or from a file-defined system's PhSystemData; the same doubles
// either way, so the paper path's tensors are bitwise what they were.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "phnn/data/dataset_file.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/models/model_config.h"
#include "phnn/systems/oscillators.h"
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
  std::size_t inference_count = 0;
  int inference_steps = 0;
  double inference_step = 0.01;
  // Built-in systems: the structure's kind and the figure trajectories
  // (x0 at H = 0.5 J and 0.75 J, their input, the true trajectories [n][2]).
  SystemKind builtin = SystemKind::kHarmonic;
  bool has_figures = false;
  std::array<std::array<double, 2>, 2> figure_x0{};
  double figure_u = 0.0;
  std::array<std::vector<double>, 2> figure_references;
  // File-defined systems: the structure of the n-dimensional models.
  std::shared_ptr<const ModelStructure> general;
};

struct CellSpec;  // phnn/training/trainer.h

// CellSpec::validate on any data: options, n_train against the pairs, seeds,
// finite data; std::invalid_argument naming the field and the fix.
void validate_cell(const CellSpec& cell, const CellData& data);

// A built-in system's data set, with its figure trajectories (two reference
// integrations of the true system) unless `with_figures` is false (checks
// that read the pairs and inference trajectories only).
CellData make_cell_data(const SystemData& data, bool with_figures = true);
// A file-defined (or any PhSystem's) data set: no figure trajectories.
CellData make_cell_data(const PhSystemData& data, const PhSystem& system);

}  // namespace phnn
