// src/models/manual_step.h — the parts of the hand-written training steps
// that do not depend on a model's structure or size: taped networks, the
// mean-L1 loss and its adjoint, the RK2 and RK4 steps of a field recorder,
// and the PH models' steps (RK, DG, DG4) around the Hamiltonian head of
// general_heads.h (gradH in reverse mode). Private to src/models (general_manual_step.cpp
// composes them per model). Every function computes the operations of the
// autograd path in its order, so NODE's loss and gradients are bitwise those
// of loss.sum().backward(), and the PH models' equal them to round-off (their
// gradH is a vector-Jacobian product of L_H where autograd's graph has
// L_H's forward-mode jet; tests/models/manual_step_test.cpp,
// general_manual_step_test.cpp, dg4_manual_step_test.cpp).
#pragma once

#include <torch/torch.h>

#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "models/fused_mlp.h"
#include "models/fused_mlp_gradient.h"
#include "models/general_heads.h"
#include "models/head_types.h"
#include "phnn/models/dynamics_model.h"
#include "phnn/models/stacked_mlp.h"

namespace phnn {
namespace internal {
namespace manual {

using torch::Tensor;

/// One field evaluation f(y) (with df/dx if asked for) and its backward:
/// adds the parameter gradients of f~ . f + dfdx~ . df/dx into the sinks and
/// returns y~ if `input` (else undefined; dfdx~ undefined = 0).
struct TapedField {
  Tensor f, dfdx;
  std::function<Tensor(const Tensor& f_bar, const Tensor& dfdx_bar, bool input)> backward;
};
using FieldRecorder = std::function<TapedField(const Tensor& y, bool jacobian)>;

/// A PH model's field from an effort e, with y the dissipation's point
/// (PHNN-S ignores it): f, and the backward f~ -> (e~, y~ or undefined).
struct TapedEffortField {
  Tensor f;
  std::function<std::pair<Tensor, Tensor>(const Tensor& f_bar, bool input)> backward;
};
using EffortFieldRecorder = std::function<TapedEffortField(const Tensor& effort, const Tensor& y)>;

/// DG4: a PH model's order-2 field jet phi(s) = F(y + s, e + Q s) in the
/// n_x state directions s (dg4_jet_heads.h: f, g [E, B, d, n], h [E, B, d,
/// d, n]), and the backward (f~, g~, h~) -> (e~, Q~); no input adjoint of y.
struct TapedFieldJet2 {
  Tensor f, g, h;
  std::function<std::pair<Tensor, Tensor>(const Tensor& f_bar, const Tensor& g_bar,
                                          const Tensor& h_bar)>
      backward;
};
using EffortJet2Recorder =
    std::function<TapedFieldJet2(const Tensor& effort, const Tensor& q, const Tensor& y)>;

/// A PH model's field with df/dx at a data point (no input adjoint), for a
/// Jacobian penalty; empty where the model has none hand-written.
using JacobianFieldRecorder = std::function<TapedField(const Tensor& x)>;

/// [x, u] along the last dimension (x [E, B, n], u [E, B, k], both dense).
Tensor cat_rows(const Tensor& x, const Tensor& u);

/// out = a + c b, elementwise (two roundings: the build does not contract).
Tensor add_scaled(const Tensor& a, double c, const Tensor& b);

/// The networks a hand-written step can use: fused float64, bound to the
/// flat buffers.
bool has_manual_step(const std::vector<std::unique_ptr<StackedMlp>>& nets, torch::ScalarType dtype);

/// A network's taped forward and its backward (parameter gradients into its sinks).
struct TapedNet {
  const StackedMlp& net;
  std::shared_ptr<FusedMlpTape> tape;
  std::shared_ptr<FusedMlpVjpTape> vjp_tape = nullptr;
  FusedMlpJet forward(const Tensor& y, int directions, int order);
  Tensor backward(const std::vector<Tensor>& grads, bool input) const;
  /// After an order-0 forward: s = J(y)^T c (fused_mlp_gradient.h); its
  /// backward s~ -> c~, then the value pass's backward from v~ (-> y~ if `input`).
  Tensor vjp(const Tensor& c);
  Tensor vjp_backward(const Tensor& s_bar) const;
  Tensor backward_after_vjp(const Tensor& v_bar, bool input) const;
  /// With an order-1 input jet (v, g [E, B, d, n]) to order 1 or 2 (the
  /// input's second derivative 0); backward -> (v~, g~).
  FusedMlpJet forward_jet(const Tensor& v, const Tensor& g, int order = 1);
  std::pair<Tensor, Tensor> backward_jet(const std::vector<Tensor>& grads) const;
};

/// H(y) and gradH(y) in reverse mode (general_heads.h): L_H's value, the
/// head's cotangent c, then gradH = L^T v + J^T c; kept for its backward
/// (unused without one: rollouts take the same path, the same bits).
struct TapedGradient {
  TapedNet l_h;
  HamiltonianTape head;
  Tensor h, grad;
  TapedGradient(const StackedMlp& net, const Tensor& y);
  /// y~ = (c + the head's x adjoint b) + L_H's input adjoint a, autograd's
  /// order; c (another node's adjoint of y, created after these) may be
  /// undefined. The product's backward gives the head's c~ first.
  Tensor backward(const Tensor& grad_bar, bool input, const Tensor& c = Tensor()) const;
};

/// gradH(x) and its Hessian from L_H's order-2 jet in the x.size(-1) state
/// directions, kept for the backward from (gradH~, Hessian~): the head, then L_H.
struct TapedCurvature {
  TapedNet l_h;
  CurvatureTape head;
  HamiltonianCurvature effort;
  TapedCurvature(const StackedMlp& net, const Tensor& x);
  void backward(const Tensor& grad_bar, const Tensor& hessian_bar) const;
};

/// The explicit step of `field` (RK2 or RK4), its mean-L1 loss per member
/// [E] (+ the penalty of df/dx at x) and backward.
Tensor explicit_mean_l1(IntegratorKind integrator, const Tensor& x, const Tensor& x_next, double h,
                        const FieldRecorder& field, const JacobianPenalty& penalty);

/// The explicit step of a PH model: f(y) = F(gradH(y), y), gradH in reverse
/// mode (L_H's value, the Hamiltonian head's cotangent, the product J^T c).
Tensor ph_explicit_mean_l1(IntegratorKind integrator, const StackedMlp& l_h,
                           const Tensor& x, const Tensor& x_next,
                           double h, const EffortFieldRecorder& effort_field,
                           const JacobianFieldRecorder& jacobian_field,
                           const JacobianPenalty& penalty);

/// The DG step of a PH model (Gonzalez gradient of H_theta), its
/// loss (+ the penalty of df/dx at x) and backward.
Tensor ph_dg_mean_l1(const StackedMlp& l_h, const Tensor& x,
                     const Tensor& x_next, double h, double min_dx_norm, bool dissipation_at_start,
                     const EffortFieldRecorder& effort_field,
                     const JacobianFieldRecorder& jacobian_field, const JacobianPenalty& penalty);

/// The DG4 step of a PH model (docs/METHOD.md "DG4: a fourth-order
/// discrete gradient"): the AVF effort e (H at the ends, gradH at the three
/// Gauss points), Q = the Hessian at m = x + dx/2, phi's order-2 jet from
/// `field_jet`, f4 = v + h^2 (phi''[v, v] / 24 - A A v / 12); its loss
/// (+ the penalty of df/dx at x) and backward.
Tensor ph_dg4_mean_l1(const StackedMlp& l_h, const Tensor& x, const Tensor& x_next, double h,
                      double min_dx_norm, const EffortJet2Recorder& field_jet,
                      const JacobianFieldRecorder& jacobian_field, const JacobianPenalty& penalty);

/// NODE's explicit step: f = MLP([y, u]) (with its order-1 jet in the n_x state
/// directions when `penalty` asks for df/dx); y~ = the first n_x columns of
/// the input adjoint. u is dense [E, B, n_u].
Tensor node_explicit_mean_l1(IntegratorKind integrator, const StackedMlp& mlp, const Tensor& x,
                             const Tensor& x_next, const Tensor& u, double h,
                             const JacobianPenalty& penalty);

}  // namespace manual
}  // namespace internal
}  // namespace phnn
