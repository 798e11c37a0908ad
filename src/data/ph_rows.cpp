// src/data/ph_rows.cpp — pairs and inference trajectories in flat rows, and
// back to PhPairSet and PhInferenceSet (include/phnn/data/ph_rows.h). In
// memory only.
#include "phnn/data/ph_rows.h"

#include <algorithm>

#include "phnn/common/check.h"

namespace phnn {
namespace {

std::size_t wide(int n) { return static_cast<std::size_t>(n); }

// Row i of `flat` rows of `width` values.
VecX row(const std::vector<double>& flat, int width, std::size_t i) {
  return VecX(Eigen::Map<const VecX>(flat.data() + i * wide(width), width));
}

// Every VecX of `rows`, joined.
void append(const std::vector<VecX>& rows, std::vector<double>* out) {
  for (const VecX& r : rows) out->insert(out->end(), r.data(), r.data() + r.size());
}

}  // namespace

PhPairRows::PhPairRows(int states, int inputs, std::size_t count)
    : n_x(states), n_u(inputs), x(count * wide(states)), x_next(count * wide(states)),
      u(count * wide(inputs)), trajectory(count), position(count) {}

void PhPairRows::set(std::size_t i, std::int64_t id, std::int64_t pos, const double* state,
                     const double* next_state, const double* input) {
  std::copy(state, state + n_x, x.begin() + static_cast<long>(i * wide(n_x)));
  std::copy(next_state, next_state + n_x, x_next.begin() + static_cast<long>(i * wide(n_x)));
  std::copy(input, input + n_u, u.begin() + static_cast<long>(i * wide(n_u)));
  trajectory[i] = id;
  position[i] = pos;
}

PhPairSet PhPairRows::to_pair_set() const {
  PhPairSet p;
  for (std::size_t i = 0; i < size(); ++i) {
    p.x.push_back(row(x, n_x, i));
    p.x_next.push_back(row(x_next, n_x, i));
    p.u.push_back(row(u, n_u, i));
    p.position.push_back(static_cast<int>(position[i]));
  }
  p.trajectory = trajectory;
  p.step = step;
  return p;
}

PhPairRows PhPairRows::of(const PhPairSet& pairs, int states, int inputs) {
  PhPairRows rows(states, inputs, pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    rows.set(i, pairs.trajectory[i], pairs.position[i], pairs.x[i].data(), pairs.x_next[i].data(),
             pairs.u[i].data());
  }
  rows.step = pairs.step;
  return rows;
}

PhInferenceRows::PhInferenceRows(int nx, int nu, std::size_t count, std::size_t length,
                                 bool per_sample_inputs, bool positions)
    : n_x(nx), n_u(nu), samples(length), trajectory(count), u(count * wide(nu)),
      states(count * length * wide(nx)), inputs(per_sample_inputs ? count * length * wide(nu) : 0),
      position(positions ? count : 0) {}

PhInferenceSet PhInferenceRows::to_inference_set() const {
  PhInferenceSet set;
  set.trajectory = trajectory;
  set.position = position;
  set.step = step;
  for (std::size_t i = 0; i < size(); ++i) {
    set.u.push_back(row(u, n_u, i));
    std::vector<VecX> traj, in;
    for (std::size_t k = 0; k < samples; ++k) {
      traj.push_back(row(states, n_x, i * samples + k));
      if (!inputs.empty()) in.push_back(row(inputs, n_u, i * samples + k));
    }
    set.states.push_back(std::move(traj));
    if (!inputs.empty()) set.inputs.push_back(std::move(in));
  }
  return set;
}

PhInferenceRows PhInferenceRows::of(const PhInferenceSet& set, int nx, int nu) {
  const std::size_t m = set.size();
  PhInferenceRows rows;
  rows.n_x = nx;
  rows.n_u = nu;
  rows.samples = m ? set.states[0].size() : 0;
  rows.trajectory = set.trajectory;
  for (const auto& traj : set.states) append(traj, &rows.states);
  append(set.u, &rows.u);
  if (!set.inputs.empty()) {
    PHNN_REQUIRE(set.inputs.size() == m, "write_ph_system_data: inputs of " << set.inputs.size()
                                             << " of " << m << " inference trajectories");
    for (const auto& traj : set.inputs) {
      PHNN_REQUIRE(traj.size() == rows.samples,
                   "write_ph_system_data: " << traj.size() << " inputs for " << rows.samples << " samples");
      append(traj, &rows.inputs);
    }
  }
  PHNN_REQUIRE(set.position.empty() || set.position.size() == m,
               "write_ph_system_data: " << set.position.size() << " start samples for " << m << " windows");
  rows.position = set.position;
  rows.step = set.step;
  return rows;
}

}  // namespace phnn
