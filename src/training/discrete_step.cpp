// src/training/discrete_step.cpp — the discrete models g_theta (Eqs. 28-30)
// declared in phnn/training/discrete_step.h.
#include "phnn/training/discrete_step.h"

#include <cmath>
#include <utility>
#include <vector>

#include "kernels/ordered_sum.h"
#include "phnn/common/check.h"
#include "phnn/common/small_lu.h"

namespace phnn {

namespace {
torch::Tensor first_stage(const DynamicsModel& model, const torch::Tensor& x,
                          const torch::Tensor& u, const torch::Tensor& k1) {
  return k1.defined() ? k1 : model.field(x, u, false).f;
}
}  // namespace

torch::Tensor rk2_step(const DynamicsModel& model, const torch::Tensor& x,
                       const torch::Tensor& u, double h, const torch::Tensor& k1_given) {
  const auto k1 = first_stage(model, x, u, k1_given);
  return x + h * model.field(x + (0.5 * h) * k1, u, false).f;
}

torch::Tensor rk4_step(const DynamicsModel& model, const torch::Tensor& x,
                       const torch::Tensor& u, double h, const torch::Tensor& k1_given) {
  const auto k1 = first_stage(model, x, u, k1_given);
  const auto k2 = model.field(x + (0.5 * h) * k1, u, false).f;
  const auto k3 = model.field(x + (0.5 * h) * k2, u, false).f;
  const auto k4 = model.field(x + h * k3, u, false).f;
  return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

torch::Tensor explicit_step(const DynamicsModel& model, IntegratorKind integrator,
                            const torch::Tensor& x, const torch::Tensor& u, double h,
                            const torch::Tensor& k1) {
  switch (integrator) {
    case IntegratorKind::kRk2: return rk2_step(model, x, u, h, k1);
    case IntegratorKind::kRk4: return rk4_step(model, x, u, h, k1);
    case IntegratorKind::kDg:
    case IntegratorKind::kDg4: break;
  }
  PHNN_CHECK(false, "explicit_step: " << to_string(integrator) << " is not explicit");
  return {};
}

torch::Tensor training_step(const DynamicsModel& model, IntegratorKind integrator,
                            const torch::Tensor& x, const torch::Tensor& x_next,
                            const torch::Tensor& u, double h, double min_dx_norm,
                            const torch::Tensor& k1) {
  switch (integrator) {
    case IntegratorKind::kDg:
      return dg_training_step(model, x, x_next, u, h, min_dx_norm);
    case IntegratorKind::kDg4:
      return dg4_training_step(model, x, x_next, u, h, min_dx_norm);
    case IntegratorKind::kRk2:
    case IntegratorKind::kRk4:
      break;
  }
  return explicit_step(model, integrator, x, u, h, k1);
}

DgInferenceStep inference_step(const DynamicsModel& model, IntegratorKind integrator,
                               const torch::Tensor& x, const torch::Tensor& u, double h,
                               const DgInferenceOptions& options, DgNewtonJacobian* cache) {
  switch (integrator) {
    case IntegratorKind::kDg:
      return dg_inference_step(model, x, u, h, options, cache);
    case IntegratorKind::kDg4:
      return dg4_inference_step(model, x, u, h, options);
    case IntegratorKind::kRk2:
    case IntegratorKind::kRk4:
      break;
  }
  DgInferenceStep s;
  s.x_next = explicit_step(model, integrator, x, u, h);
  return s;
}

torch::Tensor dg_training_step(const DynamicsModel& model, const torch::Tensor& x,
                               const torch::Tensor& x_next, const torch::Tensor& u, double h,
                               double min_dx_norm) {
  return x + h * model.discrete_gradient_field(x, x_next - x, u, min_dx_norm);
}

torch::Tensor discrete_loss(const torch::Tensor& x_next, const torch::Tensor& x_hat, double h,
                            LossNorm norm) {
  const auto scaled = (x_next - x_hat) / h;  // [E, B, 2]
  switch (norm) {
    case LossNorm::kMeanL1: return internal::ordered_mean(scaled.abs(), 2);
    case LossNorm::kSumL1: return internal::ordered_mean(internal::ordered_sum(scaled.abs(), 1), 1);
    case LossNorm::kMse: return internal::ordered_mean(scaled * scaled, 2);
  }
  PHNN_CHECK(false, "discrete_loss: unknown LossNorm " << static_cast<int>(norm));
  return {};
}

namespace {

// x with M x = r for every row (M [.., n, n], r [.., n], float64, no
// gradient): common/small_lu.h, one fixed order of operations. LAPACK's
// solve (torch::linalg_solve) runs OpenBLAS kernels chosen by CPU, so its
// last bits changed between machines; it also threw on a singular M, where
// this gives inf/NaN and the rollout marks the row diverged.
torch::Tensor lu_solve_rows(const torch::Tensor& M, const torch::Tensor& r) {
  PHNN_CHECK(r.scalar_type() == torch::kFloat64 && !(torch::GradMode::is_enabled() && (M.requires_grad() || r.requires_grad())),
             "lu_solve_rows: float64 inference only");
  const int64_t n = r.size(-1);
  std::vector<int64_t> shape = r.sizes().vec();
  shape.push_back(n);
  torch::Tensor A = torch::empty(shape, r.options()), b = torch::empty(r.sizes(), r.options());
  A.copy_(M.expand(shape));
  b.copy_(r);
  double *pa = A.data_ptr<double>(), *pb = b.data_ptr<double>();
  std::vector<int> perm(static_cast<std::size_t>(n));
  const int size = static_cast<int>(n);
  for (int64_t row = 0; row < b.numel() / n; ++row) {
    lu_factor(pa + row * n * n, perm.data(), size);
    lu_solve(pa + row * n * n, perm.data(), pb + row * n, size);
  }
  return b;
}

// The Newton update delta = -M^{-1} r of every row by Cramer's rule, with
// M = m (+ I when add_identity) [.., 2, 2] and r [.., 2]. The identity is
// added as 1 + m_ii, so callers passing -h J get I - h J to the bit.
// More than two states: lu_solve_rows.
torch::Tensor newton_update(const torch::Tensor& m, bool add_identity, const torch::Tensor& r) {
  const int64_t n = r.size(-1);
  if (n != 2) {
    const auto M = add_identity ? m + torch::eye(n, m.options()) : m;
    return -lu_solve_rows(M, r);
  }
  const double one = add_identity ? 1.0 : 0.0;
  const auto m00 = m.select(-2, 0).select(-1, 0), m11 = m.select(-2, 1).select(-1, 1);
  const auto a = add_identity ? one + m00 : m00, b = m.select(-2, 0).select(-1, 1);
  const auto c = m.select(-2, 1).select(-1, 0), d = add_identity ? one + m11 : m11;
  const auto r0 = r.select(-1, 0), r1 = r.select(-1, 1);
  const auto det = a * d - b * c;  // [a b; c d] delta = -r
  return torch::stack({(b * r1 - d * r0) / det, (c * r0 - a * r1) / det}, -1);
}

}  // namespace

DgInferenceStep dg_inference_step(const DynamicsModel& model, const torch::Tensor& x,
                                  const torch::Tensor& u, double h,
                                  const DgInferenceOptions& options, DgNewtonJacobian* cache) {
  PHNN_REQUIRE(model.is_port_hamiltonian(),
               "dg_inference_step: " << to_string(model.options().kind) << " has no Hamiltonian");
  auto dx = rk2_step(model, x, u, h) - x;
  DgInferenceStep out;
  const auto row_shape = std::vector<int64_t>{x.size(0), x.size(1)};
  auto converged = torch::zeros(row_shape, x.options().dtype(torch::kBool));
  // Simplified Newton, row by row: a row keeps its Jacobian (from the cache,
  // i.e. the previous step of the rollout, or from the first iteration)
  // while its residual shrinks at least 10x per iteration, and gets a fresh
  // one at its current iterate otherwise. Every decision is per row and the
  // residual always comes from discrete_gradient_field, so a row's result
  // does not depend on the other rows or members in the batch.
  const bool have_cache = cache && cache->dfddx.defined() && cache->dfddx.size(0) == x.size(0) &&
                          cache->dfddx.size(1) == x.size(1);
  torch::Tensor jacobian = have_cache ? cache->dfddx : torch::zeros({x.size(0), x.size(1), x.size(-1), x.size(-1)}, x.options());
  torch::Tensor previous_norm;
  for (int it = 0;; ++it) {
    // r(dx) = dx - h f_bar(x, dx, u);  r'(dx) = I - h d f_bar / d dx.
    const auto r = dx - h * model.discrete_gradient_field(x, dx, u, options.min_dx_norm);
    const auto norm = std::get<0>(r.abs().max(-1));
    converged = converged.logical_or(norm <= options.tolerance);
    if (it == options.max_iterations || converged.all().item<bool>()) break;
    // First iteration: every row without a cached Jacobian; then the rows
    // whose residual shrank less than 10x.
    const auto refresh = (previous_norm.defined()
                              ? norm > 0.1 * previous_norm
                              : torch::full(row_shape, !have_cache, converged.options())) &
                         converged.logical_not();
    if (refresh.any().item<bool>()) {
      const auto fresh = model.discrete_gradient_field_with_jacobian(x, dx, u, options.min_dx_norm).dfdx;
      jacobian = torch::where(refresh.unsqueeze(-1).unsqueeze(-1), fresh, jacobian);
      ++out.jacobian_evaluations;
    }
    previous_norm = norm;
    const auto delta = newton_update(-h * jacobian, /*add_identity=*/true, r);
    // Converged rows keep their solution.
    dx = dx + torch::where(converged.unsqueeze(-1), torch::zeros_like(delta), delta);
    out.iterations = it + 1;
  }
  if (cache) cache->dfddx = jacobian;
  out.x_next = x + dx;
  out.converged = converged;
  return out;
}

torch::Tensor dg4_training_step(const DynamicsModel& model, const torch::Tensor& x,
                                const torch::Tensor& x_next, const torch::Tensor& u, double h,
                                double min_dx_norm) {
  return x + h * model.discrete_gradient4_field(x, x_next - x, u, h, min_dx_norm).f;
}

namespace {

// d r / d dx of r(dx) = dx - h f4(x, dx, u) by forward differences, per row:
// step eta = 1e-7 max(|dx|_inf, 1e-8) (error ~ eta |r''|, i.e. a Newton
// contraction of ~1e-7 per iteration). Rows are perturbed independently,
// so a row's Jacobian depends on that row only. [E, B, 2 (r), 2 (dx)].
torch::Tensor dg4_residual_jacobian(const DynamicsModel& model, const torch::Tensor& x,
                                    const torch::Tensor& dx, const torch::Tensor& u, double h,
                                    double min_dx_norm, const torch::Tensor& r) {
  const auto eta = 1e-7 * torch::clamp_min(std::get<0>(dx.abs().max(-1, /*keepdim=*/true)), 1e-8);
  std::vector<torch::Tensor> columns;
  for (int64_t j = 0; j < dx.size(-1); ++j) {
    auto step = torch::zeros_like(dx);
    step.select(-1, j).copy_(eta.squeeze(-1));
    const auto moved = dx + step;
    const auto r_moved = moved - h * model.discrete_gradient4_field(x, moved, u, h, min_dx_norm).f;
    columns.push_back((r_moved - r) / (moved - dx).select(-1, j).unsqueeze(-1));
  }
  return torch::stack(columns, -1);
}

}  // namespace

DgInferenceStep dg4_inference_step(const DynamicsModel& model, const torch::Tensor& x,
                                   const torch::Tensor& u, double h,
                                   const DgInferenceOptions& options) {
  PHNN_REQUIRE(model.is_port_hamiltonian(),
               "dg4_inference_step: " << to_string(model.options().kind) << " has no Hamiltonian");
  auto dx = rk4_step(model, x, u, h) - x;
  DgInferenceStep out;
  const auto row_shape = std::vector<int64_t>{x.size(0), x.size(1)};
  auto converged = torch::zeros(row_shape, x.options().dtype(torch::kBool));
  auto full_newton = torch::zeros(row_shape, converged.options());
  torch::Tensor previous_norm;
  const auto eye = torch::eye(x.size(-1), x.options());
  for (int it = 0;; ++it) {
    const FieldEval f4 = model.discrete_gradient4_field(x, dx, u, h, options.min_dx_norm);
    const auto r = dx - h * f4.f;
    const auto norm = std::get<0>(r.abs().max(-1));
    converged = converged.logical_or(norm <= options.tolerance);
    if (it == options.max_iterations || converged.all().item<bool>()) break;
    // Simplified Newton (I - (h/2) A) while a row contracts 10x per
    // iteration; from its first slower iteration on, the row takes the
    // difference Jacobian (learned fields of strong curvature, where the
    // dropped O(h |dx| d3H) terms of the simple matrix matter).
    if (previous_norm.defined()) {
      full_newton = full_newton.logical_or(norm > 0.1 * previous_norm);
    }
    previous_norm = norm;
    auto jac = eye - (0.5 * h) * f4.dfdx;
    const auto need = full_newton & converged.logical_not();
    if (need.any().item<bool>()) {
      const auto exact = dg4_residual_jacobian(model, x, dx, u, h, options.min_dx_norm, r);
      jac = torch::where(need.unsqueeze(-1).unsqueeze(-1), exact, jac);
      ++out.jacobian_evaluations;
    }
    const auto delta = newton_update(jac, /*add_identity=*/false, r);
    dx = dx + torch::where(converged.unsqueeze(-1), torch::zeros_like(delta), delta);
    out.iterations = it + 1;
  }
  out.x_next = x + dx;
  out.converged = converged;
  return out;
}

}  // namespace phnn
