// src/models/fused_heads.h — the closed-form parts of the PHNN models that
// sit on top of the networks, each one autograd node with a hand-written
// backward (docs/DECISIONS.md "Fused networks"). Private to src/models; the
// op-by-op formulas they replace stay in port_hamiltonian.cpp as the
// reference path, and the tests compare the two.
#pragma once

#include <array>

#include <torch/torch.h>

namespace phnn {
namespace internal {

/// H = |L_H(x) x|^2 / 2 and, if `o_g` is defined, gradH (eq:quadratic_H),
/// from the L_H outputs o [E, B, 3] and their x-derivatives o_g [E, B, 2, 3]:
///   L_H = [[softplus(o0), 0], [o1, softplus(o2)]],  v = L_H x,
///   gradH = L_H^T v + o_g c,  c = (v0 sigmoid(o0) q, v1 q, v1 sigmoid(o2) p).
/// Returns {H [E, B, 1], gradH [E, B, 2] or undefined}.
struct HamiltonianHead {
  torch::Tensor h, grad;
};
HamiltonianHead hamiltonian_head(const torch::Tensor& o, const torch::Tensor& o_g,
                                 const torch::Tensor& x);

/// hamiltonian_head without an autograd node, for a hand-written step
/// (models/manual_step.cpp): the same forward, with what its backward
/// reads in *tape, and the same backward (adjoints h~, g~; undefined = 0).
struct HamiltonianTape {
  torch::Tensor o, o_g, x, aux;  // o_g undefined: H only
};
HamiltonianHead hamiltonian_head_taped(const torch::Tensor& o, const torch::Tensor& o_g,
                                       const torch::Tensor& x, HamiltonianTape* tape);
struct HamiltonianAdjoints {
  torch::Tensor o, o_g, x;
};
HamiltonianAdjoints hamiltonian_head_backward(const HamiltonianTape& tape,
                                              const torch::Tensor& h_bar, const torch::Tensor& g_bar);

/// gradH [E, B, 2] and the Hessian of H [E, B, 2, 2] (symmetric; [i][k] =
/// d2H / dx_i dx_k) from the L_H outputs o [E, B, 3] and their first and
/// second x-derivatives o_g [E, B, 2, 3], o_h [E, B, 2, 2, 3]: the order-2
/// jet of H = |L_H x|^2 / 2 in closed form (for the Jacobian regularizers).
struct HamiltonianCurvature {
  torch::Tensor grad, hessian;
};
HamiltonianCurvature hamiltonian_curvature_head(const torch::Tensor& o, const torch::Tensor& o_g,
                                                const torch::Tensor& o_h, const torch::Tensor& x);

/// hamiltonian_curvature_head without an autograd node (x already [E, B, 2]),
/// and its backward from (gradH~, Hessian~; undefined = 0).
struct CurvatureTape {
  torch::Tensor o, o_g, o_h, x, aux;
};
HamiltonianCurvature hamiltonian_curvature_taped(const torch::Tensor& o, const torch::Tensor& o_g,
                                                 const torch::Tensor& o_h, const torch::Tensor& x,
                                                 CurvatureTape* tape);
struct CurvatureAdjoints {
  torch::Tensor o, o_g, o_h, x;
};
CurvatureAdjoints hamiltonian_curvature_backward(const CurvatureTape& tape,
                                                 const torch::Tensor& grad_bar,
                                                 const torch::Tensor& hessian_bar);

/// PHNN-JR field (eq:f_theta-PHS-JR) from the effort e [E, B, 2] (gradH or
/// the discrete gradient), the L_R outputs o [E, B, 6] (row-major lower
/// triangle of L_R) and u [E, B, 1]:  f = [(J - L_R^T L_R) (e, u)]_{1:2}.
torch::Tensor jr_field_head(const torch::Tensor& effort, const torch::Tensor& o,
                            const torch::Tensor& u, const std::array<std::array<double, 3>, 3>& J);

/// jr_field_head without an autograd node (u already [E, B, 1]), and its
/// backward from f~: the adjoints of the effort, of o and of u.
torch::Tensor jr_field_forward(const torch::Tensor& effort, const torch::Tensor& o,
                               const torch::Tensor& u,
                               const std::array<std::array<double, 3>, 3>& J);
struct JrFieldAdjoints {
  torch::Tensor effort, o, u;
};
JrFieldAdjoints jr_field_backward(const torch::Tensor& effort, const torch::Tensor& o,
                                  const torch::Tensor& u,
                                  const std::array<std::array<double, 3>, 3>& J,
                                  const torch::Tensor& f_bar);

/// The PHNN-JR field and its x-derivatives (first-order jet) from the effort
/// e [E, B, 2] with its tangents e_g [E, B, 2 (direction), 2], the L_R outputs
/// o [E, B, 6] with theirs o_g [E, B, 2, 6], and u [E, B, 1] (constant):
/// returns f [E, B, 2] and g [E, B, 2 (direction), 2] = d f / d x_i.
struct JrFieldJet {
  torch::Tensor f, g;
};
JrFieldJet jr_field_jet_head(const torch::Tensor& effort, const torch::Tensor& effort_g,
                             const torch::Tensor& o, const torch::Tensor& o_g, const torch::Tensor& u,
                             const std::array<std::array<double, 3>, 3>& J);

/// jr_field_jet_head without an autograd node (u already [E, B, 1]), and its
/// backward from (f~, g~; undefined = 0) given the forward's inputs, dense.
JrFieldJet jr_field_jet_forward(const torch::Tensor& effort, const torch::Tensor& effort_g,
                                const torch::Tensor& o, const torch::Tensor& o_g,
                                const torch::Tensor& u,
                                const std::array<std::array<double, 3>, 3>& J);
struct JrFieldJetAdjoints {
  torch::Tensor effort, effort_g, o, o_g, u;
};
JrFieldJetAdjoints jr_field_jet_backward(const torch::Tensor& effort, const torch::Tensor& effort_g,
                                         const torch::Tensor& o, const torch::Tensor& o_g,
                                         const torch::Tensor& u,
                                         const std::array<std::array<double, 3>, 3>& J,
                                         const torch::Tensor& f_bar, const torch::Tensor& g_bar);

/// PHNN-S (eq:f_theta-PHS-DAF), in two heads around the L_z network:
///   w = S_wx e + S_wu u  (s_w = (S_w0, S_w1, S_w3); S_ww = 0),
///   f = S_xx e + S_xw l(w)^2 w + S_xu u  (rows 0, 1 of S; l = L_z(w) [E, B, 1]).
torch::Tensor phnn_s_w_head(const torch::Tensor& effort, const torch::Tensor& u,
                           const std::array<double, 3>& s_w);
torch::Tensor phnn_s_field_head(const torch::Tensor& effort, const torch::Tensor& u,
                                const torch::Tensor& l, const torch::Tensor& w,
                                const std::array<std::array<double, 4>, 4>& S);

/// The PHNN-S heads without autograd nodes (u already [E, B, 1]) and their
/// backwards: w~ -> (e~, u~);  f~ -> (e~, u~, l~, w~).
torch::Tensor phnn_s_w_forward(const torch::Tensor& effort, const torch::Tensor& u,
                               const std::array<double, 3>& s_w);
struct PhnnSWAdjoints {
  torch::Tensor effort, u;
};
PhnnSWAdjoints phnn_s_w_backward(const std::array<double, 3>& s_w, const torch::Tensor& w_bar);
torch::Tensor phnn_s_field_forward(const torch::Tensor& effort, const torch::Tensor& u,
                                   const torch::Tensor& l, const torch::Tensor& w,
                                   const std::array<std::array<double, 4>, 4>& S);
struct PhnnSFieldAdjoints {
  torch::Tensor effort, u, l, w;
};
PhnnSFieldAdjoints phnn_s_field_backward(const torch::Tensor& l, const torch::Tensor& w,
                                         const std::array<std::array<double, 4>, 4>& S,
                                         const torch::Tensor& f_bar);

/// PHNN-S's order-1 field jet without autograd (phnn_s_jet_head.cpp), for
/// the structures of the paper's oscillators (any other: kOther, and the
/// caller keeps the op-by-op path). From the effort e [E, B, 2], its
/// tangents G [E, B, 2 (direction), 2] and u [E, B, 1]: w's jet; with L_z's
/// jet (l [E, B, 1], l_g [E, B, 2, 1]) the field jet (f, g as JrFieldJet).
/// Backward from (f~ or undefined, g~): L_z's output adjoints and the part
/// of w's adjoint before L_z's input adjoint, then (e~, G~).
enum class PhnnSJetStructure { kOther, kMechanical, kSelfSustained };
PhnnSJetStructure phnn_s_jet_structure(const std::array<std::array<double, 4>, 4>& S);
struct PhnnSWJet {
  torch::Tensor w, w_g;
};
PhnnSWJet phnn_s_w_jet_forward(const torch::Tensor& effort, const torch::Tensor& effort_g,
                               const torch::Tensor& u, PhnnSJetStructure structure);
JrFieldJet phnn_s_field_jet_forward(const torch::Tensor& effort, const torch::Tensor& effort_g,
                                    const torch::Tensor& u, const torch::Tensor& l,
                                    const torch::Tensor& l_g, const PhnnSWJet& w,
                                    PhnnSJetStructure structure);
struct PhnnSJetNetAdjoints {
  torch::Tensor l, l_g, w, w_g;  // w, w_g: the part before L_z's input adjoint
};
PhnnSJetNetAdjoints phnn_s_field_jet_backward_net(const torch::Tensor& f_bar,
                                                  const torch::Tensor& g_bar,
                                                  const torch::Tensor& l, const torch::Tensor& l_g,
                                                  const PhnnSWJet& w, PhnnSJetStructure structure);
struct PhnnSJetEffortAdjoints {
  torch::Tensor effort, effort_g;
};
PhnnSJetEffortAdjoints phnn_s_field_jet_backward_effort(const torch::Tensor& f_bar,
                                                        const torch::Tensor& g_bar,
                                                        const PhnnSJetNetAdjoints& first,
                                                        const torch::Tensor& x_bar,
                                                        const torch::Tensor& xg_bar,
                                                        PhnnSJetStructure structure);

}  // namespace internal
}  // namespace phnn
