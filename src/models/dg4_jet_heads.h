// src/models/dg4_jet_heads.h — the order-2 jets of the n-state PH fields and
// the DG4 correction, for the hand-written DG4 training step
// (general_manual_step.cpp, manual_step.cpp's ph_dg4_mean_l1): the PHNN-JR
// field jet, the PHNN-S field jet with ports around L_z's order-2 call, and
// f = v + h^2 (phi''[v, v] / 24 - A A v / 12) (docs/METHOD.md "DG4: a
// fourth-order discrete gradient"), each a forward and a backward without an
// autograd node, row by row (a row = one member and one batch element, so a
// member's bits never depend on its stackmates). They compute what the
// op-by-op jets of general_ph.cpp and port_hamiltonian.cpp's
// discrete_gradient4_field compute, in another order: equal to round-off
// (tests/models/dg4_manual_step_test.cpp). A tangent [E, B, d, n] holds
// d/ds_a in row a, a second derivative [E, B, d, d, n] d2/ds_a ds_b in
// (a, b) (both copies stored). Private to src/models.
#pragma once

#include <torch/torch.h>

#include <vector>

#include "models/general_jet_heads.h"

namespace phnn {
namespace internal {

/// An order-2 jet of a field: f [E, B, n], g [E, B, d, n], h [E, B, d, d, n].
struct FieldJet2 {
  torch::Tensor f, g, h;
};

/// The adjoints of an order-2 field jet's inputs: the effort jet (e, e_g;
/// its second derivative is 0 and has no adjoint), the network's order-2
/// jet (o, o_g, o_h) and, for PHNN-S, the ports' order-1 jet (w, w_g).
struct FieldJet2Adjoints {
  torch::Tensor e, e_g, o, o_g, o_h, w, w_g;
};

/// PHNN-JR: the order-2 jet of f = [(J - L^T L) [e; u]]_{1:n_x} from the
/// effort jet (e [E, B, n_x], e_g [E, B, d, n_x], e_h = 0) and L_R's jet
/// (o [E, B, K], o_g [E, B, d, K], o_h [E, B, d, d, K]), J row-major m x m.
FieldJet2 jr_field_jet2_forward(const torch::Tensor& e, const torch::Tensor& e_g,
                                const torch::Tensor& o, const torch::Tensor& o_g,
                                const torch::Tensor& o_h, const torch::Tensor& u,
                                const std::vector<double>& J);
/// From (f~, g~, h~): the adjoints of e, e_g and of L_R's jet (w, w_g undefined).
FieldJet2Adjoints jr_field_jet2_backward(const torch::Tensor& e, const torch::Tensor& e_g,
                                         const torch::Tensor& o, const torch::Tensor& o_g,
                                         const torch::Tensor& o_h, const torch::Tensor& u,
                                         const std::vector<double>& J, const FieldJet2& bar);

/// PHNN-S with n_w >= 1 ports: z = (L^T L + K - K^T) w and f = S_x [e; z; u]
/// to order 2, from the effort jet (e_h = 0), the ports' jet (w, w_g; w_h =
/// 0: w is linear in e) and L_z's order-2 jet (o [E, B, n_w^2]).
FieldJet2 s_field_jet2_forward(const torch::Tensor& e, const torch::Tensor& e_g,
                               const torch::Tensor& u, const torch::Tensor& o,
                               const torch::Tensor& o_g, const torch::Tensor& o_h,
                               const PortJet& w, const std::vector<double>& S, int n_w);
/// From (f~, g~, h~): the adjoints of e, e_g through S_x's effort columns,
/// of L_z's jet and of the ports' jet (before L_z's own input adjoint).
FieldJet2Adjoints s_field_jet2_backward(const torch::Tensor& o, const torch::Tensor& o_g,
                                        const torch::Tensor& o_h, const PortJet& w,
                                        const std::vector<double>& S, int n_x, int n_w, int n_u,
                                        const FieldJet2& bar);

/// DG4's field from phi's order-2 jet (dg4_correction.cpp) in the n_x state directions (v = f,
/// A[i][a] = g[a][i], phi''[v, v]_i = sum_ab h[a][b][i] v_a v_b):
///   f4 = v + h^2 (phi''[v, v] / 24 - A A v / 12).
torch::Tensor dg4_correction_forward(const FieldJet2& phi, double h);
/// Its backward from f4~: the adjoints of phi's f, g and h.
FieldJet2 dg4_correction_backward(const FieldJet2& phi, double h, const torch::Tensor& f4_bar);

}  // namespace internal
}  // namespace phnn
