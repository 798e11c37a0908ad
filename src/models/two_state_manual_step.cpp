// src/models/two_state_manual_step.cpp — the hand-written training steps of
// the 2-state NODE, PHNN-S and PHNN-JR (include/phnn/models/port_hamiltonian.h)
// on fused float64 networks: the field recorders of their closed-form heads
// (fused_heads.h, phnn_s_jet_head.cpp) composed by models/manual_step.h, RK2,
// RK4 and DG, with and without a Jacobian penalty. Bitwise autograd's
// (tests/models/manual_step_test.cpp). Touches only the gradient sinks.
//
// With a penalty, stage 1 of RK2 (or DG's field at x) is the order-1 jet of
// the field at x: PHNN-JR: L_H's order-2 jet, the curvature and JR jet
// heads; PHNN-S: the curvature, L_z's jet and the PHNN-S jet head, or for a
// structure other than the paper's its op-by-op field jet on a small
// autograd graph.
#include <array>
#include <memory>

#include "models/fused_heads.h"
#include "models/fused_heads_common.h"
#include "models/manual_step.h"
#include "phnn/models/port_hamiltonian.h"

namespace phnn {
namespace {

using internal::heads::rows_like;
using namespace internal::manual;
using torch::Tensor;

const HamiltonianOps kTwoStateHead{internal::hamiltonian_head_taped,
                                   internal::hamiltonian_head_backward};
const CurvatureOps kTwoStateCurvature{internal::hamiltonian_curvature_taped,
                                      internal::hamiltonian_curvature_backward};

// PHNN-JR: F(e, y) = JR(e, L_R(y, u), u). Backward: JR~ -> L_R (y~ = c, its
// input adjoint), e~; with gradH: y~ = (c + b) + a.
EffortFieldRecorder jr_effort_field(const StackedMlp& l_r, const Tensor& u,
                                    const std::array<std::array<double, 3>, 3>& J) {
  return [&l_r, u, J](const Tensor& effort, const Tensor& y) {
    auto net_r = std::make_shared<TapedNet>(TapedNet{l_r, nullptr});
    const Tensor o_r = net_r->forward(cat_rows(y, u), 0, 0).v;
    TapedEffortField t{internal::jr_field_forward(effort, o_r, u, J), {}};
    t.backward = [=](const Tensor& f_bar, bool input) {
      const auto jr = internal::jr_field_backward(effort, o_r, u, J, f_bar);
      const Tensor c = net_r->backward({jr.o}, input);
      return std::make_pair(jr.effort, input ? c.narrow(-1, 0, 2) : Tensor());
    };
    return t;
  };
}

// PHNN-JR's field and df/dx at x: the curvature (above), L_R's order-1 jet,
// the JR jet head. Backward, in autograd's order: the JR jet head, L_R, the
// curvature head, L_H.
JacobianFieldRecorder jr_jacobian_field(const StackedMlp& l_h, const StackedMlp& l_r,
                                        const Tensor& u,
                                        const std::array<std::array<double, 3>, 3>& J) {
  return [&l_h, &l_r, u, J](const Tensor& x) {
    auto curvature = std::make_shared<TapedCurvature>(l_h, kTwoStateCurvature, x);
    const auto& effort = curvature->effort;
    auto net_r = std::make_shared<TapedNet>(TapedNet{l_r, nullptr});
    const auto jet_r = net_r->forward(cat_rows(x, u), 2, 1);
    const Tensor o = jet_r.v.contiguous(), o_g = jet_r.g.contiguous();
    const auto jet = internal::jr_field_jet_forward(effort.grad, effort.hessian, o, o_g, u, J);
    TapedField t{jet.f, jet.g.transpose(-1, -2), {}};
    t.backward = [=](const Tensor& f_bar, const Tensor& dfdx_bar, bool /*input*/) {
      const auto jr = internal::jr_field_jet_backward(effort.grad, effort.hessian, o, o_g, u, J,
                                                      f_bar, dfdx_bar.transpose(-1, -2));
      net_r->backward({jr.o, jr.o_g}, false);
      curvature->backward(jr.effort, jr.effort_g);
      return Tensor();
    };
    return t;
  };
}

// A PH model's field and df/dx at x from an effort jet op by op (its
// field_from_effort at order 1: Jet arithmetic around the dissipation
// network's input-jet call): the curvature (taped), then that jet on
// autograd's small graph from the effort jet, whose nodes run in the whole
// graph's order; its backward adds the dissipation network's gradients (its
// fused node) and gives the effort jet's adjoint, then the curvature's.
using EffortJetField = std::function<Jet(const Jet& effort, const Tensor& x)>;
JacobianFieldRecorder op_by_op_jacobian_field(const StackedMlp& l_h, EffortJetField field_jet) {
  return [&l_h, field_jet](const Tensor& x) {
    auto curvature = std::make_shared<TapedCurvature>(l_h, kTwoStateCurvature, x);
    Jet effort, f;
    {
      torch::AutoGradMode enable(true);
      effort.v = curvature->effort.grad.requires_grad_(true);
      effort.g = curvature->effort.hessian.requires_grad_(true);
      f = field_jet(effort, x);
    }
    TapedField t{f.v.detach(), f.g.detach().transpose(-1, -2), {}};
    t.backward = [=](const Tensor& f_bar, const Tensor& dfdx_bar, bool /*input*/) {
      std::vector<Tensor> outputs{f.g}, grads{dfdx_bar.transpose(-1, -2)};
      if (f_bar.defined()) {
        outputs.insert(outputs.begin(), f.v);
        grads.insert(grads.begin(), f_bar);
      }
      const auto adj = torch::autograd::grad(outputs, {effort.v, effort.g}, grads,
                                             /*retain_graph=*/false, /*create_graph=*/false,
                                             /*allow_unused=*/true);
      curvature->backward(adj[0], adj[1]);
      return Tensor();
    };
    return t;
  };
}

// PHNN-S's field and df/dx at x: the curvature, w's jet, L_z's order-1 jet
// from it and the field jet head (phnn_s_jet_head.cpp) for the paper's
// two structures; backward, in autograd's order: the head's first half,
// L_z, its second half, the curvature. Any other structure: the op-by-op
// jet of `field_jet`.
JacobianFieldRecorder s_jacobian_field(const StackedMlp& l_h, const StackedMlp& l_z,
                                       const Tensor& u,
                                       const std::array<std::array<double, 4>, 4>& S,
                                       EffortJetField field_jet) {
  const auto structure = internal::phnn_s_jet_structure(S);
  if (structure == internal::PhnnSJetStructure::kOther) {
    return op_by_op_jacobian_field(l_h, std::move(field_jet));
  }
  return [&l_h, &l_z, u, structure](const Tensor& x) {
    auto curvature = std::make_shared<TapedCurvature>(l_h, kTwoStateCurvature, x);
    const auto& e = curvature->effort;
    const auto w = internal::phnn_s_w_jet_forward(e.grad, e.hessian, u, structure);
    auto net_z = std::make_shared<TapedNet>(TapedNet{l_z, nullptr});
    const auto l = net_z->forward_jet(w.w, w.w_g);
    const auto jet =
        internal::phnn_s_field_jet_forward(e.grad, e.hessian, u, l.v, l.g, w, structure);
    TapedField t{jet.f, jet.g.transpose(-1, -2), {}};
    t.backward = [=](const Tensor& f_bar, const Tensor& dfdx_bar, bool /*input*/) {
      const Tensor g_bar = dfdx_bar.transpose(-1, -2);
      const auto first =
          internal::phnn_s_field_jet_backward_net(f_bar, g_bar, l.v, l.g, w, structure);
      const auto [x_bar, xg_bar] = net_z->backward_jet({first.l, first.l_g});
      const auto adj =
          internal::phnn_s_field_jet_backward_effort(f_bar, g_bar, first, x_bar, xg_bar, structure);
      curvature->backward(adj.effort, adj.effort_g);
      return Tensor();
    };
    return t;
  };
}

// PHNN-S: w = S_w (e, u), F = S-field(e, u, L_z(w), w). Backward: F~ ->
// (e~ A, l~, w~ B);  L_z (w~ C);  w~ = B + C -> the w head (e~ D);  e~ = A + D.
EffortFieldRecorder s_effort_field(const StackedMlp& l_z, const Tensor& u,
                                   const std::array<std::array<double, 4>, 4>& S) {
  const std::array<double, 3> s_w{S[2][0], S[2][1], S[2][3]};
  return [&l_z, u, S, s_w](const Tensor& effort, const Tensor& /*y*/) {
    auto net_z = std::make_shared<TapedNet>(TapedNet{l_z, nullptr});
    const Tensor w = internal::phnn_s_w_forward(effort, u, s_w);
    const Tensor l = net_z->forward(w, 0, 0).v;
    TapedEffortField t{internal::phnn_s_field_forward(effort, u, l, w, S), {}};
    t.backward = [=](const Tensor& f_bar, bool /*input*/) {
      const auto field = internal::phnn_s_field_backward(l, w, S, f_bar);
      const Tensor w_bar = field.w + net_z->backward({field.l}, true);
      const auto head = internal::phnn_s_w_backward(s_w, w_bar);
      return std::make_pair(field.effort + head.effort, Tensor());
    };
    return t;
  };
}

}  // namespace

torch::Tensor PhnnJr::explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                            const torch::Tensor& x_next, const torch::Tensor& u_in,
                                            double h, const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_explicit_mean_l1(integrator, *nets_[0], kTwoStateHead, x, x_next, h,
                             jr_effort_field(*nets_[1], u, J_),
                             jr_jacobian_field(*nets_[0], *nets_[1], u, J_), penalty);
}

torch::Tensor PhnnJr::dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                      const torch::Tensor& u_in, double h, double min_dx_norm,
                                      const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_dg_mean_l1(*nets_[0], kTwoStateHead, x, x_next, h, min_dx_norm, dissipation_at_start(),
                       jr_effort_field(*nets_[1], u, J_),
                       jr_jacobian_field(*nets_[0], *nets_[1], u, J_), penalty);
}

// PHNN-S: with a penalty its first stage (RK2) or field at x (DG) is
// s_jacobian_field (field_from_effort's op-by-op jet for other structures).
torch::Tensor PhnnS::explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                           const torch::Tensor& x_next, const torch::Tensor& u,
                                           double h, const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const EffortJetField field_jet = [this, &u](const Jet& effort, const Tensor& y) {
    return field_from_effort(effort, y, u, /*order=*/1, /*dissipation_fixed=*/false);
  };
  const Tensor u_rows = rows_like(u, x);
  return ph_explicit_mean_l1(
      integrator, *nets_[0], kTwoStateHead, x, x_next, h, s_effort_field(*nets_[1], u_rows, S_),
      s_jacobian_field(*nets_[0], *nets_[1], u_rows, S_, field_jet), penalty);
}

torch::Tensor PhnnS::dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                     const torch::Tensor& u, double h, double min_dx_norm,
                                     const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const EffortJetField field_jet = [this, &u](const Jet& effort, const Tensor& y) {
    return field_from_effort(effort, y, u, /*order=*/1, /*dissipation_fixed=*/false);
  };
  const Tensor u_rows = rows_like(u, x);
  return ph_dg_mean_l1(*nets_[0], kTwoStateHead, x, x_next, h, min_dx_norm, false,
                       s_effort_field(*nets_[1], u_rows, S_),
                       s_jacobian_field(*nets_[0], *nets_[1], u_rows, S_, field_jet), penalty);
}

// NODE: f = MLP(y, u) (manual_step.h).
torch::Tensor Node::explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                          const torch::Tensor& x_next, const torch::Tensor& u_in,
                                          double h, const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  return node_explicit_mean_l1(integrator, *nets_[0], x, x_next, rows_like(u_in, x), h, penalty);
}

}  // namespace phnn
