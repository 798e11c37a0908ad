// src/training/cell_spec.cpp — CellSpec::validate: the cell's options and
// the data it will use are checked before any training starts.
#include <algorithm>
#include <cmath>

#include "phnn/common/check.h"
#include "phnn/training/trainer.h"

namespace phnn {

namespace {

// A non-finite value in the data would turn every member's loss into NaN
// (all frozen at step 0) or every rollout error into NaN: refuse the data
// instead, naming the set, the index and the fix.
void require_finite_pairs(const PairSet& pairs, std::size_t count, const char* what) {
  for (std::size_t i = 0; i < std::min(count, pairs.size()); ++i) {
    PHNN_REQUIRE(pairs.x[i].allFinite() && pairs.x_next[i].allFinite() && std::isfinite(pairs.u[i]),
                 "Invalid data: " << what << " pair " << i << " has a non-finite value (x = ("
                                  << pairs.x[i](0) << ", " << pairs.x[i](1) << "), x_next = ("
                                  << pairs.x_next[i](0) << ", " << pairs.x_next[i](1)
                                  << "), u = " << pairs.u[i]
                                  << "); regenerate the data set (phnn data) or fix its source");
  }
}

void require_finite_data(const SystemData& data, int n_train) {
  require_finite_pairs(data.train, static_cast<std::size_t>(n_train), "training");
  require_finite_pairs(data.validation, data.validation.size(), "validation");
  const InferenceSet& inf = data.inference;
  for (std::size_t i = 0; i < inf.size(); ++i) {
    bool finite = std::isfinite(inf.u[i]);
    std::size_t bad_step = 0;
    for (std::size_t n = 0; finite && n < inf.states[i].size(); ++n) {
      finite = inf.states[i][n].allFinite();
      bad_step = n;
    }
    PHNN_REQUIRE(finite, "Invalid data: inference trajectory "
                             << i << " has a non-finite value (input u or the state at step "
                             << bad_step
                             << "); regenerate the data set (phnn data) or fix its source");
  }
}

}  // namespace

void CellSpec::validate(const SystemData& data) const {
  training.validate();
  PHNN_REQUIRE(!(model == ModelKind::kNode && is_discrete_gradient(integrator)),
               "integrator = " << to_string(integrator)
                   << " with model = node: the discrete gradient needs a Hamiltonian, which "
                      "NODE has not (use rk2 or rk4, or phnn-s / phnn-jr)");
  PHNN_REQUIRE(n_train >= 1 && static_cast<std::size_t>(n_train) <= data.train.size(),
               "n_train = " << n_train << "; the data set has "
                                              << data.train.size() << " training pairs");
  PHNN_REQUIRE(!seeds.empty(), "no seeds");
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    PHNN_REQUIRE(seeds[i] >= 0, "seed = " << seeds[i] << " must be >= 0");
    for (std::size_t j = 0; j < i; ++j) {
      PHNN_REQUIRE(seeds[i] != seeds[j], "seed " << seeds[i] << " listed twice");
    }
  }
  PHNN_REQUIRE(!data.validation.x.empty(), "the data set has no validation pairs");
  require_finite_data(data, n_train);
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
