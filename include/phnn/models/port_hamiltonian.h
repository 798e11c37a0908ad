// include/phnn/models/port_hamiltonian.h — what PHNN-S and PHNN-JR (paper §4)
// share: the energy, the field from gradH, the DG fields; the models
// themselves are general_ph.h's.
#pragma once


#include "phnn/models/dynamics_model.h"

namespace phnn {

/// Jet whose value is gradH [E, B, n_x] and whose g is the Hessian, from the
/// order-(k+1) jet of H.
Jet gradient_jet(const Jet& h);

/// H [E, B, 1] and gradH [E, B, n_x].
struct HamiltonianAndGradient {
  torch::Tensor h, grad;
};

/// Shared by PHNN-S and PHNN-JR on a system's structure (ModelOptions::
/// general): H_theta = 1/2 |L_H(x) x|^2 (general_hamiltonian_jet), gradH,
/// the Hessian, the Gonzalez DG, the fields from an effort and the DG
/// fields (general_ph.cpp, port_hamiltonian.cpp).
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
  torch::Tensor discrete_gradient(const torch::Tensor& x, const torch::Tensor& dx,
                                  double min_dx_norm) const;

 protected:
  /// Requires options.general (the structure).
  PortHamiltonianModel(ModelOptions options, int64_t members);
  /// f from an effort jet e ([E,B,n_x], directions x) evaluated with the
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
  /// H [E, B, 1] and gradH [E, B, n_x].
  HamiltonianAndGradient energy_and_gradient(const torch::Tensor& x) const;
  /// Jet whose value is gradH(x) [E, B, n_x] and whose g is the Hessian
  /// [E, B, n_x, n_x].
  Jet curvature_jet(const torch::Tensor& x) const;
  const ModelStructure& structure() const { return *options().general; }
  /// Row-major matrix block [r0, r0 + rows) x [c0, c0 + cols) of a
  /// structure matrix with `width` columns, as a [cols, rows] tensor (the
  /// right factor of jet_linear: y = a M^T).
  torch::Tensor block_t(const std::vector<double>& matrix, int width, int r0, int rows, int c0,
                        int cols) const;
};

}  // namespace phnn
