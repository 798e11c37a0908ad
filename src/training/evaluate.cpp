// src/training/evaluate.cpp — a stored run reloaded and evaluated again
// (include/phnn/training/evaluate.h), through the trainer's rollout code.
#include "phnn/training/evaluate.h"

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "training/rollout.h"

namespace phnn {
namespace {

// Points of a [n][n_x] trajectory as a tensor [1, n, n_x].
torch::Tensor as_states(const std::vector<double>& flat, int64_t nx) {
  const auto n = static_cast<int64_t>(flat.size()) / nx;
  return torch::from_blob(const_cast<double*>(flat.data()), {1, n, nx}, torch::kFloat64).clone();
}

// The learned energy at every point of a [n][n_x] trajectory (NaN for NODE).
std::vector<double> learned_energy(const DynamicsModel& model, const std::vector<double>& flat,
                                   int64_t nx) {
  const std::size_t n = flat.size() / static_cast<std::size_t>(nx);
  std::vector<double> h(n, std::numeric_limits<double>::quiet_NaN());
  if (!model.is_port_hamiltonian() || n == 0) return h;
  torch::NoGradGuard no_grad;
  const auto values = model.hamiltonian(as_states(flat, nx)).reshape({-1}).contiguous();
  for (std::size_t i = 0; i < n; ++i) h[i] = values[static_cast<int64_t>(i)].item<double>();
  return h;
}

// The energy trace of one figure trajectory of n_x = names.size() states;
// `energy` is the true Hamiltonian.
EnergyTrace energy_trace(const DynamicsModel& model,
                         const std::function<double(const VecX&)>& energy, double step,
                         const std::vector<std::string>& names,
                         const std::vector<double>& prediction,
                         const std::vector<double>& reference) {
  const auto nx = static_cast<int64_t>(names.size());
  const std::size_t n = std::min(prediction.size(), reference.size()) / static_cast<std::size_t>(nx);
  const std::vector<double> h_model = learned_energy(model, prediction, nx);
  const std::vector<double> h_model_ref = learned_energy(model, reference, nx);
  EnergyTrace trace;
  trace.columns = "t";
  for (const std::string& name : names) trace.columns += "," + name;
  for (const std::string& name : names) trace.columns += "," + name + "_ref";
  trace.columns += ",H_true,H_true_ref,H_model,H_model_ref";
  for (std::size_t i = 0; i < n; ++i) {
    const auto at = static_cast<std::ptrdiff_t>(i) * nx;
    const VecX x = Eigen::Map<const VecX>(prediction.data() + at, nx);
    const VecX x_ref = Eigen::Map<const VecX>(reference.data() + at, nx);
    std::vector<double> row = {static_cast<double>(i) * step};
    row.insert(row.end(), x.data(), x.data() + nx);
    row.insert(row.end(), x_ref.data(), x_ref.data() + nx);
    // A diverged rollout has NaN states; H of them is NaN, as it should be.
    row.insert(row.end(), {energy(x), energy(x_ref), h_model[i], h_model_ref[i]});
    trace.rows.push_back(std::move(row));
  }
  return trace;
}

}  // namespace

namespace {

std::unique_ptr<DynamicsModel> load_member(const CellSpec& cell, const CellData& data,
                                           const std::vector<double>& weights) {
  if (cell.seeds.size() != 1) {
    throw std::invalid_argument("load_member: expected one seed, got " +
                                std::to_string(cell.seeds.size()));
  }
  // The trainer's inference model (float64 whatever the training precision).
  auto model = DynamicsModel::create(inference_model_options(cell, data),
                                     {static_cast<std::uint64_t>(cell.seeds[0])});
  if (static_cast<long>(weights.size()) != model->parameter_count()) {
    throw std::invalid_argument("load_member: " + std::to_string(weights.size()) +
                                " stored weights, the model has " +
                                std::to_string(model->parameter_count()) + " parameters");
  }
  torch::NoGradGuard no_grad;
  std::size_t at = 0;
  for (torch::Tensor p : model->parameters()) {
    const int64_t n = p.numel();
    const auto values = torch::from_blob(const_cast<double*>(weights.data() + at), {n},
                                         torch::kFloat64);
    p.copy_(values.reshape(p.sizes()));
    at += static_cast<std::size_t>(n);
  }
  return model;
}

// Inference results of the stored weights on `cell_data`.
Evaluation evaluate_on(const CellSpec& cell, const CellData& cell_data,
                       const std::vector<double>& weights,
                       std::unique_ptr<DynamicsModel>* model_out) {
  validate_cell(cell, cell_data);
  auto model = load_member(cell, cell_data, weights);
  const Rollouts rollouts = roll_out(*model, cell, cell_data);
  Evaluation out;
  RunResult& r = out.result;
  fill_inference(rollouts, /*e=*/0, member_mse(rollouts).at(0), &r);
  fill_figures(rollouts, /*e=*/0, cell_data, &r);
  r.parameter_count = model->parameter_count();
  r.weights = weights;
  r.status = r.diverged_rollouts > 0 ? RunStatus::kDiverged : RunStatus::kDone;
  *model_out = std::move(model);
  return out;
}

}  // namespace

Evaluation evaluate_stored_run(const CellSpec& cell, const PhSystemData& data,
                               const PhSystem& system, const std::vector<double>& weights) {
  std::unique_ptr<DynamicsModel> model;
  Evaluation out = evaluate_on(cell, make_cell_data(data, system), weights, &model);
  const RunResult& r = out.result;
  // A structure-only system (measured data) has no true energy to compare.
  const auto energy = [&system](const VecX& x) {
    return system.has_energy() ? system.hamiltonian(x) : std::numeric_limits<double>::quiet_NaN();
  };
  out.energy_05 = energy_trace(*model, energy, data.inference.step, data.state_names,
                               r.figure_prediction_05, r.figure_reference_05);
  out.energy_075 = energy_trace(*model, energy, data.inference.step, data.state_names,
                                r.figure_prediction_075, r.figure_reference_075);
  if (system.has_energy()) out.figure_energies = system.figure_energies();
  return out;
}

}  // namespace phnn
