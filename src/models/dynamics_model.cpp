// src/models/dynamics_model.cpp — the learned vector field f_theta of a stack
// of E models (phnn/models/dynamics_model.h).
#include "phnn/models/dynamics_model.h"

#include "phnn/common/check.h"
#include "phnn/models/general_ph.h"
#include "phnn/systems/builtin_systems.h"

namespace phnn {

torch::Tensor DynamicsModel::discrete_gradient_field(const torch::Tensor&, const torch::Tensor&,
                                                     const torch::Tensor&, double) const {
  PHNN_REQUIRE(false, "discrete_gradient_field: " << to_string(options_.kind)
                                                  << " has no Hamiltonian; the DG integrator "
                                                     "needs phnn-s or phnn-jr");
  return {};
}

FieldEval DynamicsModel::discrete_gradient_field_with_jacobian(const torch::Tensor&,
                                                               const torch::Tensor&,
                                                               const torch::Tensor&,
                                                               double) const {
  PHNN_REQUIRE(false, "discrete_gradient_field_with_jacobian: " << to_string(options_.kind)
                                                                << " has no Hamiltonian");
  return {};
}

FieldEval DynamicsModel::discrete_gradient4_field(const torch::Tensor&, const torch::Tensor&,
                                                   const torch::Tensor&, double, double) const {
  PHNN_REQUIRE(false, "discrete_gradient4_field: " << to_string(options_.kind)
                                                   << " has no Hamiltonian; the DG4 integrator "
                                                      "needs phnn-s or phnn-jr");
  return {};
}

torch::Tensor DynamicsModel::explicit_mean_l1_step(IntegratorKind, const torch::Tensor&,
                                                   const torch::Tensor&, const torch::Tensor&,
                                                   double, const JacobianPenalty&) const {
  return {};
}

torch::Tensor DynamicsModel::dg_mean_l1_step(const torch::Tensor&, const torch::Tensor&,
                                             const torch::Tensor&, double, double,
                                             const JacobianPenalty&) const {
  return {};
}

torch::Tensor DynamicsModel::dg4_mean_l1_step(const torch::Tensor&, const torch::Tensor&,
                                              const torch::Tensor&, double, double,
                                              const JacobianPenalty&) const {
  return {};
}

// An integrator without a case has no hand-written step: undefined, and the
// trainer runs autograd on training_step.
torch::Tensor DynamicsModel::mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                          const torch::Tensor& x_next, const torch::Tensor& u,
                                          double h, double min_dx_norm,
                                          const JacobianPenalty& penalty) const {
  switch (integrator) {
    case IntegratorKind::kRk2:
    case IntegratorKind::kRk4:
      return explicit_mean_l1_step(integrator, x, x_next, u, h, penalty);
    case IntegratorKind::kDg:
      return dg_mean_l1_step(x, x_next, u, h, min_dx_norm, penalty);
    case IntegratorKind::kDg4:
      return dg4_mean_l1_step(x, x_next, u, h, min_dx_norm, penalty);
  }
  return {};
}

torch::Tensor DynamicsModel::hamiltonian(const torch::Tensor&) const {
  PHNN_REQUIRE(false, "hamiltonian: " << to_string(options_.kind) << " has no Hamiltonian");
  return {};
}

torch::Tensor DynamicsModel::grad_hamiltonian(const torch::Tensor&) const {
  PHNN_REQUIRE(false, "grad_hamiltonian: " << to_string(options_.kind) << " has no Hamiltonian");
  return {};
}

std::vector<torch::Tensor> DynamicsModel::parameters() const {
  std::vector<torch::Tensor> out;
  for (const auto& net : nets_) {
    for (const auto& p : net->parameters()) out.push_back(p);
  }
  return out;
}

DynamicsModel::FlatParameters DynamicsModel::flatten_parameters() {
  const std::vector<torch::Tensor> params = parameters();
  int64_t total = 0;
  for (const auto& p : params) total += p.numel();
  FlatParameters flat{torch::empty({total}, options_.dtype), torch::zeros({total}, options_.dtype)};
  {
    torch::NoGradGuard no_grad;
    int64_t offset = 0;
    for (const auto& p : params) {
      flat.values.narrow(0, offset, p.numel()).copy_(p.detach().reshape({-1}));
      offset += p.numel();
    }
  }
  int64_t offset = 0;
  for (auto& net : nets_) net->bind_to(flat.values, flat.gradients, &offset);
  return flat;
}

std::vector<torch::Tensor> DynamicsModel::unflatten(const torch::Tensor& flat_like) const {
  std::vector<torch::Tensor> out;
  int64_t offset = 0;
  for (const auto& p : parameters()) {
    out.push_back(flat_like.narrow(0, offset, p.numel()).view(p.sizes()));
    offset += p.numel();
  }
  return out;
}

long DynamicsModel::parameter_count() const {
  long n = 0;
  for (const auto& net : nets_) n += net->parameter_count();
  return n;
}

const std::vector<const StackedMlp*> DynamicsModel::networks() const {
  std::vector<const StackedMlp*> out;
  for (const auto& net : nets_) out.push_back(net.get());
  return out;
}

ModelStructure builtin_structure(SystemKind kind) {
  const auto system = builtin_system(OscillatorOptions::defaults(kind), BuiltinEnergies{});
  ModelStructure s{2, 1, 1, {}, {}};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) s.S.push_back(system->S()(r, c));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) s.J.push_back(system->J()(r, c));
  return s;
}

// One model family for every system: a built-in system's models are the
// n-state ones on its structure.
std::unique_ptr<DynamicsModel> DynamicsModel::create(const ModelOptions& options_in,
                                                     const std::vector<std::uint64_t>& seeds) {
  ModelOptions options = options_in;
  if (!options.general)
    options.general = std::make_shared<ModelStructure>(builtin_structure(options.structure));
  switch (options.kind) {
    case ModelKind::kNode: return std::make_unique<Node>(options, seeds);
    case ModelKind::kPhnnS: return std::make_unique<PhnnS>(options, seeds);
    case ModelKind::kPhnnJr: return std::make_unique<PhnnJr>(options, seeds);
  }
  PHNN_CHECK(false, "unknown model kind");
  return nullptr;
}

}  // namespace phnn
