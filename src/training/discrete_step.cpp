// src/training/discrete_step.cpp
#include "phnn/training/discrete_step.h"

#include "phnn/common/check.h"

namespace phnn {

torch::Tensor rk2_step(const DynamicsModel& model, const torch::Tensor& x,
                       const torch::Tensor& u, double h) {
  const auto k1 = model.field(x, u, false).f;
  return x + h * model.field(x + (0.5 * h) * k1, u, false).f;
}

torch::Tensor dg_training_step(const DynamicsModel& model, const torch::Tensor& x,
                               const torch::Tensor& x_next, const torch::Tensor& u, double h,
                               double min_dx_norm) {
  return x + h * model.discrete_gradient_field(x, x_next - x, u, min_dx_norm);
}

DgInferenceStep dg_inference_step(const DynamicsModel& model, const torch::Tensor& x,
                                  const torch::Tensor& u, double h,
                                  const DgInferenceOptions& options) {
  PHNN_REQUIRE(model.is_port_hamiltonian(),
               "dg_inference_step: " << to_string(model.options().kind) << " has no Hamiltonian");
  const int64_t B = x.size(1);
  const double eps = options.fd_step;
  auto dx = rk2_step(model, x, u, h) - x;
  // Row 3 blocks: dx, dx + eps e_q, dx + eps e_p.
  const auto e_q = torch::tensor({eps, 0.0}, x.options());
  const auto e_p = torch::tensor({0.0, eps}, x.options());
  const auto x3 = torch::cat({x, x, x}, 1);
  const auto u3 = torch::cat({u, u, u}, 1);
  DgInferenceStep out;
  auto converged = torch::zeros({x.size(0), B}, x.options().dtype(torch::kBool));
  for (int it = 0; it < options.max_iterations; ++it) {
    const auto dx3 = torch::cat({dx, dx + e_q, dx + e_p}, 1);
    const auto r3 = dx3 - h * model.discrete_gradient_field(x3, dx3, u3, options.min_dx_norm);
    const auto r = r3.narrow(1, 0, B);
    const auto col_q = (r3.narrow(1, B, B) - r) / eps;  // dr/d dx_q  [E, B, 2]
    const auto col_p = (r3.narrow(1, 2 * B, B) - r) / eps;
    // Solve [col_q col_p] delta = -r (Cramer's rule, 2 x 2).
    const auto a = col_q.select(-1, 0), c = col_q.select(-1, 1);
    const auto b = col_p.select(-1, 0), d = col_p.select(-1, 1);
    const auto det = a * d - b * c;
    const auto r0 = r.select(-1, 0), r1 = r.select(-1, 1);
    const auto delta = torch::stack({-(d * r0 - b * r1) / det, -(a * r1 - c * r0) / det}, -1);
    // Converged rows keep their solution.
    const auto step = torch::where(converged.unsqueeze(-1), torch::zeros_like(delta), delta);
    dx = dx + step;
    out.iterations = it + 1;
    converged = converged.logical_or(std::get<0>(step.abs().max(-1)) <= options.tolerance);
    if (converged.all().item<bool>()) break;
  }
  out.x_next = x + dx;
  out.converged = converged;
  return out;
}

}  // namespace phnn
