// src/models/general_manual_step.cpp — hand-written training steps of the
// n-dimensional NODE, PHNN-S and PHNN-JR (include/phnn/models/general_ph.h)
// on fused float64 networks: RK2 and RK4 for the three, DG and DG4 for the
// PH models (DG4's order-2 field jets: dg4_jet_heads.h), with
// the mean-L1 loss, with or without a Jacobian penalty. Forward, loss and
// backward run without an autograd graph through the n-state heads' taped
// forms (general_heads.h) in the order autograd takes the model's graph:
// NODE's loss and gradients are bitwise those of loss.sum().backward(); the
// PH models' equal them to round-off, since gradH is a vector-Jacobian
// product of L_H (manual_step.h's TapedGradient) where autograd's graph
// carries L_H's forward jet, and with a penalty the field jet at x runs
// through general_jet_heads.h (the curvature of H and the field jet heads)
// (tests/models/general_manual_step_test.cpp, manual_step_test.cpp,
// dg4_manual_step_test.cpp). The composition (RK2, RK4, DG, DG4, the loss)
// is models/manual_step.h's. Touches
// only the models' gradient sinks.
//
// Backward of one PH field evaluation f(y) = F(gradH(y), y), as autograd
// orders it (of the nodes ready at once, the one created last runs first):
//   PHNN-JR: F = [(J - L^T L) [e; u]]_{1:n_x}, L from L_R([y, u]):
//     the JR head (e~, o~) -> L_R (y~ c) -> the H head and L_H's product
//     and value passes (y~ b from the head, a from L_H);
//     y~ = (c + b) + a.
//   PHNN-S: w = [S_wx S_wu] [e; u], F = S_x [e; z(w); u], z from L_z(w):
//     the S head (e~ A, w~ B) -> L_z (w~ C) -> the w head from w~ = B + C
//     (e~ D); e~ = A + D. No ports: F = [S_xx S_xu] [e; u], one linear head.
#include <array>
#include <memory>

#include "models/dg4_jet_heads.h"
#include "models/fused_heads_common.h"
#include "models/general_heads.h"
#include "models/general_jet_heads.h"
#include "models/manual_step.h"
#include "phnn/models/general_ph.h"

namespace phnn {
namespace {

using internal::heads::rows_like;
using namespace internal::manual;
using torch::Tensor;

// PHNN-JR: F(e, y) = JR(e, L_R(y, u), u).
EffortFieldRecorder jr_effort_field(const StackedMlp& l_r, const Tensor& u,
                                    const std::vector<double>& J) {
  return [&l_r, u, &J](const Tensor& effort, const Tensor& y) {
    auto net_r = std::make_shared<TapedNet>(TapedNet{l_r, nullptr});
    const Tensor o_r = net_r->forward(cat_rows(y, u), 0, 0).v;
    TapedEffortField t{internal::general_jr_field_forward(effort, u, o_r, J), {}};
    const int64_t n_x = y.size(-1);
    t.backward = [=, &J](const Tensor& f_bar, bool input) {
      const auto jr = internal::general_jr_field_backward(effort, u, o_r, J, f_bar);
      const Tensor c = net_r->backward({jr.o}, input);
      return std::make_pair(jr.effort, input ? c.narrow(-1, 0, n_x) : Tensor());
    };
    return t;
  };
}

// PHNN-S without ports: F = [S_xx S_xu] [e; u].
EffortFieldRecorder linear_effort_field(const Tensor& u, const std::vector<double>& s_x_rows) {
  return [u, &s_x_rows](const Tensor& effort, const Tensor& /*y*/) {
    const int64_t n_x = effort.size(-1), n_u = u.size(-1);
    TapedEffortField t{internal::general_linear_forward(effort, u, s_x_rows, static_cast<int>(n_x)),
                       {}};
    t.backward = [=, &s_x_rows](const Tensor& f_bar, bool /*input*/) {
      const auto adj = internal::general_linear_backward(f_bar, s_x_rows, static_cast<int>(n_x),
                                                         static_cast<int>(n_u));
      return std::make_pair(adj.a, Tensor());
    };
    return t;
  };
}

// PHNN-S with n_w ports (file comment).
EffortFieldRecorder s_effort_field(const StackedMlp& l_z, const Tensor& u,
                                   const std::vector<double>& s_w_rows,
                                   const std::vector<double>& S, int n_w) {
  return [&l_z, u, &s_w_rows, &S, n_w](const Tensor& effort, const Tensor& /*y*/) {
    auto net_z = std::make_shared<TapedNet>(TapedNet{l_z, nullptr});
    const Tensor w = internal::general_linear_forward(effort, u, s_w_rows, n_w);
    const Tensor o = net_z->forward(w, 0, 0).v;
    TapedEffortField t{internal::general_s_field_forward(effort, u, o, w, S, n_w), {}};
    const int n_x = static_cast<int>(effort.size(-1)), n_u = static_cast<int>(u.size(-1));
    t.backward = [=, &s_w_rows, &S](const Tensor& f_bar, bool /*input*/) {
      const auto field = internal::general_s_field_backward(o, w, S, n_x, n_w, n_u, f_bar);
      const Tensor w_bar = field.w + net_z->backward({field.o}, true);
      const auto head = internal::general_linear_backward(w_bar, s_w_rows, n_x, n_u);
      return std::make_pair(field.e + head.a, Tensor());
    };
    return t;
  };
}

// PHNN-JR's field and df/dx at x: the curvature, L_R's order-1 jet in the
// n_x state directions, the JR jet head. Backward: the JR jet head, L_R,
// the curvature head, L_H.
JacobianFieldRecorder jr_jacobian_field(const StackedMlp& l_h, const StackedMlp& l_r,
                                        const Tensor& u, const std::vector<double>& J) {
  return [&l_h, &l_r, u, &J](const Tensor& x) {
    auto curvature = std::make_shared<TapedCurvature>(l_h, x);
    const auto& effort = curvature->effort;
    auto net_r = std::make_shared<TapedNet>(TapedNet{l_r, nullptr});
    const auto jet_r = net_r->forward(cat_rows(x, u), static_cast<int>(x.size(-1)), 1);
    const Tensor o = jet_r.v.contiguous(), o_g = jet_r.g.contiguous();
    const auto jet =
        internal::general_jr_field_jet_forward(effort.grad, effort.hessian, o, o_g, u, J);
    TapedField t{jet.f, jet.g.transpose(-1, -2), {}};
    t.backward = [=, &J](const Tensor& f_bar, const Tensor& dfdx_bar, bool /*input*/) {
      const auto jr = internal::general_jr_field_jet_backward(
          effort.grad, effort.hessian, o, o_g, u, J, f_bar, dfdx_bar.transpose(-1, -2));
      net_r->backward({jr.o, jr.o_g}, false);
      curvature->backward(jr.effort, jr.effort_g);
      return Tensor();
    };
    return t;
  };
}

// PHNN-S's field and df/dx at x: the curvature, the ports' jet, L_z's
// order-1 jet from it, the S jet head (no ports: the linear map [S_xx S_xu]
// as a port map of n_x rows). Backward: the S jet head, L_z, the port map,
// the curvature, L_H.
JacobianFieldRecorder s_jacobian_field(const StackedMlp& l_h, const StackedMlp* l_z,
                                       const Tensor& u, const std::vector<double>& s_w_rows,
                                       const std::vector<double>& s_x_rows,
                                       const std::vector<double>& S, int n_w) {
  return [&l_h, l_z, u, &s_w_rows, &s_x_rows, &S, n_w](const Tensor& x) {
    auto curvature = std::make_shared<TapedCurvature>(l_h, x);
    const auto& e = curvature->effort;
    const int n_x = static_cast<int>(x.size(-1)), n_u = static_cast<int>(u.size(-1));
    if (n_w == 0) {
      const auto f = internal::general_port_jet(e.grad, e.hessian, u, s_x_rows, n_x);
      TapedField t{f.w, f.w_g.transpose(-1, -2), {}};
      t.backward = [=, &s_x_rows](const Tensor& f_bar, const Tensor& dfdx_bar, bool /*input*/) {
        const Tensor fb = f_bar.defined() ? f_bar : torch::zeros_like(f.w);
        const auto adj =
            internal::general_port_jet_backward(fb, dfdx_bar.transpose(-1, -2), s_x_rows, n_x, n_u);
        curvature->backward(adj.e, adj.e_g);
        return Tensor();
      };
      return t;
    }
    const auto w = internal::general_port_jet(e.grad, e.hessian, u, s_w_rows, n_w);
    auto net_z = std::make_shared<TapedNet>(TapedNet{*l_z, nullptr});
    const auto l = net_z->forward_jet(w.w, w.w_g);
    const Tensor o = l.v.contiguous(), o_g = l.g.contiguous();
    const auto jet = internal::general_s_field_jet_forward(e.grad, e.hessian, u, o, o_g, w, S, n_w);
    TapedField t{jet.f, jet.g.transpose(-1, -2), {}};
    t.backward = [=, &s_w_rows, &S](const Tensor& f_bar, const Tensor& dfdx_bar, bool /*input*/) {
      const auto adj = internal::general_s_field_jet_backward(o, o_g, w, S, n_x, n_w, n_u, f_bar,
                                                              dfdx_bar.transpose(-1, -2));
      const auto [w_bar, w_g_bar] = net_z->backward_jet({adj.o, adj.o_g});
      const auto port =
          internal::general_port_jet_backward(adj.w + w_bar, adj.w_g + w_g_bar, s_w_rows, n_x, n_u);
      curvature->backward(adj.e + port.e, adj.e_g + port.e_g);
      return Tensor();
    };
    return t;
  };
}

// DG4: PHNN-JR's order-2 field jet phi(s) = F(y + s, e + Q s): L_R's
// order-2 jet of [y, u] in the n_x state directions, the JR jet head.
// Backward: the head, L_R.
EffortJet2Recorder jr_field_jet2(const StackedMlp& l_r, const Tensor& u,
                                 const std::vector<double>& J) {
  return [&l_r, u, &J](const Tensor& e, const Tensor& q, const Tensor& y) {
    auto net_r = std::make_shared<TapedNet>(TapedNet{l_r, nullptr});
    const auto o = net_r->forward(cat_rows(y, u), static_cast<int>(y.size(-1)), 2);
    const auto jet = internal::jr_field_jet2_forward(e, q, o.v, o.g, o.h, u, J);
    TapedFieldJet2 t{jet.f, jet.g, jet.h, {}};
    t.backward = [=, &J](const Tensor& f_bar, const Tensor& g_bar, const Tensor& h_bar) {
      const auto adj =
          internal::jr_field_jet2_backward(e, q, o.v, o.g, o.h, u, J, {f_bar, g_bar, h_bar});
      net_r->backward({adj.o, adj.o_g, adj.o_h}, false);
      return std::make_pair(adj.e, adj.e_g);
    };
    return t;
  };
}

// DG4: PHNN-S's order-2 field jet: the ports' jet (w = M [e; u], w_a = M_x
// Q_a, w_ab = 0), L_z's order-2 jet from it, the S jet head. Backward: the
// head, L_z (-> w~, w_g~), the port map. No ports: F = [S_xx S_xu] [e; u]
// as a port map of n_x rows, phi'' = 0.
EffortJet2Recorder s_field_jet2(const StackedMlp* l_z, const Tensor& u,
                                const std::vector<double>& s_w_rows,
                                const std::vector<double>& s_x_rows, const std::vector<double>& S,
                                int n_w) {
  return [l_z, u, &s_w_rows, &s_x_rows, &S, n_w](const Tensor& e, const Tensor& q, const Tensor&) {
    const int n_x = static_cast<int>(e.size(-1)), n_u = static_cast<int>(u.size(-1));
    if (n_w == 0) {
      const auto f = internal::general_port_jet(e, q, u, s_x_rows, n_x);
      TapedFieldJet2 t{f.w, f.w_g, torch::zeros({e.size(0), e.size(1), n_x, n_x, n_x}, e.options()),
                       {}};
      t.backward = [=, &s_x_rows](const Tensor& f_bar, const Tensor& g_bar, const Tensor&) {
        const auto adj = internal::general_port_jet_backward(f_bar, g_bar, s_x_rows, n_x, n_u);
        return std::make_pair(adj.e, adj.e_g);
      };
      return t;
    }
    const auto w = internal::general_port_jet(e, q, u, s_w_rows, n_w);
    auto net_z = std::make_shared<TapedNet>(TapedNet{*l_z, nullptr});
    const auto o = net_z->forward_jet(w.w, w.w_g, 2);
    const auto jet = internal::s_field_jet2_forward(e, q, u, o.v, o.g, o.h, w, S, n_w);
    TapedFieldJet2 t{jet.f, jet.g, jet.h, {}};
    t.backward = [=, &s_w_rows, &S](const Tensor& f_bar, const Tensor& g_bar, const Tensor& h_bar) {
      const auto adj = internal::s_field_jet2_backward(o.v, o.g, o.h, w, S, n_x, n_w, n_u,
                                                       {f_bar, g_bar, h_bar});
      const auto [w_bar, w_g_bar] = net_z->backward_jet({adj.o, adj.o_g, adj.o_h});
      const auto port =
          internal::general_port_jet_backward(adj.w + w_bar, adj.w_g + w_g_bar, s_w_rows, n_x, n_u);
      return std::make_pair(adj.e + port.e, adj.e_g + port.e_g);
    };
    return t;
  };
}

// PHNN-S's two recorders: the field from an effort (no ports: the linear
// map) and the field's jet at x.
struct SRecorders {
  EffortFieldRecorder field;
  JacobianFieldRecorder jacobian;
};
SRecorders s_recorders(const StackedMlp& l_h, const StackedMlp* l_z, const Tensor& u,
                       const std::vector<double>& s_w_rows, const std::vector<double>& s_x_rows,
                       const ModelStructure& s) {
  return {
      s.n_w == 0 ? linear_effort_field(u, s_x_rows) : s_effort_field(*l_z, u, s_w_rows, s.S, s.n_w),
      s_jacobian_field(l_h, l_z, u, s_w_rows, s_x_rows, s.S, s.n_w)};
}

}  // namespace

Tensor PhnnJr::explicit_mean_l1_step(IntegratorKind integrator, const Tensor& x,
                                            const Tensor& x_next, const Tensor& u_in, double h,
                                            const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_explicit_mean_l1(integrator, l_h(), x, x_next, h,
                             jr_effort_field(*nets_[1], u, structure().J),
                             jr_jacobian_field(l_h(), *nets_[1], u, structure().J), penalty);
}

Tensor PhnnJr::dg_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                      double h, double min_dx_norm,
                                      const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_dg_mean_l1(l_h(), x, x_next, h, min_dx_norm, dissipation_at_start(),
                       jr_effort_field(*nets_[1], u, structure().J),
                       jr_jacobian_field(l_h(), *nets_[1], u, structure().J), penalty);
}

Tensor PhnnS::explicit_mean_l1_step(IntegratorKind integrator, const Tensor& x,
                                           const Tensor& x_next, const Tensor& u_in, double h,
                                           const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  const SRecorders r = s_recorders(l_h(), nets_.size() > 1 ? nets_[1].get() : nullptr, u, s_w_rows_,
                                   s_x_rows_, structure());
  return ph_explicit_mean_l1(integrator, l_h(), x, x_next, h, r.field, r.jacobian,
                             penalty);
}

Tensor PhnnS::dg_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                     double h, double min_dx_norm,
                                     const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  const SRecorders r = s_recorders(l_h(), nets_.size() > 1 ? nets_[1].get() : nullptr, u, s_w_rows_,
                                   s_x_rows_, structure());
  return ph_dg_mean_l1(l_h(), x, x_next, h, min_dx_norm, false, r.field, r.jacobian,
                       penalty);
}

Tensor PhnnJr::dg4_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                double h, double min_dx_norm,
                                const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_dg4_mean_l1(l_h(), x, x_next, h, min_dx_norm,
                        jr_field_jet2(*nets_[1], u, structure().J),
                        jr_jacobian_field(l_h(), *nets_[1], u, structure().J), penalty);
}

Tensor PhnnS::dg4_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                               double h, double min_dx_norm,
                               const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  const StackedMlp* l_z = nets_.size() > 1 ? nets_[1].get() : nullptr;
  const ModelStructure& s = structure();
  return ph_dg4_mean_l1(l_h(), x, x_next, h, min_dx_norm,
                        s_field_jet2(l_z, u, s_w_rows_, s_x_rows_, s.S, s.n_w),
                        s_recorders(l_h(), l_z, u, s_w_rows_, s_x_rows_, s).jacobian, penalty);
}

// NODE: f = MLP([y, u]) (manual_step.h).
Tensor Node::explicit_mean_l1_step(IntegratorKind integrator, const Tensor& x,
                                          const Tensor& x_next, const Tensor& u_in, double h,
                                          const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  return node_explicit_mean_l1(integrator, *nets_[0], x, x_next, rows_like(u_in, x), h, penalty);
}

}  // namespace phnn
