// src/training/cell_spec.cpp — CellSpec::validate: the cell's options and
// the data it will use are checked before any training starts.
#include <algorithm>
#include <cmath>

#include "phnn/common/check.h"
#include <sstream>

#include "phnn/integrators/integrator.h"
#include "phnn/training/trainer.h"
#include "training/cell_data.h"

namespace phnn {

namespace {

// A non-finite value in the data would turn every member's loss into NaN
// (all frozen at step 0) or every rollout error into NaN: refuse the data
// instead, naming the set, the index and the fix.
std::string row_text(const std::vector<double>& v, std::size_t row, int width) {
  std::ostringstream os;
  os << "(";
  for (int j = 0; j < width; ++j) {
    os << (j ? ", " : "") << v[row * static_cast<std::size_t>(width) + static_cast<std::size_t>(j)];
  }
  os << ")";
  return os.str();
}

bool finite_row(const std::vector<double>& v, std::size_t row, int width) {
  for (int j = 0; j < width; ++j) {
    if (!std::isfinite(v[row * static_cast<std::size_t>(width) + static_cast<std::size_t>(j)])) {
      return false;
    }
  }
  return true;
}

void require_finite_pairs(const FlatPairs& p, std::size_t count, int nx, int nu, const char* what) {
  for (std::size_t i = 0; i < std::min(count, p.count); ++i) {
    PHNN_REQUIRE(finite_row(p.x, i, nx) && finite_row(p.x_next, i, nx) && finite_row(p.u, i, nu),
                 "Invalid data: " << what << " pair " << i << " has a non-finite value (x = "
                                  << row_text(p.x, i, nx) << ", x_next = "
                                  << row_text(p.x_next, i, nx) << ", u = " << row_text(p.u, i, nu)
                                  << "); regenerate the data set (phnn data) or fix its source");
  }
}

void require_finite_data(const CellData& data, int n_train) {
  require_finite_pairs(data.train, static_cast<std::size_t>(n_train), data.n_x, data.n_u, "training");
  require_finite_pairs(data.validation, data.validation.count, data.n_x, data.n_u, "validation");
  const std::size_t points = static_cast<std::size_t>(data.inference_steps) + 1;
  for (std::size_t i = 0; i < data.inference_count; ++i) {
    bool finite = finite_row(data.inference_u, i, data.n_u);
    for (std::size_t n = 0; finite && !data.inference_inputs.empty() &&
                            n < static_cast<std::size_t>(data.inference_steps);
         ++n) {
      finite = finite_row(data.inference_inputs, i * (points - 1) + n, data.n_u);
    }
    std::size_t bad_step = 0;
    for (std::size_t n = 0; finite && n < points; ++n) {
      finite = finite_row(data.inference_states, i * points + n, data.n_x);
      bad_step = n;
    }
    PHNN_REQUIRE(finite, "Invalid data: inference trajectory "
                             << i << " has a non-finite value (input u or the state at step "
                             << bad_step
                             << "); regenerate the data set (phnn data) or fix its source");
  }
}

}  // namespace

void CellSpec::validate(const PhSystemData& data) const { validate_cell(*this, make_split_data(data)); }

void validate_cell(const CellSpec& cell, const CellData& data) {
  cell.training.validate();
  PHNN_REQUIRE(!(cell.model == ModelKind::kNode && is_discrete_gradient(cell.integrator)),
               "integrator = " << to_string(cell.integrator)
                   << " with model = node: the discrete gradient needs a Hamiltonian, which "
                      "NODE has not (use rk2 or rk4, or phnn-s / phnn-jr)");
  PHNN_REQUIRE(cell.n_train >= 1 && static_cast<std::size_t>(cell.n_train) <= data.train.count,
               "n_train = " << cell.n_train << "; the data set has " << data.train.count
                            << " training pairs");
  PHNN_REQUIRE(!cell.seeds.empty(), "no seeds");
  for (std::size_t i = 0; i < cell.seeds.size(); ++i) {
    PHNN_REQUIRE(cell.seeds[i] >= 0, "seed = " << cell.seeds[i] << " must be >= 0");
    for (std::size_t j = 0; j < i; ++j) {
      PHNN_REQUIRE(cell.seeds[i] != cell.seeds[j], "seed " << cell.seeds[i] << " listed twice");
    }
  }
  PHNN_REQUIRE(data.validation.count > 0, "the data set has no validation pairs");
  require_finite_data(data, cell.n_train);
}

CellSpec cell_spec_for(const RunConfig& run, const std::vector<int>& seeds) {
  CellSpec cell;
  cell.model = run.model;
  cell.integrator = run.integrator;
  cell.size = run.size;
  cell.n_train = run.n_train;
  cell.regularizer = run.regularizer;
  cell.training = run.training;
  cell.seeds = seeds;
  return cell;
}

}  // namespace phnn
