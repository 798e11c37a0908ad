// src/models/general_ph.cpp — the n-dimensional NODE, PHNN-S and PHNN-JR of
// include/phnn/models/general_ph.h: jets of matrix-vector products, the
// Cholesky-form Hamiltonian, and the two PH fields on a file's structure.
#include "phnn/models/general_ph.h"

#include <vector>

#include "models/general_heads.h"
#include "models/manual_step.h"
#include "kernels/ordered_sum.h"
#include "phnn/common/check.h"

namespace phnn {
namespace {

// Network streams: distinct initializations for the networks of one member
// (the values of the former 2-state models, so a member starts from the
// weights it always had).
constexpr std::uint64_t kStreamLH = 1, kStreamLR = 2, kStreamLz = 3, kStreamNode = 4;

torch::Tensor from_values(const std::vector<double>& v, int64_t rows, int64_t cols,
                          torch::ScalarType dtype) {
  return torch::tensor(v, torch::kFloat64).reshape({rows, cols}).to(dtype);
}

// Lower-triangle outputs (row-major: (0,0), (1,0), (1,1), (2,0), ...) placed
// into a row-major n x n matrix: into L (transpose = false) or L^T. With
// `diagonal` = +1 only the diagonal entries, -1 only the off-diagonal ones,
// 0 all of them.
torch::Tensor triangle_placement(int64_t n, int64_t outputs, bool transpose, int diagonal,
                                 torch::ScalarType dtype) {
  std::vector<double> p(static_cast<std::size_t>(outputs * n * n), 0.0);
  int64_t k = 0;
  for (int64_t r = 0; r < n; ++r) {
    for (int64_t c = 0; c <= r; ++c, ++k) {
      const bool on = diagonal == 0 || (diagonal > 0) == (r == c);
      if (on) p[static_cast<std::size_t>(k * n * n + (transpose ? c * n + r : r * n + c))] = 1.0;
    }
  }
  return from_values(p, outputs, n * n, dtype);
}

Jet jet_sum(const Jet& a) {
  Jet out;
  out.v = internal::ordered_sum(a.v, 1).unsqueeze(-1);  // fixed order (ordered_sum.h)
  if (a.g.defined()) out.g = internal::ordered_sum(a.g, 1).unsqueeze(-1);
  if (a.h.defined()) out.h = internal::ordered_sum(a.h, 1).unsqueeze(-1);
  return out;
}

int directions_of(const Jet& a) { return a.g.defined() ? static_cast<int>(a.g.size(-2)) : 0; }

// Member e of a stacked jet ([1, B, ...]) and the members put back together.
Jet member_of(const Jet& a, int64_t e) {
  Jet out;
  out.v = a.v.narrow(0, e, 1);
  if (a.g.defined()) out.g = a.g.narrow(0, e, 1);
  if (a.h.defined()) out.h = a.h.narrow(0, e, 1);
  return out;
}

// The algebra after the networks runs member by member: with all members
// in one tensor, the reductions autograd makes for broadcasts (and
// LibTorch's choice of reduction order) depend on the number of members,
// and a member's bits must not depend on its stackmates. The networks
// themselves are exact per member (stacked_matmul.cpp).
template <class F>
Jet per_member(int64_t members, F&& f) {
  if (members == 1) return f(0);
  std::vector<Jet> parts;
  for (int64_t e = 0; e < members; ++e) parts.push_back(f(e));
  Jet out;
  std::vector<torch::Tensor> v, g, h;
  for (const Jet& p : parts) {
    v.push_back(p.v);
    if (p.g.defined()) g.push_back(p.g);
    if (p.h.defined()) h.push_back(p.h);
  }
  out.v = torch::cat(v, 0);
  if (!g.empty()) out.g = torch::cat(g, 0);
  if (!h.empty()) out.h = torch::cat(h, 0);
  return out;
}

}  // namespace

Jet jet_linear(const Jet& a, const torch::Tensor& M) {
  Jet out;
  out.v = internal::ordered_matmul(a.v, M);
  if (a.g.defined()) out.g = internal::ordered_matmul(a.g, M);
  if (a.h.defined()) out.h = internal::ordered_matmul(a.h, M);
  return out;
}

Jet jet_narrow(const Jet& a, int64_t start, int64_t length) {
  Jet out;
  out.v = a.v.narrow(-1, start, length);
  if (a.g.defined()) out.g = a.g.narrow(-1, start, length);
  if (a.h.defined()) out.h = a.h.narrow(-1, start, length);
  return out;
}

// y = A b, row-major A (n x m):
//   y   = A b
//   y_i = A_i b + A b_i                                  (tangents)
//   y_ij = A_ij b + A_i b_j + A_j b_i + A b_ij           (Hessians)
Jet jet_matvec(const Jet& A, const Jet& b, int64_t n, int64_t m) {
  const int order = std::min(A.order(), b.order());
  const auto Av = A.v.unflatten(-1, {n, m});                      // [E, B, n, m]
  Jet out;
  out.v = internal::ordered_matmul(Av, b.v.unsqueeze(-1)).squeeze(-1);     // [E, B, n]
  if (order < 1) return out;
  const auto Ag = A.g.unflatten(-1, {n, m});                      // [E, B, d, n, m]
  const auto bv = b.v.unsqueeze(2).unsqueeze(-1);                 // [E, B, 1, m, 1]
  out.g = internal::ordered_matmul(Ag, bv).squeeze(-1) +
          internal::ordered_matmul(Av.unsqueeze(2), b.g.unsqueeze(-1)).squeeze(-1);  // [E, B, d, n]
  if (order < 2) return out;
  const auto Ah = A.h.unflatten(-1, {n, m});                      // [E, B, d, d, n, m]
  const auto cross = internal::ordered_matmul(Ag.unsqueeze(3), b.g.unsqueeze(2).unsqueeze(-1)).squeeze(-1);
  out.h = internal::ordered_matmul(Ah, bv.unsqueeze(2)).squeeze(-1) + cross + cross.transpose(2, 3) +
          internal::ordered_matmul(Av.unsqueeze(2).unsqueeze(2), b.h.unsqueeze(-1)).squeeze(-1);
  return out;
}

// H = 1/2 |L x|^2, L = lower(o) with softplus on the diagonal (Q = L^T L > 0).
Jet general_hamiltonian_jet(const StackedMlp& l_h, const torch::Tensor& x, int order) {
  const int64_t n = x.size(-1);
  const int64_t k = n * (n + 1) / 2;
  const auto dtype = x.scalar_type();
  const Jet X = Jet::input(x, static_cast<int>(n), order);
  const Jet o = order == 0 ? Jet{l_h.forward(x), {}, {}}
                           : l_h.forward_input(x, static_cast<int>(n), order);
  const auto off = triangle_placement(n, k, false, -1, dtype);
  const auto diag = triangle_placement(n, k, false, +1, dtype);
  return per_member(x.size(0), [&](int64_t e) {
    const Jet oe = member_of(o, e);
    const Jet L = jet_add(jet_linear(oe, off), jet_linear(jet_softplus(oe), diag));
    const Jet v = jet_matvec(L, member_of(X, e), n, n);
    return jet_scale(jet_sum(jet_mul(v, v)), 0.5);
  });
}

// ------------------------------------------------------- shared PH parts
PortHamiltonianModel::PortHamiltonianModel(ModelOptions options, int64_t members)
    : DynamicsModel(std::move(options), members) {
  PHNN_REQUIRE(this->options().general != nullptr,
               "PortHamiltonianModel: ModelOptions::general (the structure) is not set");
}

torch::Tensor PortHamiltonianModel::block_t(const std::vector<double>& matrix, int width,
                                                  int r0, int rows, int c0, int cols) const {
  std::vector<double> t(static_cast<std::size_t>(rows * cols));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      t[static_cast<std::size_t>(c * rows + r)] =
          matrix[static_cast<std::size_t>((r0 + r) * width + c0 + c)];
    }
  }
  return from_values(t, cols, rows, options().dtype);
}

// With fused networks, H and gradH come from the fused head (general_heads.h):
// without a graph in reverse mode, with one on the network's order-1 jet;
// otherwise from the op-by-op jet (the reference the tests compare the
// heads with).
torch::Tensor PortHamiltonianModel::hamiltonian(const torch::Tensor& x) const {
  if (l_h().options().fused) {
    return internal::general_hamiltonian_head(l_h().forward(x), {}, x).h.squeeze(-1);
  }
  return general_hamiltonian_jet(l_h(), x, 0).v.squeeze(-1);
}

HamiltonianAndGradient PortHamiltonianModel::energy_and_gradient(
    const torch::Tensor& x) const {
  if (l_h().options().fused && !torch::GradMode::is_enabled()) {
    // No graph to keep (rollouts): gradH in reverse mode through the
    // hand-written steps' own TapedGradient, two passes through L_H for any n_x.
    const internal::manual::TapedGradient g(l_h(), x);
    return {g.h, g.grad};
  }
  if (l_h().options().fused) {
    const Jet o = l_h().forward_input(x, static_cast<int>(x.size(-1)), /*order=*/1);
    const auto head = internal::general_hamiltonian_head(o.v, o.g, x);
    return {head.h, head.grad};
  }
  const Jet H = general_hamiltonian_jet(l_h(), x, 1);
  return {H.v, H.g.squeeze(-1)};
}

Jet PortHamiltonianModel::curvature_jet(const torch::Tensor& x) const {
  return gradient_jet(general_hamiltonian_jet(l_h(), x, 2));
}

// dg = gradH(x + dx/2) + (H(x + dx) - H(x) - gradH(x + dx/2)^T dx) / |dx|^2 dx
// (= gradH(x + dx/2) below min_dx_norm), one network call for the three points.
torch::Tensor PortHamiltonianModel::discrete_gradient(const torch::Tensor& x,
                                                             const torch::Tensor& dx,
                                                             double min_dx_norm) const {
  const int64_t B = x.size(1);
  if (l_h().options().fused) {
    // H at the ends needs no derivative: one order-0 call for both.
    const auto ends = torch::cat({x, x + dx}, /*dim=*/1);
    const auto h_ends = internal::general_hamiltonian_head(l_h().forward(ends), {}, ends).h;
    const auto grad_mid = energy_and_gradient(x + 0.5 * dx).grad;
    return internal::general_gonzalez_head(h_ends.narrow(1, 0, B), h_ends.narrow(1, B, B),
                                           grad_mid, dx, min_dx_norm);
  }
  const auto points = torch::cat({x, x + dx, x + 0.5 * dx}, /*dim=*/1);
  const HamiltonianAndGradient h = energy_and_gradient(points);
  const auto grad_mid = h.grad.narrow(1, 2 * B, B);
  const auto n2 = internal::ordered_sum(dx * dx, 1).unsqueeze(-1);
  const auto defect =
      h.h.narrow(1, B, B) - h.h.narrow(1, 0, B) - internal::ordered_sum(grad_mid * dx, 1).unsqueeze(-1);
  const auto small = n2 < min_dx_norm * min_dx_norm;
  const auto coef = torch::where(small, torch::zeros_like(defect),
                                 defect / torch::where(small, torch::ones_like(n2), n2));
  return grad_mid + coef * dx;
}

// ---------------------------------------------------------------- PHNN-S
PhnnS::PhnnS(ModelOptions options, const std::vector<std::uint64_t>& seeds)
    : PortHamiltonianModel(std::move(options), static_cast<int64_t>(seeds.size())) {
  const ModelOptions& o = this->options();
  const ModelStructure& s = structure();
  PHNN_REQUIRE(o.kind == ModelKind::kPhnnS, "PhnnS: options.kind must be phnn-s");
  const int nx = s.n_x, nw = s.n_w, nu = s.n_u, width = nx + nw + nu;
  const NetworkWidths widths = network_widths(o.size);
  nets_.push_back(std::make_unique<StackedMlp>(
      StackedMlpOptions{nx, widths.l_h, nx * (nx + 1) / 2, o.fused_networks, o.dtype}, seeds,
      kStreamLH));
  const int tri = nw * (nw + 1) / 2, skew = nw * (nw - 1) / 2;
  if (nw > 0) {
    nets_.push_back(std::make_unique<StackedMlp>(
        StackedMlpOptions{nw, widths.l_z, tri + skew, o.fused_networks, o.dtype}, seeds, kStreamLz));
  }
  // w = [e, u] [S_wx S_wu]^T;  f = [e, z, u] S_x^T;  y likewise (unused here).
  std::vector<double> w_rows;  // S_w without its z columns: [S_wx S_wu]
  for (int r = nx; r < nx + nw; ++r) {
    for (int c = 0; c < width; ++c) {
      if (c < nx || c >= nx + nw) w_rows.push_back(s.S[static_cast<std::size_t>(r * width + c)]);
    }
  }
  s_w_ = block_t(w_rows, nx + nu, 0, nw, 0, nx + nu);
  s_w_rows_ = w_rows;
  s_x_rows_.assign(s.S.begin(), s.S.begin() + nx * width);  // [S_xx S_xw S_xu]
  s_x_ = block_t(s.S, width, 0, nx, 0, width);
  const int64_t total = tri + skew;
  if (nw > 0) {
    place_l_ = torch::cat({triangle_placement(nw, tri, false, 0, o.dtype),
                           torch::zeros({skew, nw * nw}, o.dtype)});
    place_lt_ = torch::cat({triangle_placement(nw, tri, true, 0, o.dtype),
                            torch::zeros({skew, nw * nw}, o.dtype)});
    // K strictly lower from the last outputs: A = K - K^T.
    std::vector<double> a(static_cast<std::size_t>(total * nw * nw), 0.0);
    int64_t k = tri;
    for (int r = 0; r < nw; ++r) {
      for (int c = 0; c < r; ++c, ++k) {
        a[static_cast<std::size_t>(k * nw * nw + r * nw + c)] = 1.0;
        a[static_cast<std::size_t>(k * nw * nw + c * nw + r)] = -1.0;
      }
    }
    place_skew_ = from_values(a, total, nw * nw, o.dtype);
  }
}

Jet PhnnS::field_from_effort(const Jet& effort, const torch::Tensor& /*x_dissipation*/,
                                    const torch::Tensor& u, int order,
                                    bool /*dissipation_fixed*/) const {
  const ModelStructure& s = structure();
  if (order == 0 && l_h().options().fused) {
    // Fused heads: w = [S_wx S_wu] [e; u], then f = S_x [e; z(w); u]
    // (with no ports S_x is [S_xx S_xu]).
    if (s.n_w == 0) return Jet{internal::general_linear_head(effort.v, u, s_x_rows_, s.n_x), {}, {}};
    const auto w = internal::general_linear_head(effort.v, u, s_w_rows_, s.n_w);
    return Jet{internal::general_s_field_head(effort.v, u, nets_[1]->forward(w), w, s.S, s.n_w),
               {}, {}};
  }
  const int d = directions_of(effort);
  const Jet U = Jet::constant(u, d, order);
  const int64_t E = effort.v.size(0);
  if (s.n_w == 0) {
    return per_member(E, [&](int64_t e) {
      return jet_linear(Jet::cat({member_of(effort, e), member_of(U, e)}), s_x_);
    });
  }
  const Jet w = per_member(E, [&](int64_t e) {
    return jet_linear(Jet::cat({member_of(effort, e), member_of(U, e)}), s_w_);
  });
  const Jet o = order == 0 ? Jet{nets_[1]->forward(w.v), {}, {}} : nets_[1]->forward(w);
  return per_member(E, [&](int64_t e) {
    // z = L^T (L w) + (K - K^T) w.
    const Jet oe = member_of(o, e), we = member_of(w, e);
    Jet z = jet_matvec(jet_linear(oe, place_lt_),
                       jet_matvec(jet_linear(oe, place_l_), we, s.n_w, s.n_w), s.n_w, s.n_w);
    if (s.n_w > 1) z = jet_add(z, jet_matvec(jet_linear(oe, place_skew_), we, s.n_w, s.n_w));
    return jet_linear(Jet::cat({member_of(effort, e), z, member_of(U, e)}), s_x_);
  });
}

// --------------------------------------------------------------- PHNN-JR
PhnnJr::PhnnJr(ModelOptions options, const std::vector<std::uint64_t>& seeds)
    : PortHamiltonianModel(std::move(options), static_cast<int64_t>(seeds.size())) {
  const ModelOptions& o = this->options();
  const ModelStructure& s = structure();
  PHNN_REQUIRE(o.kind == ModelKind::kPhnnJr, "PhnnJr: options.kind must be phnn-jr");
  const int nx = s.n_x, m = s.n_x + s.n_u;
  const NetworkWidths widths = network_widths(o.size);
  nets_.push_back(std::make_unique<StackedMlp>(
      StackedMlpOptions{nx, widths.l_h, nx * (nx + 1) / 2, o.fused_networks, o.dtype}, seeds,
      kStreamLH));
  nets_.push_back(std::make_unique<StackedMlp>(
      StackedMlpOptions{m, widths.l_r, m * (m + 1) / 2, o.fused_networks, o.dtype}, seeds,
      kStreamLR));
  j_t_ = block_t(s.J, m, 0, m, 0, m);
  place_l_ = triangle_placement(m, m * (m + 1) / 2, false, 0, o.dtype);
  place_lt_ = triangle_placement(m, m * (m + 1) / 2, true, 0, o.dtype);
}

torch::Tensor PhnnJr::dissipation_matrix(const torch::Tensor& x,
                                                const torch::Tensor& u) const {
  const int64_t m = structure().n_x + structure().n_u;
  const auto o = nets_[1]->forward(torch::cat({x, u}, -1));  // [E, B, m (m + 1) / 2]
  auto L = torch::zeros({x.size(0), x.size(1), m, m}, x.options());
  int64_t k = 0;
  for (int64_t r = 0; r < m; ++r)
    for (int64_t c = 0; c <= r; ++c) L.select(-2, r).select(-1, c).copy_(o.select(-1, k++));
  return internal::ordered_matmul(L.transpose(-1, -2), L);
}

Jet PhnnJr::field_from_effort(const Jet& effort, const torch::Tensor& x_dissipation,
                                     const torch::Tensor& u, int order,
                                     bool dissipation_fixed) const {
  const ModelStructure& s = structure();
  const int64_t m = s.n_x + s.n_u;
  if (order == 0 && l_h().options().fused) {
    const auto o = nets_[1]->forward(torch::cat({x_dissipation, u}, -1));
    return Jet{internal::general_jr_field_head(effort.v, u, o, s.J), {}, {}};
  }
  const int d = directions_of(effort);
  const Jet U = Jet::constant(u, d, order);
  const Jet eu = Jet::cat({effort, U});
  // L_R(x, u): its jet moves with the state directions unless fixed (R at x_n).
  const auto input = torch::cat({x_dissipation, u}, -1);
  const Jet o = order == 0           ? Jet{nets_[1]->forward(input), {}, {}}
                : dissipation_fixed ? Jet::constant(nets_[1]->forward(input), d, order)
                                    : nets_[1]->forward_input(input, d, order);
  return per_member(eu.v.size(0), [&](int64_t e) {
    const Jet oe = member_of(o, e), eue = member_of(eu, e);
    const Jet re = jet_matvec(jet_linear(oe, place_lt_),
                              jet_matvec(jet_linear(oe, place_l_), eue, m, m), m, m);
    return jet_narrow(jet_sub(jet_linear(eue, j_t_), re), 0, s.n_x);
  });
}

// ------------------------------------------------------------------ NODE
Node::Node(ModelOptions options, const std::vector<std::uint64_t>& seeds)
    : DynamicsModel(options, static_cast<int64_t>(seeds.size())) {
  PHNN_REQUIRE(options.kind == ModelKind::kNode, "Node: options.kind must be node");
  PHNN_REQUIRE(options.general != nullptr, "Node: ModelOptions::general is not set");
  const ModelStructure& s = *options.general;
  nets_.push_back(std::make_unique<StackedMlp>(
      StackedMlpOptions{s.n_x + s.n_u, network_widths(options.size).node, s.n_x,
                        options.fused_networks, options.dtype},
      seeds, kStreamNode));
}

FieldEval Node::field(const torch::Tensor& x, const torch::Tensor& u,
                             bool with_jacobian) const {
  FieldEval out;
  const auto input = torch::cat({x, u}, -1);
  if (!with_jacobian) {
    out.f = nets_[0]->forward(input);
    return out;
  }
  const Jet f = nets_[0]->forward_input(input, static_cast<int>(x.size(-1)), /*order=*/1);
  out.f = f.v;
  out.dfdx = f.g.transpose(-1, -2);
  return out;
}

}  // namespace phnn
