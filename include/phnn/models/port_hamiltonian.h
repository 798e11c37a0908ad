// include/phnn/models/port_hamiltonian.h — PHNN-S and PHNN-JR (paper §4).
#pragma once

#include <array>

#include "phnn/models/dynamics_model.h"

namespace phnn {

/// H_theta(x) = 1/2 x^T L_H(x)^T L_H(x) x (eq:quadratic_H,
/// eq:physical_constraints_H) with L_H = [[softplus(o0), 0], [o1, softplus(o2)]]
/// from a 2 -> 3 MLP: Q = L^T L is positive definite by construction.
/// Returns the jet of H ([E, B, 1]): g = gradH, h = Hessian, up to `order`.
Jet hamiltonian_jet(const StackedMlp& l_h, const torch::Tensor& x, int order);

/// Jet whose value is gradH [E, B, 2] and whose g is the Hessian, from the
/// order-(k+1) jet of H.
Jet gradient_jet(const Jet& h);

/// H [E, B, 1] and gradH [E, B, 2] in closed form from the order-1 jet of
/// the L_H outputs o (fewer ops than hamiltonian_jet(.., 1), same values to
/// round-off). With v = L_H x, s_k = sigmoid(o_k):
///   gradH = L_H^T v + (do/dx) c,  c = (v0 s0 q, v1 q, v1 s2 p).
struct HamiltonianAndGradient {
  torch::Tensor h, grad;
};
HamiltonianAndGradient hamiltonian_and_gradient(const StackedMlp& l_h, const torch::Tensor& x);

/// Shared by PHNN-S and PHNN-JR: H_theta, gradH_theta, the Gonzalez DG.
class PortHamiltonianModel : public DynamicsModel {
 public:
  bool is_port_hamiltonian() const override { return true; }
  torch::Tensor hamiltonian(const torch::Tensor& x) const override;
  torch::Tensor grad_hamiltonian(const torch::Tensor& x) const override;
  FieldEval field(const torch::Tensor& x, const torch::Tensor& u,
                  bool with_jacobian) const override;
  torch::Tensor discrete_gradient_field(const torch::Tensor& x, const torch::Tensor& dx,
                                        const torch::Tensor& u,
                                        double min_dx_norm) const override;

  /// d f_bar / d dx from jets taken w.r.t. the midpoint m = x + dx/2 (see
  /// port_hamiltonian.cpp): no finite differences.
  FieldEval discrete_gradient_field_with_jacobian(const torch::Tensor& x, const torch::Tensor& dx,
                                                  const torch::Tensor& u,
                                                  double min_dx_norm) const override;

  FieldEval discrete_gradient4_field(const torch::Tensor& x, const torch::Tensor& dx,
                                     const torch::Tensor& u, double h,
                                     double min_dx_norm) const override;

  /// Average-vector-field discrete gradient of H_theta, made exact:
  ///   g = sum_k w_k gradH(x + c_k dx)   (3-point Gauss-Legendre, error O(|dx|^6)),
  ///   avf = g + (H(x+dx) - H(x) - g^T dx) / |dx|^2 dx   (= g below min_dx_norm),
  /// so avf^T dx = H(x+dx) - H(x) to round-off and avf = int_0^1 gradH + O(|dx|^5).
  torch::Tensor average_vector_field_gradient(const torch::Tensor& x, const torch::Tensor& dx,
                                              double min_dx_norm) const;

  /// Gonzalez discrete gradient of H_theta (eq: gonzalez-discrete-gradient):
  ///   dg = gradH(x + dx/2) + (H(x+dx) - H(x) - gradH(x+dx/2)^T dx) / |dx|^2 dx,
  /// = gradH(x + dx/2) where |dx| < min_dx_norm (docs/METHOD.md §4).
  virtual torch::Tensor discrete_gradient(const torch::Tensor& x, const torch::Tensor& dx,
                                          double min_dx_norm) const;

 protected:
  PortHamiltonianModel(ModelOptions options, int64_t members)
      : DynamicsModel(options, members) {}
  /// f from an effort jet e ([E,B,2], directions x) evaluated with the
  /// dissipation network at `x_dissipation` (PHNN-JR: R(x, u)); with
  /// `dissipation_fixed`, R does not move along the jet's directions (its
  /// derivatives are zero: the DG field with R at the start x_n, where only
  /// the effort depends on dx).
  virtual Jet field_from_effort(const Jet& effort, const torch::Tensor& x_dissipation,
                                const torch::Tensor& u, int order,
                                bool dissipation_fixed) const = 0;
  /// True when the DG field evaluates R_theta at x_n (PHNN-JR with
  /// ModelOptions::dg_structure_point = kStart).
  bool dissipation_at_start() const;
  const StackedMlp& l_h() const { return *nets_[0]; }
  /// H [E, B, 1] and gradH [E, B, n_x] (the 2-state closed form; the
  /// n-dimensional models of general_ph.h override it).
  virtual HamiltonianAndGradient energy_and_gradient(const torch::Tensor& x) const;
  /// Jet whose value is gradH(x) [E, B, n_x] and whose g is the Hessian
  /// [E, B, n_x, n_x].
  virtual Jet curvature_jet(const torch::Tensor& x) const;
};

/// PHNN-S (eq:f_theta-PHS-DAF): w = S_wx gradH + S_wu u,
/// z_theta(w) = Gamma(w) w with Gamma = L_z(w)^T L_z(w) (n_w = 1: K omitted),
/// f = S_xx gradH + S_xw z_theta(w) + S_xu u.
class PhnnS : public PortHamiltonianModel {
 public:
  PhnnS(ModelOptions options, const std::vector<std::uint64_t>& seeds);
  torch::Tensor explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, const JacobianPenalty& penalty) const override;
  torch::Tensor dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                const torch::Tensor& u, double h, double min_dx_norm,
                                const JacobianPenalty& penalty) const override;

 protected:
  Jet field_from_effort(const Jet& effort, const torch::Tensor& x_dissipation,
                        const torch::Tensor& u, int order, bool dissipation_fixed) const override;

 private:
  std::array<std::array<double, 4>, 4> S_;
};

/// PHNN-JR (eq:f_theta-PHS-JR): f = [(J - R_theta(x, u)) [gradH; u]]_{1:2},
/// R = L_R^T L_R with L_R lower triangular 3 x 3 from a 3 -> 6 MLP.
class PhnnJr : public PortHamiltonianModel {
 public:
  PhnnJr(ModelOptions options, const std::vector<std::uint64_t>& seeds);
  /// R_theta(x, u) [E, B, 3, 3] (for tests: symmetric PSD).
  torch::Tensor dissipation_matrix(const torch::Tensor& x, const torch::Tensor& u) const;
  torch::Tensor explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, const JacobianPenalty& penalty) const override;
  torch::Tensor dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                const torch::Tensor& u, double h, double min_dx_norm,
                                const JacobianPenalty& penalty) const override;

 protected:
  Jet field_from_effort(const Jet& effort, const torch::Tensor& x_dissipation,
                        const torch::Tensor& u, int order, bool dissipation_fixed) const override;

 private:
  std::array<std::array<double, 3>, 3> J_;
  torch::Tensor j_matrix_;   // J [3, 3]
  torch::Tensor placement_;  // [6, 9]: L_R outputs -> row-major 3 x 3 lower triangle
};

/// NODE baseline (eq: neural-ode): f = MLP([x; u]), 3 -> 2.
class Node : public DynamicsModel {
 public:
  Node(ModelOptions options, const std::vector<std::uint64_t>& seeds);
  FieldEval field(const torch::Tensor& x, const torch::Tensor& u,
                  bool with_jacobian) const override;
  torch::Tensor explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, const JacobianPenalty& penalty) const override;
};

}  // namespace phnn
