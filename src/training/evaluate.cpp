// src/training/evaluate.cpp — a stored run reloaded and evaluated again
// (include/phnn/training/evaluate.h), through the trainer's rollout code.
#include "phnn/training/evaluate.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "phnn/systems/oscillators.h"
#include "training/rollout.h"

namespace phnn {
namespace {

// Points of a [n][2] trajectory as a tensor [1, n, 2].
torch::Tensor as_states(const std::vector<double>& flat) {
  const auto n = static_cast<int64_t>(flat.size() / 2);
  return torch::from_blob(const_cast<double*>(flat.data()), {1, n, 2}, torch::kFloat64).clone();
}

EnergyTrace energy_trace(const DynamicsModel& model, const Oscillator& system, double step,
                         const std::vector<double>& prediction,
                         const std::vector<double>& reference) {
  const std::size_t n = std::min(prediction.size(), reference.size()) / 2;
  std::vector<double> h_model(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> h_model_ref = h_model;
  if (model.is_port_hamiltonian() && n > 0) {
    torch::NoGradGuard no_grad;
    const auto a = model.hamiltonian(as_states(prediction)).reshape({-1}).contiguous();
    const auto b = model.hamiltonian(as_states(reference)).reshape({-1}).contiguous();
    for (std::size_t i = 0; i < n; ++i) {
      h_model[i] = a[static_cast<int64_t>(i)].item<double>();
      h_model_ref[i] = b[static_cast<int64_t>(i)].item<double>();
    }
  }
  EnergyTrace trace;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 x(prediction[2 * i], prediction[2 * i + 1]);
    const Vec2 x_ref(reference[2 * i], reference[2 * i + 1]);
    // A diverged rollout has NaN states; H of them is NaN, as it should be.
    trace.rows.push_back({static_cast<double>(i) * step, x(0), x(1), x_ref(0), x_ref(1),
                          system.hamiltonian(x), system.hamiltonian(x_ref), h_model[i],
                          h_model_ref[i]});
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

std::unique_ptr<DynamicsModel> load_member(const CellSpec& cell, const SystemData& data,
                                           const std::vector<double>& weights) {
  return load_member(cell, make_cell_data(data, /*with_figures=*/false), weights);
}

Evaluation evaluate_stored_run(const CellSpec& cell, const SystemData& data,
                               const std::vector<double>& weights) {
  std::unique_ptr<DynamicsModel> model;
  Evaluation out = evaluate_on(cell, make_cell_data(data), weights, &model);
  const RunResult& r = out.result;
  const Oscillator system(data.system);
  out.energy_05 = energy_trace(*model, system, data.inference.step, r.figure_prediction_05,
                               r.figure_reference_05);
  out.energy_075 = energy_trace(*model, system, data.inference.step, r.figure_prediction_075,
                                r.figure_reference_075);
  return out;
}

Evaluation evaluate_stored_run(const CellSpec& cell, const PhSystemData& data,
                               const PhSystem& system, const std::vector<double>& weights) {
  std::unique_ptr<DynamicsModel> model;
  return evaluate_on(cell, make_cell_data(data, system), weights, &model);
}

}  // namespace phnn
