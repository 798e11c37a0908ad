// src/models/port_hamiltonian.cpp — the 2-state PHNN-S and PHNN-JR (fused heads) and the
// virtual hooks the n-dimensional models override.
// Size: both formulations share the energy, curvature and discrete-gradient paths.
#include "phnn/models/port_hamiltonian.h"

#include <cmath>
#include <utility>

#include "models/fused_heads.h"
#include "models/general_heads.h"
#include "models/ordered_sum.h"
#include "models/pinned_activations.h"
#include "phnn/common/check.h"

namespace phnn {
namespace {

// Network streams: distinct initializations for the networks of one member.
constexpr std::uint64_t kStreamLH = 1, kStreamLR = 2, kStreamLz = 3, kStreamNode = 4;

// sum_k c_k a_k over the non-zero coefficients (the structure matrices are
// sparse {-1, 0, 1}).
Jet lincomb(const std::vector<std::pair<double, const Jet*>>& terms, const Jet& zero_like) {
  Jet out;
  bool first = true;
  for (const auto& [c, jet] : terms) {
    if (c == 0.0) continue;
    const Jet term = c == 1.0 ? *jet : jet_scale(*jet, c);
    out = first ? term : jet_add(out, term);
    first = false;
  }
  return first ? jet_scale(zero_like, 0.0) : out;
}

}  // namespace

Jet hamiltonian_jet(const StackedMlp& l_h, const torch::Tensor& x, int order) {
  const Jet X = Jet::input(x, /*directions=*/2, order);
  const Jet o = l_h.forward_input(x, /*directions=*/2, order);
  const Jet l00 = jet_softplus(o.component(0));
  const Jet l10 = o.component(1);
  const Jet l11 = jet_softplus(o.component(2));
  const Jet x0 = X.component(0), x1 = X.component(1);
  // v = L_H x, H = |v|^2 / 2.
  const Jet v0 = jet_mul(l00, x0);
  const Jet v1 = jet_add(jet_mul(l10, x0), jet_mul(l11, x1));
  return jet_scale(jet_add(jet_mul(v0, v0), jet_mul(v1, v1)), 0.5);
}

Jet gradient_jet(const Jet& h) {
  PHNN_CHECK(h.g.defined(), "gradient_jet needs an order >= 1 jet of H");
  Jet g;
  g.v = h.g.squeeze(-1);                      // [E, B, 2]
  if (h.h.defined()) g.g = h.h.squeeze(-1);  // [E, B, d, 2], symmetric
  return g;
}

HamiltonianAndGradient hamiltonian_and_gradient(const StackedMlp& l_h, const torch::Tensor& x) {
  const Jet o = l_h.forward_input(x, /*directions=*/2, /*order=*/1);
  if (l_h.options().fused) {
    const auto head = internal::hamiltonian_head(o.v, o.g, x);
    return {head.h, head.grad};
  }
  const auto q = x.narrow(-1, 0, 1), p = x.narrow(-1, 1, 1);
  const auto o0 = o.v.narrow(-1, 0, 1), l10 = o.v.narrow(-1, 1, 1), o2 = o.v.narrow(-1, 2, 1);
  const auto l00 = internal::pinned_softplus(o0), l11 = internal::pinned_softplus(o2);
  const auto v0 = l00 * q, v1 = l10 * q + l11 * p;
  HamiltonianAndGradient out;
  out.h = 0.5 * (v0 * v0 + v1 * v1);
  // L^T v = (l00 v0 + l10 v1, l11 v1).
  const auto lt_v = torch::cat({l00 * v0 + l10 * v1, l11 * v1}, -1);
  const auto c = torch::cat({v0 * internal::pinned_sigmoid(o0) * q, v1 * q, v1 * internal::pinned_sigmoid(o2) * p}, -1);
  // (do/dx) c: o.g is [E, B, 2 (directions), 3 (outputs)].
  out.grad = lt_v + internal::ordered_sum(o.g * c.unsqueeze(-2), 1);
  return out;
}

torch::Tensor PortHamiltonianModel::hamiltonian(const torch::Tensor& x) const {
  if (l_h().options().fused) {
    return internal::hamiltonian_head(l_h().forward(x), {}, x).h.squeeze(-1);
  }
  return hamiltonian_jet(l_h(), x, 0).v.squeeze(-1);
}

torch::Tensor PortHamiltonianModel::grad_hamiltonian(const torch::Tensor& x) const {
  return energy_and_gradient(x).grad;
}

HamiltonianAndGradient PortHamiltonianModel::energy_and_gradient(const torch::Tensor& x) const {
  return hamiltonian_and_gradient(l_h(), x);
}

Jet PortHamiltonianModel::curvature_jet(const torch::Tensor& x) const {
  if (!l_h().options().fused) return gradient_jet(hamiltonian_jet(l_h(), x, /*order=*/2));
  // Closed-form gradH and Hessian from L_H's order-2 jet (one fused head).
  const Jet o = l_h().forward_input(x, /*directions=*/2, /*order=*/2);
  const auto curvature = internal::hamiltonian_curvature_head(o.v, o.g, o.h, x);
  return Jet{curvature.grad, curvature.hessian, {}};
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

torch::Tensor PortHamiltonianModel::discrete_gradient(const torch::Tensor& x,
                                                      const torch::Tensor& dx,
                                                      double min_dx_norm) const {
  const int64_t B = x.size(1);
  if (l_h().options().fused) {
    // H at x and x + dx needs no derivative: one order-0 network call for
    // both, one order-1 call at the midpoint.
    const auto ends = torch::cat({x, x + dx}, /*dim=*/1);
    const auto h_ends = internal::hamiltonian_head(l_h().forward(ends), {}, ends).h;
    const auto grad_mid = hamiltonian_and_gradient(l_h(), x + 0.5 * dx).grad;
    // The n-state Gonzalez head: for n = 2 the same operations in the same
    // order as the former 2-state one (bitwise; PaperPathTest).
    return internal::general_gonzalez_head(h_ends.narrow(1, 0, B), h_ends.narrow(1, B, B), grad_mid,
                                           dx, min_dx_norm);
  }
  // One network call for H(x), H(x + dx) and gradH(x + dx/2).
  const auto points = torch::cat({x, x + dx, x + 0.5 * dx}, /*dim=*/1);
  const HamiltonianAndGradient h = energy_and_gradient(points);
  const auto h_x = h.h.narrow(1, 0, B);
  const auto h_xdx = h.h.narrow(1, B, B);
  const auto grad_mid = h.grad.narrow(1, 2 * B, B);  // [E, B, 2]
  const auto n2 = internal::ordered_sum(dx * dx, 1).unsqueeze(-1);
  const auto defect = h_xdx - h_x - internal::ordered_sum(grad_mid * dx, 1).unsqueeze(-1);
  const auto small = n2 < min_dx_norm * min_dx_norm;
  const auto coef = torch::where(small, torch::zeros_like(defect),
                                 defect / torch::where(small, torch::ones_like(n2), n2));
  return grad_mid + coef * dx;
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

namespace {
// The L_H network shared by both formulations, then the dissipation network.
void add_networks(std::vector<std::unique_ptr<StackedMlp>>* nets, const ModelOptions& options,
                  const std::vector<std::uint64_t>& seeds, int dissipation_in,
                  const std::vector<int>& dissipation_hidden, int dissipation_out,
                  std::uint64_t dissipation_stream) {
  nets->push_back(std::make_unique<StackedMlp>(
      StackedMlpOptions{2, network_widths(options.size).l_h, 3, options.fused_networks,
                        options.dtype}, seeds, kStreamLH));
  nets->push_back(std::make_unique<StackedMlp>(
      StackedMlpOptions{dissipation_in, dissipation_hidden, dissipation_out,
                        options.fused_networks, options.dtype}, seeds,
      dissipation_stream));
}
}  // namespace

// ---------------------------------------------------------------- PHNN-S
PhnnS::PhnnS(ModelOptions options, const std::vector<std::uint64_t>& seeds)
    : PortHamiltonianModel(options, static_cast<int64_t>(seeds.size())) {
  PHNN_REQUIRE(options.kind == ModelKind::kPhnnS, "PhnnS: options.kind must be phnn-s");
  add_networks(&nets_, options, seeds, 1, network_widths(options.size).l_z, 1, kStreamLz);
  const Oscillator structure(OscillatorOptions::defaults(options.structure));
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) S_[r][c] = structure.S()(r, c);
}

Jet PhnnS::field_from_effort(const Jet& effort, const torch::Tensor& /*x_dissipation*/,
                             const torch::Tensor& u, int order,
                             bool /*dissipation_fixed*/) const {
  if (order == 0 && nets_[1]->options().fused) {
    const auto w = internal::phnn_s_w_head(effort.v, u, {S_[2][0], S_[2][1], S_[2][3]});
    return Jet{internal::phnn_s_field_head(effort.v, u, nets_[1]->forward(w), w, S_), {}, {}};
  }
  const Jet eq = effort.component(0), ep = effort.component(1);
  const Jet U = Jet::constant(u, /*directions=*/2, order);
  // w = S_wx e + S_wu u (S_ww = 0 for the three systems).
  const Jet w = lincomb({{S_[2][0], &eq}, {S_[2][1], &ep}, {S_[2][3], &U}}, U);
  // z(w) = Gamma(w) w, Gamma = L_z^T L_z >= 0 (eq:physical_constraints_Gamma).
  const Jet l = nets_[1]->forward(w);
  const Jet z = jet_mul(jet_mul(l, l), w);
  const Jet f0 = lincomb({{S_[0][0], &eq}, {S_[0][1], &ep}, {S_[0][2], &z}, {S_[0][3], &U}}, U);
  const Jet f1 = lincomb({{S_[1][0], &eq}, {S_[1][1], &ep}, {S_[1][2], &z}, {S_[1][3], &U}}, U);
  return Jet::cat({f0, f1});
}

// --------------------------------------------------------------- PHNN-JR
PhnnJr::PhnnJr(ModelOptions options, const std::vector<std::uint64_t>& seeds)
    : PortHamiltonianModel(options, static_cast<int64_t>(seeds.size())) {
  PHNN_REQUIRE(options.kind == ModelKind::kPhnnJr, "PhnnJr: options.kind must be phnn-jr");
  add_networks(&nets_, options, seeds, 3, network_widths(options.size).l_r, 6, kStreamLR);
  const Oscillator structure(OscillatorOptions::defaults(options.structure));
  const Eigen::Matrix3d J = structure.J();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) J_[r][c] = J(r, c);
  // Entries 0, +-1: exact in either dtype.
  j_matrix_ = torch::zeros({3, 3}, options.dtype);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) j_matrix_[r][c] = J_[r][c];
  // Output k of L_R goes to row-major lower-triangle entry (row, col).
  placement_ = torch::zeros({6, 9}, options.dtype);
  int k = 0;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col <= row; ++col) placement_[k++][3 * row + col] = 1.0;
}

torch::Tensor PhnnJr::dissipation_matrix(const torch::Tensor& x, const torch::Tensor& u) const {
  const auto o = nets_[1]->forward(torch::cat({x, u}, -1));  // [E, B, 6]
  auto L = torch::zeros({x.size(0), x.size(1), 3, 3}, x.options());
  int idx = 0;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j <= k; ++j) L.select(-2, k).select(-1, j).copy_(o.select(-1, idx++));
  return internal::ordered_matmul(L.transpose(-1, -2), L);
}

Jet PhnnJr::field_from_effort(const Jet& effort, const torch::Tensor& x_dissipation,
                              const torch::Tensor& u, int order, bool dissipation_fixed) const {
  if (order == 0 && nets_[1]->options().fused) {
    const auto o = nets_[1]->forward(torch::cat({x_dissipation, u}, -1));  // [E, B, 6]
    return Jet{internal::jr_field_head(effort.v, o, u, J_), {}, {}};
  }
  if (order == 0) {
    // Matrix form: L_R from its 6 outputs by one placement matmul, then
    // f = [J e - L^T (L e)]_{1:2} with e = (gradH, u).
    const auto o = nets_[1]->forward(torch::cat({x_dissipation, u}, -1));  // [E, B, 6]
    const auto L = internal::ordered_matmul(o, placement_).unflatten(-1, {3, 3});    // [E, B, 3, 3]
    const auto e = torch::cat({effort.v, u}, -1).unsqueeze(-1);            // [E, B, 3, 1]
    const auto re = internal::ordered_matmul(L.transpose(-1, -2), internal::ordered_matmul(L, e));
    const auto je = internal::ordered_matmul(j_matrix_, e);
    return Jet{(je - re).squeeze(-1).narrow(-1, 0, 2), {}, {}};
  }
  // L_R(x, u): lower triangular 3 x 3 from 6 outputs, row by row (constant
  // along the jet's directions when the dissipation is fixed).
  const auto input = torch::cat({x_dissipation, u}, -1);
  const Jet o = dissipation_fixed ? Jet::constant(nets_[1]->forward(input), 2, order)
                                  : nets_[1]->forward_input(input, 2, order);
  if (order == 1 && nets_[1]->options().fused && effort.g.defined()) {
    const auto jet = internal::jr_field_jet_head(effort.v, effort.g, o.v, o.g, u, J_);
    return Jet{jet.f, jet.g, {}};
  }
  Jet L[3][3];
  int idx = 0;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j <= k; ++j) L[k][j] = o.component(idx++);
  const Jet U = Jet::constant(u, 2, order);
  const Jet e[3] = {effort.component(0), effort.component(1), U};
  // v = L_R e;  R e = L_R^T v.
  Jet v[3];
  for (int k = 0; k < 3; ++k) {
    v[k] = jet_mul(L[k][0], e[0]);
    for (int j = 1; j <= k; ++j) v[k] = jet_add(v[k], jet_mul(L[k][j], e[j]));
  }
  Jet f[2];
  for (int i = 0; i < 2; ++i) {
    Jet re = jet_mul(L[i][i], v[i]);
    for (int k = i + 1; k < 3; ++k) re = jet_add(re, jet_mul(L[k][i], v[k]));
    const Jet je = lincomb({{J_[i][0], &e[0]}, {J_[i][1], &e[1]}, {J_[i][2], &e[2]}}, U);
    f[i] = jet_sub(je, re);
  }
  return Jet::cat({f[0], f[1]});
}

// ------------------------------------------------------------------ NODE
Node::Node(ModelOptions options, const std::vector<std::uint64_t>& seeds)
    : DynamicsModel(options, static_cast<int64_t>(seeds.size())) {
  PHNN_REQUIRE(options.kind == ModelKind::kNode, "Node: options.kind must be node");
  nets_.push_back(std::make_unique<StackedMlp>(
      StackedMlpOptions{3, network_widths(options.size).node, 2, options.fused_networks,
                        options.dtype}, seeds, kStreamNode));
}

FieldEval Node::field(const torch::Tensor& x, const torch::Tensor& u, bool with_jacobian) const {
  FieldEval out;
  const auto input = torch::cat({x, u}, -1);
  if (!with_jacobian) {
    out.f = nets_[0]->forward(input);
    return out;
  }
  const Jet f = nets_[0]->forward_input(input, /*directions=*/2, /*order=*/1);
  out.f = f.v;
  out.dfdx = f.g.transpose(-1, -2);
  return out;
}

}  // namespace phnn

namespace phnn {

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
// (include/phnn/integrators/discrete_gradient4.h) with F(m, e) the model's
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
