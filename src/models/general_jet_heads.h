// src/models/general_jet_heads.h — the order-1 jets of the n-state PH fields
// for the hand-written regularized training steps (general_manual_step.cpp):
// the curvature of H_theta (gradH and its Hessian), the PHNN-JR field jet and
// the PHNN-S field jet with its port map, each a forward and a backward
// without an autograd node, row by row (a row = one member and one batch
// element, so a member's bits never depend on its stackmates). They compute
// what the op-by-op jets of general_ph.cpp compute, in another order: equal
// to round-off (tests/models/general_manual_step_test.cpp). Jets carry d
// directions: a tangent [E, B, d, n] holds d/dx_a in row a. Private to src/models.
#pragma once

#include <torch/torch.h>

#include <vector>

#include "models/head_types.h"

namespace phnn {
namespace internal {

/// gradH [E, B, n] and its Hessian [E, B, n, n] from L_H's order-2 jet (o
/// [E, B, K], o_g [E, B, n, K], o_h [E, B, n, n, K], K = n (n + 1) / 2) and
/// x [E, B, n]; the tape keeps what the backward reads.
HamiltonianCurvature general_curvature_forward(const torch::Tensor& o, const torch::Tensor& o_g,
                                               const torch::Tensor& o_h, const torch::Tensor& x,
                                               CurvatureTape* tape);
/// From (gradH~, Hessian~; undefined = 0): the adjoints of o, o_g, o_h, x.
CurvatureAdjoints general_curvature_backward(const CurvatureTape& tape,
                                             const torch::Tensor& grad_bar,
                                             const torch::Tensor& hessian_bar);

/// PHNN-JR: f = [(J - L^T L) [e; u]]_{1:n_x} and its tangents g [E, B, d, n_x]
/// from the effort jet (e, e_g [E, B, d, n_x]) and L_R's (o, o_g [E, B, d, K]);
/// J row-major m x m, m = n_x + n_u.
JrFieldJet general_jr_field_jet_forward(const torch::Tensor& e, const torch::Tensor& e_g,
                                        const torch::Tensor& o, const torch::Tensor& o_g,
                                        const torch::Tensor& u, const std::vector<double>& J);
/// From (f~, g~; undefined = 0): the adjoints of e, e_g, o, o_g and u.
JrFieldJetAdjoints general_jr_field_jet_backward(const torch::Tensor& e, const torch::Tensor& e_g,
                                                 const torch::Tensor& o, const torch::Tensor& o_g,
                                                 const torch::Tensor& u,
                                                 const std::vector<double>& J,
                                                 const torch::Tensor& f_bar,
                                                 const torch::Tensor& g_bar);

/// PHNN-S's port variables and their tangents: w = M [e; u], w_g = M_x e_g,
/// M = [S_wx S_wu] row-major (n_w rows), and the backward to (e~, e_g~).
struct PortJet {
  torch::Tensor w, w_g;  // [E, B, n_w], [E, B, d, n_w]
};
PortJet general_port_jet(const torch::Tensor& e, const torch::Tensor& e_g, const torch::Tensor& u,
                         const std::vector<double>& M, int n_w);
struct EffortJetAdjoints {
  torch::Tensor e, e_g;
};
EffortJetAdjoints general_port_jet_backward(const torch::Tensor& w_bar,
                                            const torch::Tensor& w_g_bar,
                                            const std::vector<double>& M, int n_x, int n_u);

/// PHNN-S: z = (L^T L + K - K^T) w and f = S_x [e; z; u] with their tangents,
/// from the effort jet, the ports' jet and L_z's outputs with their tangents
/// (o [E, B, n_w^2]: L's triangle, then K's strict lower triangle).
JrFieldJet general_s_field_jet_forward(const torch::Tensor& e, const torch::Tensor& e_g,
                                       const torch::Tensor& u, const torch::Tensor& o,
                                       const torch::Tensor& o_g, const PortJet& w,
                                       const std::vector<double>& S, int n_w);
/// From (f~, g~; undefined = 0): the adjoints of e and e_g through S_x's
/// effort columns, of L_z's outputs and of the ports' jet (before L_z's own
/// input adjoint).
struct SFieldJetAdjoints {
  torch::Tensor e, e_g, o, o_g, w, w_g;
};
SFieldJetAdjoints general_s_field_jet_backward(const torch::Tensor& o, const torch::Tensor& o_g,
                                               const PortJet& w, const std::vector<double>& S,
                                               int n_x, int n_w, int n_u,
                                               const torch::Tensor& f_bar,
                                               const torch::Tensor& g_bar);

}  // namespace internal
}  // namespace phnn
