// src/models/manual_step.cpp — hand-written training steps with the mean-L1
// loss on fused float64 networks: the explicit midpoint (RK2) step for the
// 2-state NODE, PHNN-S and PHNN-JR, and the discrete-gradient (DG) step for
// PHNN-S and PHNN-JR. Forward, loss and backward run without
// an autograd graph, through the same kernels as the autograd path
// (fused_mlp_taped, the heads' taped forms) with the same operations in the
// same order, so loss and gradients are bitwise those of
// loss.sum().backward() (tests/models/manual_step_test.cpp).
// Touches only the models' gradient sinks (their flat gradient buffer).
// Size: one file, as every step composes the same tapes in autograd's order (the
// bitwise contract the tests pin); splitting it would put the tapes in a header.
//
// Forward (per member, batch rows b, h the step):
//   k1 = f(x),  x2 = x + (h/2) k1,  k2 = f(x2),  x^ = x + h k2,
//   L = (sum_{b,i} |(x_next - x^)_bi / h|) / N              (N = 2 B)
// Backward, as autograd's engine takes it (of the nodes ready at once, the
// one created last runs first, and an adjoint that several nodes feed is
// summed in that order):
//   x^~ = -(((1 / N) sgn(.)) / h),  k2~ = x^~ h,  stage 2 backward -> x2~,
//   k1~ = x2~ (h/2),  stage 1 backward (no input adjoint: x is data).
// Parameter gradients are added stage 2 first, then stage 1.
// DG: x^ = x + h F(dg(x, dx), m), dx = x_next - x, m = x + dx/2 (or x), with
// dg from H at the ends x, x + dx (one order-0 L_H call on both) and gradH(m)
// (general_gonzalez_head); backward F~ -> dg~ -> gradH(m)'s networks first,
// then the ends' (the same order autograd takes); no input adjoints.
// With a Jacobian regularizer: L += P(df/dx at x), P and its adjoint from
// the trainer (JacobianPenalty); stage 1 of RK2 is then the order-1 jet of
// the field at x (PHNN-JR: L_H's order-2 jet, the curvature and JR jet
// heads; PHNN-S: the curvature, L_z's jet and the PHNN-S jet head, or for
// a structure other than the paper's its op-by-op field jet on a small
// autograd graph), whose backward takes f~ and dfdx~ at once; in DG the
// field at x is created first, so its backward runs last.
#include <cmath>
#include <functional>
#include <memory>

#include "models/fused_heads.h"
#include "models/fused_heads_common.h"
#include "models/fused_mlp.h"
#include "models/general_heads.h"
#include "phnn/models/port_hamiltonian.h"

namespace phnn {
namespace {

using internal::heads::rows_like;
using torch::Tensor;

// One field evaluation f(y) (with df/dx if asked for) and its backward: adds
// the parameter gradients of f~ . f + dfdx~ . df/dx into the sinks and returns
// y~ if `input` (else undefined; dfdx~ undefined = 0).
struct TapedField {
  Tensor f, dfdx;
  std::function<Tensor(const Tensor& f_bar, const Tensor& dfdx_bar, bool input)> backward;
};
using FieldRecorder = std::function<TapedField(const Tensor& y, bool jacobian)>;

// [x, u] along the last dimension (x [E, B, 2], u [E, B, 1], both dense).
Tensor cat_rows(const Tensor& x, const Tensor& u) {
  const int64_t rows = x.size(0) * x.size(1);
  Tensor out = torch::empty({x.size(0), x.size(1), 3}, x.options());
  const double *px = x.data_ptr<double>(), *pu = u.data_ptr<double>();
  double* po = out.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    po[3 * r] = px[2 * r], po[3 * r + 1] = px[2 * r + 1], po[3 * r + 2] = pu[r];
  }
  return out;
}

// out = a + c b, elementwise (two roundings: the build does not contract).
Tensor add_scaled(const Tensor& a, double c, const Tensor& b) {
  Tensor out = torch::empty_like(a);
  const double *pa = a.data_ptr<double>(), *pb = b.data_ptr<double>();
  double* po = out.data_ptr<double>();
  for (int64_t k = 0; k < a.numel(); ++k) po[k] = pa[k] + c * pb[k];
  return out;
}

// L = (sum_{b,i} |(x_next - x^)_bi / h|) / N per member [E], and in *f_bar
// the adjoint of f in x^ = x + h f: x^~ h (file comment).
Tensor mean_l1_loss(const Tensor& x_next, const Tensor& x_hat, double h, Tensor* f_bar) {
  const int64_t E = x_hat.size(0), n = x_hat.size(1) * x_hat.size(2);
  const double count = static_cast<double>(n), seed = 1.0 / count;
  Tensor loss = torch::empty({E}, x_hat.options());
  *f_bar = torch::empty_like(x_hat);
  const double *pn = x_next.data_ptr<double>(), *ph = x_hat.data_ptr<double>();
  double *pl = loss.data_ptr<double>(), *pk = f_bar->data_ptr<double>();
  for (int64_t e = 0; e < E; ++e) {
    double sum = 0.0;  // ordered_sum: row-major, left to right
    for (int64_t k = e * n; k < (e + 1) * n; ++k) {
      const double scaled = (pn[k] - ph[k]) / h;
      sum += std::fabs(scaled);
      const double sign = static_cast<double>((0.0 < scaled) - (scaled < 0.0));
      pk[k] = (-((seed * sign) / h)) * h;
    }
    pl[e] = sum / count;
  }
  return loss;
}

// L + the penalty of df/dx (if any), with dfdx~ in *dfdx_bar.
Tensor add_penalty(const Tensor& loss, const JacobianPenalty& penalty, const Tensor& dfdx,
                   Tensor* dfdx_bar) {
  return penalty ? loss + penalty(dfdx, dfdx_bar) : loss;
}

// The RK2 step, its loss (+ the penalty of df/dx at x) and backward (file comment).
Tensor rk2_mean_l1(const Tensor& x_in, const Tensor& x_next_in, double h,
                   const FieldRecorder& field, const JacobianPenalty& penalty) {
  const Tensor x = x_in.contiguous(), x_next = x_next_in.contiguous();
  const TapedField s1 = field(x, static_cast<bool>(penalty));
  const TapedField s2 = field(add_scaled(x, 0.5 * h, s1.f), false);
  Tensor k2_bar, dfdx_bar;
  const Tensor loss = add_penalty(mean_l1_loss(x_next, add_scaled(x, h, s2.f), h, &k2_bar), penalty,
                                  s1.dfdx, &dfdx_bar);
  const Tensor x2_bar = s2.backward(k2_bar, Tensor(), true);
  s1.backward(x2_bar * (0.5 * h), dfdx_bar, false);
  return loss;
}

// The networks a hand-written step can use: fused float64, bound to the flat buffers.
bool has_manual_step(const std::vector<std::unique_ptr<StackedMlp>>& nets,
                     torch::ScalarType dtype) {
  for (const auto& net : nets) {
    if (!net->options().fused || net->gradient_sinks().empty()) return false;
  }
  return dtype == torch::kFloat64;
}

// A network's taped forward and its backward (parameter gradients into its sinks).
struct TapedNet {
  const StackedMlp& net;
  std::shared_ptr<internal::FusedMlpTape> tape;
  internal::FusedMlpJet forward(const Tensor& y, int directions, int order) {
    return internal::fused_mlp_taped(net.weights(), net.biases(), y, {directions, order}, &tape);
  }
  Tensor backward(const std::vector<Tensor>& grads, bool input) const {
    return internal::fused_mlp_taped_backward(*tape, net.weights(), net.gradient_sinks(), grads,
                                              input);
  }
  // With an order-1 input jet (v, g [E, B, d, n]); backward -> (v~, g~).
  internal::FusedMlpJet forward_jet(const Tensor& v, const Tensor& g) {
    const int directions = static_cast<int>(g.size(-2));
    return internal::fused_mlp_taped(net.weights(), net.biases(), v, {directions, 1}, &tape, g);
  }
  std::pair<Tensor, Tensor> backward_jet(const std::vector<Tensor>& grads) const {
    return internal::fused_mlp_taped_jet_backward(*tape, net.weights(), net.gradient_sinks(),
                                                  grads);
  }
};

// gradH(y) from L_H's first-order jet, kept for its backward.
struct TapedGradient {
  TapedNet l_h;
  internal::HamiltonianTape head;
  Tensor grad;
  TapedGradient(const StackedMlp& net, const Tensor& y) : l_h{net, nullptr} {
    const auto o = l_h.forward(y, 2, 1);
    grad = internal::hamiltonian_head_taped(o.v, o.g, y, &head).grad;
  }
  // y~ = (c + the head's x adjoint b) + L_H's input adjoint a, autograd's
  // order; c (another node's adjoint of y, created after these) may be undefined.
  Tensor backward(const Tensor& grad_bar, bool input, const Tensor& c = Tensor()) const {
    const auto adj = internal::hamiltonian_head_backward(head, Tensor(), grad_bar);
    const Tensor a = l_h.backward({adj.o, adj.o_g}, input);
    if (!input) return Tensor();
    return (c.defined() ? c + adj.x : adj.x) + a;
  }
};

// A PH model's field from an effort e, with y the dissipation's point (PHNN-S
// ignores it): f, and the backward f~ -> (e~, y~ or undefined).
struct TapedEffortField {
  Tensor f;
  std::function<std::pair<Tensor, Tensor>(const Tensor& f_bar, bool input)> backward;
};
using EffortFieldRecorder = std::function<TapedEffortField(const Tensor& effort, const Tensor& y)>;

// A PH model's field with df/dx at a data point (no input adjoint), for a
// Jacobian penalty; empty where the model has none hand-written.
using JacobianFieldRecorder = std::function<TapedField(const Tensor& x)>;

// RK2 of a PH model: f(y) = F(gradH(y), y).
Tensor ph_rk2_mean_l1(const StackedMlp& l_h, const Tensor& x, const Tensor& x_next, double h,
                      const EffortFieldRecorder& effort_field,
                      const JacobianFieldRecorder& jacobian_field, const JacobianPenalty& penalty) {
  const FieldRecorder field = [&](const Tensor& y, bool jacobian) {
    if (jacobian) return jacobian_field(y);
    auto gradient = std::make_shared<TapedGradient>(l_h, y);
    const TapedEffortField effort = effort_field(gradient->grad, y);
    TapedField t{effort.f, Tensor(), {}};
    t.backward = [=](const Tensor& f_bar, const Tensor&, bool input) {
      const auto [effort_bar, y_bar] = effort.backward(f_bar, input);
      return gradient->backward(effort_bar, input, y_bar);
    };
    return t;
  };
  return rk2_mean_l1(x, x_next, h, field, penalty);
}

// The DG step of a PH model, its loss (+ the penalty of df/dx at x) and
// backward (file comment); the field at x, created first, goes back last.
Tensor ph_dg_mean_l1(const StackedMlp& l_h, const Tensor& x_in, const Tensor& x_next_in, double h,
                     double min_dx_norm, bool dissipation_at_start,
                     const EffortFieldRecorder& effort_field,
                     const JacobianFieldRecorder& jacobian_field, const JacobianPenalty& penalty) {
  const Tensor x = x_in.contiguous(), x_next = x_next_in.contiguous();
  const TapedField at_x = penalty ? jacobian_field(x) : TapedField{};
  const int64_t B = x.size(1);
  const Tensor dx = x_next - x, m = add_scaled(x, 0.5, dx);
  const Tensor ends = torch::cat({x, add_scaled(x, 1.0, dx)}, /*dim=*/1);
  TapedNet ends_net{l_h, nullptr};
  internal::HamiltonianTape ends_head;
  const Tensor h_ends =
      internal::hamiltonian_head_taped(ends_net.forward(ends, 0, 0).v, Tensor(), ends, &ends_head)
          .h;
  const TapedGradient mid(l_h, m);
  const Tensor h0 = h_ends.narrow(1, 0, B), h1 = h_ends.narrow(1, B, B);
  const Tensor effort = internal::gonzalez_forward(h0, h1, mid.grad, dx, min_dx_norm);
  const TapedEffortField field = effort_field(effort, dissipation_at_start ? x : m);
  Tensor f_bar, dfdx_bar;
  const Tensor loss = add_penalty(mean_l1_loss(x_next, add_scaled(x, h, field.f), h, &f_bar),
                                  penalty, at_x.dfdx, &dfdx_bar);
  const auto g = internal::gonzalez_backward(h0, h1, mid.grad, dx, min_dx_norm,
                                             field.backward(f_bar, false).first);
  mid.backward(g.grad, false);
  // The ends' adjoint is two narrow adjoints summed over zeros (-0 becomes +0).
  const Tensor h_ends_bar = torch::cat({g.h0, g.h1}, /*dim=*/1) + 0.0;
  const auto ends_adj = internal::hamiltonian_head_backward(ends_head, h_ends_bar, Tensor());
  ends_net.backward({ends_adj.o}, false);
  if (penalty) at_x.backward(Tensor(), dfdx_bar, false);
  return loss;
}

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

// gradH(x) and its Hessian from L_H's order-2 jet (the curvature head), kept
// for the backward from (gradH~, Hessian~): the head, then L_H.
struct TapedCurvature {
  TapedNet l_h;
  internal::CurvatureTape head;
  internal::HamiltonianCurvature effort;
  TapedCurvature(const StackedMlp& net, const Tensor& x) : l_h{net, nullptr} {
    const auto o = l_h.forward(x, 2, 2);
    effort = internal::hamiltonian_curvature_taped(o.v, o.g, o.h, x, &head);
  }
  void backward(const Tensor& grad_bar, const Tensor& hessian_bar) const {
    const auto c = internal::hamiltonian_curvature_backward(head, grad_bar, hessian_bar);
    l_h.backward({c.o, c.o_g, c.o_h}, false);
  }
};

// PHNN-JR's field and df/dx at x: the curvature (above), L_R's order-1 jet,
// the JR jet head. Backward, in autograd's order: the JR jet head, L_R, the
// curvature head, L_H.
JacobianFieldRecorder jr_jacobian_field(const StackedMlp& l_h, const StackedMlp& l_r,
                                        const Tensor& u,
                                        const std::array<std::array<double, 3>, 3>& J) {
  return [&l_h, &l_r, u, J](const Tensor& x) {
    auto curvature = std::make_shared<TapedCurvature>(l_h, x);
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
    auto curvature = std::make_shared<TapedCurvature>(l_h, x);
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
    auto curvature = std::make_shared<TapedCurvature>(l_h, x);
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
      const auto adj = internal::phnn_s_field_jet_backward_effort(f_bar, g_bar, first, x_bar,
                                                                  xg_bar, structure);
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

torch::Tensor PhnnJr::rk2_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                       const torch::Tensor& u_in, double h,
                                       const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_rk2_mean_l1(*nets_[0], x, x_next, h, jr_effort_field(*nets_[1], u, J_),
                        jr_jacobian_field(*nets_[0], *nets_[1], u, J_), penalty);
}

torch::Tensor PhnnJr::dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                      const torch::Tensor& u_in, double h, double min_dx_norm,
                                      const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_dg_mean_l1(*nets_[0], x, x_next, h, min_dx_norm, dissipation_at_start(),
                       jr_effort_field(*nets_[1], u, J_),
                       jr_jacobian_field(*nets_[0], *nets_[1], u, J_), penalty);
}

// PHNN-S: with a penalty its first stage (RK2) or field at x (DG) is
// s_jacobian_field (field_from_effort's op-by-op jet for other structures).
torch::Tensor PhnnS::rk2_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                      const torch::Tensor& u, double h,
                                      const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const EffortJetField field_jet = [this, &u](const Jet& effort, const Tensor& y) {
    return field_from_effort(effort, y, u, /*order=*/1, /*dissipation_fixed=*/false);
  };
  const Tensor u_rows = rows_like(u, x);
  return ph_rk2_mean_l1(*nets_[0], x, x_next, h, s_effort_field(*nets_[1], u_rows, S_),
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
  return ph_dg_mean_l1(*nets_[0], x, x_next, h, min_dx_norm, false,
                       s_effort_field(*nets_[1], u_rows, S_),
                       s_jacobian_field(*nets_[0], *nets_[1], u_rows, S_, field_jet), penalty);
}

// NODE: f = MLP(y, u) (with its order-1 jet in y for df/dx); y~ = the first
// two columns of the input adjoint.
torch::Tensor Node::rk2_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                     const torch::Tensor& u_in, double h,
                                     const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  const StackedMlp& mlp = *nets_[0];
  const FieldRecorder field = [&](const Tensor& y, bool jacobian) {
    auto net = std::make_shared<TapedNet>(TapedNet{mlp, nullptr});
    const auto out = net->forward(cat_rows(y, u), jacobian ? 2 : 0, jacobian ? 1 : 0);
    TapedField t{out.v, jacobian ? out.g.transpose(-1, -2) : Tensor(), {}};
    t.backward = [=](const Tensor& f_bar, const Tensor& dfdx_bar, bool input) {
      std::vector<Tensor> grads{f_bar};
      if (dfdx_bar.defined()) grads.push_back(dfdx_bar.transpose(-1, -2).contiguous());
      const Tensor c = net->backward(grads, input);
      return input ? c.narrow(-1, 0, 2) : Tensor();
    };
    return t;
  };
  return rk2_mean_l1(x, x_next, h, field, penalty);
}

}  // namespace phnn
