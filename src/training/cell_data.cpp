// src/training/cell_data.cpp — CellData from the two kinds of data sets.
#include "training/cell_data.h"

#include "phnn/common/check.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace {

Eigen::Matrix<double, 1, 1> as_vector(double u) { return Eigen::Matrix<double, 1, 1>(u); }
const VecX& as_vector(const VecX& u) { return u; }

template <class Vec>
void append(const Vec& v, std::vector<double>* out) {
  for (int i = 0; i < static_cast<int>(v.size()); ++i) out->push_back(v(i));
}

FlatPairs flatten(const PairSet& p) {
  FlatPairs out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    append(p.x[i], &out.x);
    append(p.x_next[i], &out.x_next);
    out.u.push_back(p.u[i]);
  }
  out.count = p.size();
  return out;
}

FlatPairs flatten(const PhPairSet& p) {
  FlatPairs out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    append(p.x[i], &out.x);
    append(p.x_next[i], &out.x_next);
    append(p.u[i], &out.u);
  }
  out.count = p.size();
  return out;
}

std::vector<double> row_major(const MatX& m) {
  std::vector<double> out;
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) out.push_back(m(r, c));
  }
  return out;
}

// The split sizes, steps and inference trajectories of either data set.
template <class Data>
CellData common_cell_data(const Data& data) {
  CellData d;
  d.step = data.train.step;
  d.train = flatten(data.train);
  d.validation = flatten(data.validation);
  d.inference_count = data.inference.size();
  d.inference_steps =
      static_cast<int>(data.inference.states.empty() ? 0 : data.inference.states[0].size() - 1);
  d.inference_step = data.inference.step;
  for (std::size_t i = 0; i < data.inference.size(); ++i) {
    for (const auto& x : data.inference.states[i]) append(x, &d.inference_states);
    append(as_vector(data.inference.u[i]), &d.inference_u);
  }
  return d;
}

}  // namespace

ModelStructure model_structure(const PhSystem& system) {
  ModelStructure s;
  s.n_x = system.n_x();
  s.n_w = system.n_w();
  s.n_u = system.n_u();
  s.S = row_major(system.S());
  s.J = row_major(system.J());
  return s;
}

CellData make_cell_data(const SystemData& data, bool with_figures) {
  CellData d = common_cell_data(data);
  d.builtin = data.system.kind;
  if (!with_figures) return d;
  d.has_figures = true;
  const FigureSetup fig = figure_setup(data.system);
  d.figure_x0 = {std::vector<double>{fig.x0_05(0), fig.x0_05(1)},
                 std::vector<double>{fig.x0_075(0), fig.x0_075(1)}};
  d.figure_u = {std::vector<double>{fig.u}, std::vector<double>{fig.u}};
  d.figure_references = {reference_trajectory(data.system, data.options, fig.x0_05, fig.u),
                         reference_trajectory(data.system, data.options, fig.x0_075, fig.u)};
  return d;
}

CellData make_cell_data(const PhSystemData& data, const PhSystem& system) {
  CellData d = common_cell_data(data);
  d.n_x = system.n_x();
  d.n_u = system.n_u();
  // Time-varying inputs: u_n of steps 0..steps-1 (the last sample's input
  // moves no step).
  for (const auto& traj : data.inference.inputs) {
    PHNN_REQUIRE(traj.size() >= static_cast<std::size_t>(d.inference_steps),
                 "make_cell_data: " << traj.size() << " inputs for " << d.inference_steps << " steps");
    for (int n = 0; n < d.inference_steps; ++n) append(traj[static_cast<std::size_t>(n)], &d.inference_inputs);
  }
  d.general = std::make_shared<ModelStructure>(model_structure(system));
  if (d.inference_count == 0) return d;
  d.has_figures = true;
  const std::size_t nx = static_cast<std::size_t>(d.n_x), nu = static_cast<std::size_t>(d.n_u);
  const std::size_t points = static_cast<std::size_t>(d.inference_steps) + 1;
  for (std::size_t k = 0; k < 2; ++k) {
    const std::size_t i = std::min(k, d.inference_count - 1);
    const auto states = d.inference_states.begin() + static_cast<long>(i * points * nx);
    d.figure_references[k].assign(states, states + static_cast<long>(points * nx));
    d.figure_x0[k].assign(states, states + static_cast<long>(nx));
    const auto u = d.inference_u.begin() + static_cast<long>(i * nu);
    d.figure_u[k].assign(u, u + static_cast<long>(nu));
    if (!d.inference_inputs.empty()) {
      const std::size_t per = static_cast<std::size_t>(d.inference_steps) * nu;
      const auto in = d.inference_inputs.begin() + static_cast<long>(i * per);
      d.figure_inputs[k].assign(in, in + static_cast<long>(per));
    }
  }
  return d;
}

}  // namespace phnn
