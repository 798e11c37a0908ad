// src/training/cell_data.cpp — CellData from a data set and its system.
#include "training/cell_data.h"

#include "phnn/common/check.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace {

template <class Vec>
void append(const Vec& v, std::vector<double>* out) {
  for (int i = 0; i < static_cast<int>(v.size()); ++i) out->push_back(v(i));
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

// The split sizes, steps and inference trajectories.
CellData common_cell_data(const PhSystemData& data) {
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
    append(data.inference.u[i], &d.inference_u);
  }
  return d;
}

// The two figure trajectories from `figures` (ph_figure_set's, or the
// inference set; one trajectory is shown twice). With time-varying
// inference inputs they need u at every step: the set's own (inference), or
// its constant u repeated (figure energies).
void set_figures(const PhInferenceSet& figures, CellData* d) {
  d->has_figures = true;
  for (std::size_t k = 0; k < 2; ++k) {
    const std::size_t i = std::min(k, figures.size() - 1);
    d->figure_references[k].clear();
    for (const VecX& x : figures.states[i]) append(x, &d->figure_references[k]);
    d->figure_x0[k].clear();
    append(figures.states[i].front(), &d->figure_x0[k]);
    d->figure_u[k].clear();
    append(figures.u[i], &d->figure_u[k]);
    d->figure_inputs[k].clear();
    for (int n = 0; !d->inference_inputs.empty() && n < d->inference_steps; ++n) {
      append(figures.inputs.empty() ? figures.u[i] : figures.inputs[i][static_cast<std::size_t>(n)],
             &d->figure_inputs[k]);
    }
  }
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

CellData make_split_data(const PhSystemData& data) {
  CellData d = common_cell_data(data);
  d.n_x = static_cast<int>(data.state_names.size());
  d.n_u = static_cast<int>(data.input_names.size());
  // Time-varying inputs: u_n of steps 0..steps-1 (the last sample's input
  // moves no step).
  for (const auto& traj : data.inference.inputs) {
    PHNN_REQUIRE(traj.size() >= static_cast<std::size_t>(d.inference_steps),
                 "make_cell_data: " << traj.size() << " inputs for " << d.inference_steps << " steps");
    for (int n = 0; n < d.inference_steps; ++n) append(traj[static_cast<std::size_t>(n)], &d.inference_inputs);
  }
  return d;
}

CellData make_cell_data(const PhSystemData& data, const PhSystem& system) {
  CellData d = make_split_data(data);
  PHNN_REQUIRE(d.n_x == system.n_x() && d.n_u == system.n_u(),
               "make_cell_data: a data set of " << d.n_x << " states and " << d.n_u
                                                 << " inputs for system " << system.name() << " of "
                                                 << system.n_x() << " and " << system.n_u());
  d.general = std::make_shared<ModelStructure>(model_structure(system));
  if (!system.figure_energies().empty() && system.has_energy()) {
    set_figures(ph_figure_set(system, data.options), &d);
    return d;
  }
  if (d.inference_count > 0) set_figures(data.inference, &d);
  return d;
}

}  // namespace phnn
