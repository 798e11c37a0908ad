// include/phnn/models/general_ph.h — NODE, PHNN-S and PHNN-JR for any n_x
// states, n_w dissipation ports and n_u inputs (paper §4 in its general
// form; docs/METHOD.md "n-dimensional models"), on the known structure of a
// system: a file's, or a built-in oscillator's (builtin_structure); the one
// model family of every system. Built from stacked MLPs and forward-mode
// jets with the matrix algebra written for any size. With fused networks,
// the order-0 and order-1 parts (H, gradH, the DG, the fields) run through
// fused heads with hand-written backwards (src/models/general_heads.h), and
// training through the hand-written steps of general_manual_step.cpp; jets
// of order 2 run op by op.
#pragma once

#include "phnn/models/port_hamiltonian.h"

namespace phnn {

/// Jet algebra for matrices stored row-major in a jet's components.
/// y = A b for A [.., n * m] (row-major n x m) and b [.., m]: the product
/// rule on value, tangents and Hessians.
Jet jet_matvec(const Jet& A, const Jet& b, int64_t n, int64_t m);
/// y = a M for a constant matrix M [n_in, n_out]: linear in the jet.
Jet jet_linear(const Jet& a, const torch::Tensor& M);
/// Components [start, start + length).
Jet jet_narrow(const Jet& a, int64_t start, int64_t length);

/// H_theta(x) = 1/2 |L(x) x|^2 with L lower triangular n x n from the
/// n (n + 1) / 2 outputs of L_H (row-major lower triangle; softplus on the
/// diagonal), as a jet in the n state directions up to `order`.
Jet general_hamiltonian_jet(const StackedMlp& l_h, const torch::Tensor& x, int order);

/// PHNN-S (eq:f_theta-PHS-DAF) for n_w ports:
///   w = S_wx gradH + S_wu u,
///   z_theta(w) = (L_z(w)^T L_z(w) + K(w) - K(w)^T) w,
///   f = S_xx gradH + S_xw z_theta(w) + S_xu u,
/// one network n_w -> n_w (n_w + 1) / 2 (L_z, lower triangle) + n_w (n_w - 1) / 2
/// (K, strictly lower); for n_w = 1 a 1 -> 1 network and K is empty.
class PhnnS : public PortHamiltonianModel {
 public:
  PhnnS(ModelOptions options, const std::vector<std::uint64_t>& seeds);
  /// Hand-written steps (src/models/general_manual_step.cpp), equal to
  /// autograd's loss and gradients to round-off (gradH in reverse mode).
  torch::Tensor explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, const JacobianPenalty& penalty) const override;
  torch::Tensor dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                const torch::Tensor& u, double h, double min_dx_norm,
                                const JacobianPenalty& penalty) const override;
  torch::Tensor dg4_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                 const torch::Tensor& u, double h, double min_dx_norm,
                                 const JacobianPenalty& penalty) const override;

 protected:
  Jet field_from_effort(const Jet& effort, const torch::Tensor& x_dissipation,
                        const torch::Tensor& u, int order, bool dissipation_fixed) const override;

 private:
  torch::Tensor s_w_, s_x_, s_y_;  // jet_linear factors, see the constructor
  std::vector<double> s_w_rows_;   // [S_wx S_wu] row-major (the fused head's)
  std::vector<double> s_x_rows_;   // the first n_x rows of S (no ports: [S_xx S_xu])
  torch::Tensor place_l_, place_lt_, place_skew_;  // L_z outputs -> L, L^T, K - K^T
};

/// PHNN-JR (eq:f_theta-PHS-JR): f = [(J - R_theta(x, u)) [gradH; u]]_{1:n_x},
/// R = L_R^T L_R, L_R lower triangular m x m (m = n_x + n_u) from an
/// m -> m (m + 1) / 2 network of (x, u).
class PhnnJr : public PortHamiltonianModel {
 public:
  PhnnJr(ModelOptions options, const std::vector<std::uint64_t>& seeds);
  /// R_theta(x, u) = L^T L [E, B, m, m], m = n_x + n_u (for tests: symmetric PSD).
  torch::Tensor dissipation_matrix(const torch::Tensor& x, const torch::Tensor& u) const;
  /// Hand-written steps, as PhnnS's.
  torch::Tensor explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, const JacobianPenalty& penalty) const override;
  torch::Tensor dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                const torch::Tensor& u, double h, double min_dx_norm,
                                const JacobianPenalty& penalty) const override;
  torch::Tensor dg4_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                 const torch::Tensor& u, double h, double min_dx_norm,
                                 const JacobianPenalty& penalty) const override;

 protected:
  Jet field_from_effort(const Jet& effort, const torch::Tensor& x_dissipation,
                        const torch::Tensor& u, int order, bool dissipation_fixed) const override;

 private:
  torch::Tensor j_t_;                 // J^T [m, m]
  torch::Tensor place_l_, place_lt_;  // L_R outputs -> L, L^T
};

/// NODE (eq: neural-ode): f = MLP([x; u]), n_x + n_u -> n_x.
class Node : public DynamicsModel {
 public:
  Node(ModelOptions options, const std::vector<std::uint64_t>& seeds);
  FieldEval field(const torch::Tensor& x, const torch::Tensor& u,
                  bool with_jacobian) const override;
  /// Hand-written RK2 step, with or without a penalty.
  torch::Tensor explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, const JacobianPenalty& penalty) const override;
};

}  // namespace phnn
