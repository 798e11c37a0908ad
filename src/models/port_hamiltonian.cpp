// src/models/port_hamiltonian.cpp — what PHNN-S and PHNN-JR share on top of
// their energy (PortHamiltonianModel): the field from gradH, the DG field
// and its Newton Jacobian, the AVF gradient and the DG4 field. H, gradH and
// the Hessian are the models' (general_ph.cpp).
#include "phnn/models/port_hamiltonian.h"

#include <cmath>
#include <utility>

#include "kernels/ordered_sum.h"
#include "phnn/common/check.h"

namespace phnn {

Jet gradient_jet(const Jet& h) {
  PHNN_CHECK(h.g.defined(), "gradient_jet needs an order >= 1 jet of H");
  Jet g;
  g.v = h.g.squeeze(-1);                      // [E, B, 2]
  if (h.h.defined()) g.g = h.h.squeeze(-1);  // [E, B, d, 2], symmetric
  return g;
}

torch::Tensor PortHamiltonianModel::grad_hamiltonian(const torch::Tensor& x) const {
  return energy_and_gradient(x).grad;
}

FieldEval PortHamiltonianModel::field(const torch::Tensor& x, const torch::Tensor& u,
                                      bool with_jacobian) const {
  FieldEval out;
  if (!with_jacobian) {
    Jet effort;
    effort.v = energy_and_gradient(x).grad;
    out.f = field_from_effort(effort, x, u, /*order=*/0, /*dissipation_fixed=*/false).v;
    return out;
  }
  const int order = 1;
  const Jet grad = curvature_jet(x);
  const Jet f = field_from_effort(grad, x, u, order, /*dissipation_fixed=*/false);
  out.f = f.v;
  if (with_jacobian) out.dfdx = f.g.transpose(-1, -2);
  return out;
}

torch::Tensor PortHamiltonianModel::discrete_gradient_field(const torch::Tensor& x,
                                                            const torch::Tensor& dx,
                                                            const torch::Tensor& u,
                                                            double min_dx_norm) const {
  Jet effort;
  effort.v = discrete_gradient(x, dx, min_dx_norm);
  // R_theta at x_n + dx/2 (default) or x_n (docs/METHOD.md §4, dg_structure_point).
  const auto x_dissipation = dissipation_at_start() ? x : x + 0.5 * dx;
  return field_from_effort(effort, x_dissipation, u, /*order=*/0, /*dissipation_fixed=*/false).v;
}

bool PortHamiltonianModel::dissipation_at_start() const {
  return options().kind == ModelKind::kPhnnJr &&
         options().dg_structure_point == DgStructurePoint::kStart;
}

// Jacobian of the DG field w.r.t. dx. With m = x + dx/2, g = gradH(m),
// Hm = Hessian of H at m, g1 = gradH(x + dx), n2 = |dx|^2,
// D = H(x + dx) - H(x) - g.dx and k = D / n2 (eq: gonzalez-discrete-gradient):
//   d dg / d dx = Hm / 2 + dx (dk/d dx)^T + k I,
//   dk / d dx   = (g1 - g - Hm dx / 2) / n2 - 2 k dx / n2,
// and d dg / d dx = Hm / 2 below the fallback threshold (dg = g). Everything
// else in f_bar depends on dx through m only (R(m, u), z(w(dg))), so the
// field is differentiated as a jet in the directions of m with the effort's
// tangent d dg / d m = 2 d dg / d dx, and d f_bar / d dx = (d f_bar / d m) / 2.
// With R at the start x_n only the effort moves: the jet's directions are dx
// itself, the effort's tangent is d dg / d dx and R's is zero.
FieldEval PortHamiltonianModel::discrete_gradient_field_with_jacobian(
    const torch::Tensor& x, const torch::Tensor& dx, const torch::Tensor& u,
    double min_dx_norm) const {
  const auto m = x + 0.5 * dx;
  const Jet grad_m = curvature_jet(m);  // v = g, g = Hm
  const auto hess = grad_m.g;                                                // [E, B, 2, 2]
  const auto h0 = hamiltonian(x).unsqueeze(-1);
  const auto end = energy_and_gradient(x + dx);
  const auto n2 = internal::ordered_sum(dx * dx, 1).unsqueeze(-1);                          // [E, B, 1]
  const auto small = n2 < min_dx_norm * min_dx_norm;
  const auto safe_n2 = torch::where(small, torch::ones_like(n2), n2);
  const auto k = torch::where(small, torch::zeros_like(n2),
                              (end.h - h0 - internal::ordered_sum(grad_m.v * dx, 1).unsqueeze(-1)) / safe_n2);
  const auto hess_dx = internal::ordered_matmul(hess, dx.unsqueeze(-1)).squeeze(-1);  // Hm dx
  const auto dk = torch::where(small, torch::zeros_like(dx),
                               (end.grad - grad_m.v - 0.5 * hess_dx) / safe_n2 - 2.0 * k * dx / safe_n2);
  const auto eye = torch::eye(x.size(-1), x.options());
  // J_dg[a][b] = d dg_a / d dx_b.
  const auto j_dg = 0.5 * hess + dx.unsqueeze(-1) * dk.unsqueeze(-2) + k.unsqueeze(-1) * eye;
  Jet effort;
  effort.v = grad_m.v + k * dx;
  FieldEval out;
  if (dissipation_at_start()) {
    effort.g = j_dg.transpose(-1, -2);  // [E, B, i (direction dx_i), a]
    const Jet f = field_from_effort(effort, x, u, /*order=*/1, /*dissipation_fixed=*/true);
    out.f = f.v;
    out.dfdx = f.g.transpose(-1, -2);  // [E, B, component, dx_i]
    return out;
  }
  effort.g = 2.0 * j_dg.transpose(-1, -2);  // [E, B, i (direction m_i), a]
  const Jet f = field_from_effort(effort, m, u, /*order=*/1, /*dissipation_fixed=*/false);
  out.f = f.v;
  out.dfdx = 0.5 * f.g.transpose(-1, -2);  // [E, B, component, dx_i]
  return out;
}

// ------------------------------------------------ fourth-order DG (DG4)
torch::Tensor PortHamiltonianModel::average_vector_field_gradient(const torch::Tensor& x,
                                                                  const torch::Tensor& dx,
                                                                  double min_dx_norm) const {
  // Gauss-Legendre on [0, 1]: nodes 1/2 -+ sqrt(15)/10, 1/2; weights 5/18, 8/18, 5/18.
  const double c = std::sqrt(15.0) / 10.0;
  const int64_t B = x.size(1);
  const auto points = torch::cat({x, x + dx, x + (0.5 - c) * dx, x + 0.5 * dx, x + (0.5 + c) * dx},
                                 /*dim=*/1);
  const HamiltonianAndGradient hg = energy_and_gradient(points);
  const auto g = (5.0 / 18.0) * hg.grad.narrow(1, 2 * B, B) +
                 (8.0 / 18.0) * hg.grad.narrow(1, 3 * B, B) +
                 (5.0 / 18.0) * hg.grad.narrow(1, 4 * B, B);
  const auto n2 = internal::ordered_sum(dx * dx, 1).unsqueeze(-1);
  const auto defect = hg.h.narrow(1, B, B) - hg.h.narrow(1, 0, B) - internal::ordered_sum(g * dx, 1).unsqueeze(-1);
  const auto small = n2 < min_dx_norm * min_dx_norm;
  const auto coef = torch::where(small, torch::zeros_like(defect),
                                 defect / torch::where(small, torch::ones_like(n2), n2));
  return g + coef * dx;
}

// (DG4) for a learned model, the same scheme as the true systems'
// (include/phnn/integrators/ph_steps.h) with F(m, e) the model's
// field from an effort e and its dissipation evaluated at m. One order-2 jet
// of phi(s) = F(m + s, e + Q s) in the two state directions s gives at once
//   phi(0)          = F(m, e) = v,
//   d phi / d s     = F_x + F_e Q = A           (f'(m) with effort e),
//   d2 phi[v, v]    = F_xx[v,v] + 2 F_xe[v, Qv] + F_ee[Qv, Qv],
// (e'' = 0: the H''' term cancels against the AVF effort), and
//   C = d2 phi[v, v] / 24 - A A v / 12,   f = v + h^2 C.
FieldEval PortHamiltonianModel::discrete_gradient4_field(const torch::Tensor& x,
                                                         const torch::Tensor& dx,
                                                         const torch::Tensor& u, double h,
                                                         double min_dx_norm) const {
  const auto m = x + 0.5 * dx;
  Jet effort;
  effort.v = average_vector_field_gradient(x, dx, min_dx_norm);
  effort.g = curvature_jet(m).g;  // Q [E, B, 2 (direction), 2]
  const int64_t n = x.size(-1);
  effort.h = torch::zeros({x.size(0), x.size(1), n, n, n}, x.options());
  const Jet phi = field_from_effort(effort, m, u, /*order=*/2, /*dissipation_fixed=*/false);
  const auto v = phi.v;                               // [E, B, 2]
  const auto A = phi.g.transpose(-1, -2);             // [E, B, component, direction]
  // Products and sums in one fixed order, backward included (ordered_sum.h).
  using internal::ordered_broadcast_mul;
  const auto vv = ordered_broadcast_mul(v.unsqueeze(-1), v.unsqueeze(-2));  // [E, B, i, j]
  const auto second =
      internal::ordered_sum(ordered_broadcast_mul(phi.h, vv.unsqueeze(-1)).movedim(-1, 2), 2);
  const auto Av = internal::ordered_sum(ordered_broadcast_mul(A, v.unsqueeze(-2)), 1);  // [E, B, n]
  const auto AAv = internal::ordered_sum(ordered_broadcast_mul(A, Av.unsqueeze(-2)), 1);
  FieldEval out;
  out.f = v + (h * h) * (second / 24.0 - AAv / 12.0);
  out.dfdx = A;
  return out;
}

}  // namespace phnn
