// src/models/general_heads.h — the fused heads of the n-dimensional PHNN-S and
// PHNN-JR (include/phnn/models/general_ph.h): the parts that sit on top of the
// networks, each one autograd node with a hand-written backward, computed row
// by row (a row = one member and one batch element, so a member's bits never
// depend on its stackmates). Order 0 and 1 in the state (training, RK and DG
// fields); the jets of order 2 (regularizers, DG4, Newton Jacobians) stay on
// the op-by-op path of general_ph.cpp (the hand-written training steps have
// their own: general_jet_heads.h, dg4_jet_heads.h), which is also the
// reference the tests compare these heads with. Each head's arithmetic is a pair of plain
// functions (forward, backward) that its autograd node calls and that the
// hand-written steps (general_manual_step.cpp) call without a node, so both
// paths compute the same bits. Private to src/models.
#pragma once

#include <vector>

#include <torch/torch.h>

#include "models/head_types.h"

namespace phnn {
namespace internal {

/// H = |L(x) x|^2 / 2 with L lower triangular n x n from the n (n + 1) / 2
/// outputs o [E, B, K] of L_H (row-major lower triangle, softplus on the
/// diagonal), and, when o_g [E, B, n (direction), K] is defined, gradH:
///   v = L x,  gradH_i = (L^T v)_i + sum_k o_g[i][k] c_k,
///   c_k = v_r x_c (sigmoid(o_k) on the diagonal) for entry k = (r, c).
struct GeneralHamiltonian {
  torch::Tensor h, grad;  // [E, B, 1], [E, B, n] or undefined
};
GeneralHamiltonian general_hamiltonian_head(const torch::Tensor& o, const torch::Tensor& o_g,
                                            const torch::Tensor& x);

/// general_hamiltonian_head without an autograd node: the same forward,
/// with what its backward reads in *tape (o_g undefined: H only), and the
/// same backward from (H~, gradH~; undefined = 0): the adjoints of o, o_g, x.
HamiltonianHead general_hamiltonian_forward(const torch::Tensor& o, const torch::Tensor& o_g,
                                            const torch::Tensor& x, HamiltonianTape* tape);
HamiltonianAdjoints general_hamiltonian_backward(const HamiltonianTape& tape,
                                                 const torch::Tensor& h_bar,
                                                 const torch::Tensor& g_bar);

/// Reverse mode: gradH = L^T v + J_o(x)^T c, the second term a
/// vector-Jacobian product of L_H (fused_mlp_gradient.h) with the cotangent
///   c_k = v_r x_c (sigmoid(o_k) on the diagonal), entry k = (r, c).
/// The head gives H, c and L^T v (o_g undefined in *tape); its backward
/// takes H~ (undefined = 0), gradH~ and the product's c~ (o_g~ undefined).
struct HamiltonianCotangent {
  torch::Tensor h, c, l_t_v;  // [E, B, 1], [E, B, K], [E, B, n]
};
HamiltonianCotangent general_hamiltonian_cotangent(const torch::Tensor& o, const torch::Tensor& x,
                                                   HamiltonianTape* tape);
HamiltonianAdjoints general_hamiltonian_cotangent_backward(const HamiltonianTape& tape,
                                                           const torch::Tensor& h_bar,
                                                           const torch::Tensor& g_bar,
                                                           const torch::Tensor& c_bar);

/// Gonzalez discrete gradient for n states (eq: gonzalez-discrete-gradient):
///   dg = g + (H1 - H0 - g.dx) / |dx|^2 dx,  = g where |dx| < min_dx_norm.
torch::Tensor general_gonzalez_head(const torch::Tensor& h0, const torch::Tensor& h1,
                                    const torch::Tensor& grad_mid, const torch::Tensor& dx,
                                    double min_dx_norm);

/// The same without an autograd node (all [E, B, .] alike), and its backward
/// from dg~: the adjoints of H0, H1, g and dx.
torch::Tensor gonzalez_forward(const torch::Tensor& h0, const torch::Tensor& h1,
                               const torch::Tensor& grad_mid, const torch::Tensor& dx,
                               double min_dx_norm);
struct GonzalezAdjoints {
  torch::Tensor h0, h1, grad, dx;
};
GonzalezAdjoints gonzalez_backward(const torch::Tensor& h0, const torch::Tensor& h1,
                                   const torch::Tensor& grad_mid, const torch::Tensor& dx,
                                   double min_dx_norm, const torch::Tensor& dg_bar);

/// A linear map y = M [a; b] per row, M row-major rows x (n_a + n_b)
/// (a structure block): the PHNN-S port variables w = [S_wx S_wu] [e; u].
torch::Tensor general_linear_head(const torch::Tensor& a, const torch::Tensor& b,
                                  const std::vector<double>& M, int rows);
/// Its forward without a node, and its backward from y~ (n_a, n_b the widths of a, b).
torch::Tensor general_linear_forward(const torch::Tensor& a, const torch::Tensor& b,
                                     const std::vector<double>& M, int rows);
struct LinearAdjoints {
  torch::Tensor a, b;
};
LinearAdjoints general_linear_backward(const torch::Tensor& y_bar, const std::vector<double>& M,
                                       int n_a, int n_b);

/// PHNN-S field for n_w ports from the effort e [E, B, n_x], u [E, B, n_u],
/// the L_z outputs o [E, B, n_w (n_w + 1) / 2 + n_w (n_w - 1) / 2] (L_z lower
/// triangle, then K strictly lower) and w [E, B, n_w]:
///   z = L_z^T L_z w + (K - K^T) w,  f = S_x [e; z; u],
/// S_x the first n_x rows of S (row-major, n_x + n_w + n_u columns).
torch::Tensor general_s_field_head(const torch::Tensor& e, const torch::Tensor& u,
                                   const torch::Tensor& o, const torch::Tensor& w,
                                   const std::vector<double>& S, int n_w);
/// Its forward without a node, and its backward from f~ given o and w.
torch::Tensor general_s_field_forward(const torch::Tensor& e, const torch::Tensor& u,
                                      const torch::Tensor& o, const torch::Tensor& w,
                                      const std::vector<double>& S, int n_w);
struct SFieldAdjoints {
  torch::Tensor e, u, o, w;
};
SFieldAdjoints general_s_field_backward(const torch::Tensor& o, const torch::Tensor& w,
                                        const std::vector<double>& S, int n_x, int n_w, int n_u,
                                        const torch::Tensor& f_bar);

/// PHNN-JR field: f = [(J - L^T L) [e; u]]_{1:n_x} with L lower triangular
/// m x m (m = n_x + n_u) from the L_R outputs o [E, B, m (m + 1) / 2] and J
/// row-major m x m.
torch::Tensor general_jr_field_head(const torch::Tensor& e, const torch::Tensor& u,
                                    const torch::Tensor& o, const std::vector<double>& J);
/// Its forward without a node, and its backward from f~: the adjoints of
/// the effort, of o and of u.
torch::Tensor general_jr_field_forward(const torch::Tensor& e, const torch::Tensor& u,
                                       const torch::Tensor& o, const std::vector<double>& J);
JrFieldAdjoints general_jr_field_backward(const torch::Tensor& e, const torch::Tensor& u,
                                          const torch::Tensor& o, const std::vector<double>& J,
                                          const torch::Tensor& f_bar);

}  // namespace internal
}  // namespace phnn
