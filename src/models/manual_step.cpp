// src/models/manual_step.cpp — the shared parts of the hand-written training
// steps (models/manual_step.h): the mean-L1 loss, RK2 and DG around field
// recorders, the PH models' gradient (reverse mode) and DG around the
// Hamiltonian head, and NODE's RK2 step. Forward, loss and backward run
// without an autograd graph, through the same kernels as the autograd path
// (fused_mlp_taped, the heads' taped forms) with the same operations in the
// same order, so NODE's loss and gradients are bitwise those of
// loss.sum().backward() and the PH models' equal them to round-off (gradH by
// a vector-Jacobian product of L_H, fused_mlp_gradient.h, where autograd
// propagates L_H's forward-mode jet; tests/models/manual_step_test.cpp,
// general_manual_step_test.cpp).
// Touches only the models' gradient sinks (their flat gradient buffer).
//
// Forward (per member, batch rows b, h the step):
//   k1 = f(x),  x2 = x + (h/2) k1,  k2 = f(x2),  x^ = x + h k2,
//   L = (sum_{b,i} |(x_next - x^)_bi / h|) / N              (N = n_x B)
// Backward, as autograd's engine takes it (of the nodes ready at once, the
// one created last runs first, and an adjoint that several nodes feed is
// summed in that order):
//   x^~ = -(((1 / N) sgn(.)) / h),  k2~ = x^~ h,  stage 2 backward -> x2~,
//   k1~ = x2~ (h/2),  stage 1 backward (no input adjoint: x is data).
// Parameter gradients are added stage 2 first, then stage 1.
// DG: x^ = x + h F(dg(x, dx), m), dx = x_next - x, m = x + dx/2 (or x), with
// dg from H at the ends x, x + dx (one order-0 L_H call on both) and gradH(m)
// (gonzalez_forward); backward F~ -> dg~ -> gradH(m)'s networks first,
// then the ends' (the same order autograd takes); no input adjoints.
// DG4 (ph_dg4_mean_l1): the same around the AVF effort, the Hessian at m
// and the field's order-2 jet (dg4_jet_heads.h).
// With a Jacobian regularizer: L += P(df/dx at x), P and its adjoint from
// the trainer (JacobianPenalty); stage 1 of RK2 is then the model's order-1
// jet of the field at x, whose backward takes f~ and dfdx~ at once; in DG
// the field at x is created first, so its backward runs last.
#include "models/manual_step.h"

#include <cmath>

#include "models/dg4_jet_heads.h"
#include "models/general_heads.h"
#include "models/general_jet_heads.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {
namespace manual {
namespace {

// L = (sum_{b,i} |(x_next - x^)_bi / h|) / N per member [E], and in *f_bar
// the adjoint of f in x^ = x + scale f: x^~ scale (file comment).
Tensor mean_l1_loss(const Tensor& x_next, const Tensor& x_hat, double h, double scale,
                    Tensor* f_bar) {
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
      pk[k] = (-((seed * sign) / h)) * scale;
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

}  // namespace

Tensor cat_rows(const Tensor& x, const Tensor& u) {
  const int64_t rows = x.size(0) * x.size(1), n = x.size(2), k = u.size(2), w = n + k;
  Tensor out = torch::empty({x.size(0), x.size(1), w}, x.options());
  const double *px = x.data_ptr<double>(), *pu = u.data_ptr<double>();
  double* po = out.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    for (int64_t i = 0; i < n; ++i) po[w * r + i] = px[n * r + i];
    for (int64_t j = 0; j < k; ++j) po[w * r + n + j] = pu[k * r + j];
  }
  return out;
}

Tensor add_scaled(const Tensor& a, double c, const Tensor& b) {
  Tensor out = torch::empty_like(a);
  const double *pa = a.data_ptr<double>(), *pb = b.data_ptr<double>();
  double* po = out.data_ptr<double>();
  for (int64_t k = 0; k < a.numel(); ++k) po[k] = pa[k] + c * pb[k];
  return out;
}

bool has_manual_step(const std::vector<std::unique_ptr<StackedMlp>>& nets,
                     torch::ScalarType dtype) {
  for (const auto& net : nets) {
    if (!net->options().fused || net->gradient_sinks().empty()) return false;
  }
  return dtype == torch::kFloat64;
}

FusedMlpJet TapedNet::forward(const Tensor& y, int directions, int order) {
  vjp_tape = nullptr;  // a product belongs to the value pass it was taken on
  return fused_mlp_taped(net.weights(), net.biases(), y, {directions, order}, &tape);
}

Tensor TapedNet::backward(const std::vector<Tensor>& grads, bool input) const {
  return fused_mlp_taped_backward(*tape, net.weights(), net.gradient_sinks(), grads, input);
}

Tensor TapedNet::vjp(const Tensor& c) {
  return fused_mlp_taped_vjp(*tape, net.weights(), c, &vjp_tape);
}

Tensor TapedNet::vjp_backward(const Tensor& s_bar) const {
  return fused_mlp_taped_vjp_backward(*vjp_tape, *tape, net.weights(), net.gradient_sinks(), s_bar);
}

Tensor TapedNet::backward_after_vjp(const Tensor& v_bar, bool input) const {
  return fused_mlp_vjp_value_backward(*vjp_tape, *tape, net.weights(), net.gradient_sinks(), v_bar,
                                      input);
}

TapedGradient::TapedGradient(const StackedMlp& net, const Tensor& y) : l_h{net, nullptr} {
  const auto head_out = general_hamiltonian_cotangent(l_h.forward(y, 0, 0).v, y, &head);
  h = head_out.h;
  grad = head_out.l_t_v + l_h.vjp(head_out.c);
}

Tensor TapedGradient::backward(const Tensor& grad_bar, bool input, const Tensor& c) const {
  const Tensor c_bar = l_h.vjp_backward(grad_bar);
  const auto adj = general_hamiltonian_cotangent_backward(head, Tensor(), grad_bar, c_bar);
  const Tensor a = l_h.backward_after_vjp(adj.o, input);
  if (!input) return Tensor();
  return (c.defined() ? c + adj.x : adj.x) + a;
}

FusedMlpJet TapedNet::forward_jet(const Tensor& v, const Tensor& g, int order) {
  const int directions = static_cast<int>(g.size(-2));
  return fused_mlp_taped(net.weights(), net.biases(), v, {directions, order}, &tape, g);
}

std::pair<Tensor, Tensor> TapedNet::backward_jet(const std::vector<Tensor>& grads) const {
  return fused_mlp_taped_jet_backward(*tape, net.weights(), net.gradient_sinks(), grads);
}

TapedCurvature::TapedCurvature(const StackedMlp& net, const Tensor& x) : l_h{net, nullptr} {
  const int n = static_cast<int>(x.size(-1));
  const auto o = l_h.forward(x, n, 2);
  effort = general_curvature_forward(o.v, o.g, o.h, x, &head);
}

void TapedCurvature::backward(const Tensor& grad_bar, const Tensor& hessian_bar) const {
  const auto c = general_curvature_backward(head, grad_bar, hessian_bar);
  l_h.backward({c.o, c.o_g, c.o_h}, false);
}

namespace {

// H at a step's ends x and x + dx from one order-0 L_H call, kept for the
// backward from (H0~, H1~).
struct TapedEnds {
  TapedNet net;
  HamiltonianTape head;
  Tensor h0, h1;
  TapedEnds(const StackedMlp& l_h, const Tensor& x, const Tensor& dx) : net{l_h, nullptr} {
    const int64_t B = x.size(1);
    const Tensor ends = torch::cat({x, add_scaled(x, 1.0, dx)}, /*dim=*/1);
    const Tensor h = general_hamiltonian_forward(net.forward(ends, 0, 0).v, Tensor(), ends, &head).h;
    h0 = h.narrow(1, 0, B), h1 = h.narrow(1, B, B);
  }
  void backward(const Tensor& h0_bar, const Tensor& h1_bar) const {
    // Two narrow adjoints summed over zeros (-0 becomes +0), as autograd's.
    const Tensor h_bar = torch::cat({h0_bar, h1_bar}, /*dim=*/1) + 0.0;
    net.backward({general_hamiltonian_backward(head, h_bar, Tensor()).o}, false);
  }
};

// The RK2 step, its loss (+ the penalty of df/dx at x) and backward (file comment).
Tensor rk2_mean_l1(const Tensor& x, const Tensor& x_next, double h, const FieldRecorder& field,
                   const JacobianPenalty& penalty) {
  const TapedField s1 = field(x, static_cast<bool>(penalty));
  const TapedField s2 = field(add_scaled(x, 0.5 * h, s1.f), false);
  Tensor k2_bar, dfdx_bar;
  const Tensor loss = add_penalty(mean_l1_loss(x_next, add_scaled(x, h, s2.f), h, h, &k2_bar),
                                  penalty, s1.dfdx, &dfdx_bar);
  const Tensor x2_bar = s2.backward(k2_bar, Tensor(), true);
  s1.backward(x2_bar * (0.5 * h), dfdx_bar, false);
  return loss;
}

// The RK4 step (discrete_step.cpp's rk4_step):
//   k1 = f(x), k2 = f(x + (h/2) k1), k3 = f(x + (h/2) k2), k4 = f(x + h k3),
//   c = ((k1 + 2 k2) + 2 k3) + k4,  x^ = x + (h/6) c,
// its loss (+ the penalty of df/dx at x) and backward, autograd's order:
//   c~ = x^~ (h/6);  k4~ = c~;  stage 4 -> y4~;  k3~ = 2 c~ + h y4~;  stage 3
//   -> y3~;  k2~ = 2 c~ + (h/2) y3~;  stage 2 -> y2~;  k1~ = c~ + (h/2) y2~;
//   stage 1. Each k has two consumers, so each sum has two terms and its
//   order does not matter; the stages add their parameter gradients 4, 3, 2, 1.
Tensor rk4_mean_l1(const Tensor& x, const Tensor& x_next, double h, const FieldRecorder& field,
                   const JacobianPenalty& penalty) {
  const TapedField s1 = field(x, static_cast<bool>(penalty));
  const TapedField s2 = field(add_scaled(x, 0.5 * h, s1.f), false);
  const TapedField s3 = field(add_scaled(x, 0.5 * h, s2.f), false);
  const TapedField s4 = field(add_scaled(x, h, s3.f), false);
  const Tensor c = ((s1.f + s2.f * 2.0) + s3.f * 2.0) + s4.f;
  Tensor c_bar, dfdx_bar;
  const Tensor loss =
      add_penalty(mean_l1_loss(x_next, add_scaled(x, h / 6.0, c), h, h / 6.0, &c_bar), penalty,
                  s1.dfdx, &dfdx_bar);
  const Tensor y4_bar = s4.backward(c_bar, Tensor(), true);
  const Tensor y3_bar = s3.backward(c_bar * 2.0 + y4_bar * h, Tensor(), true);
  const Tensor y2_bar = s2.backward(c_bar * 2.0 + y3_bar * (0.5 * h), Tensor(), true);
  s1.backward(c_bar + y2_bar * (0.5 * h), dfdx_bar, false);
  return loss;
}

}  // namespace

Tensor explicit_mean_l1(IntegratorKind integrator, const Tensor& x_in, const Tensor& x_next_in,
                        double h, const FieldRecorder& field, const JacobianPenalty& penalty) {
  const Tensor x = x_in.contiguous(), x_next = x_next_in.contiguous();
  PHNN_CHECK(integrator == IntegratorKind::kRk2 || integrator == IntegratorKind::kRk4,
             "explicit_mean_l1: " << to_string(integrator) << " is not explicit");
  return integrator == IntegratorKind::kRk2 ? rk2_mean_l1(x, x_next, h, field, penalty)
                                            : rk4_mean_l1(x, x_next, h, field, penalty);
}

Tensor ph_explicit_mean_l1(IntegratorKind integrator, const StackedMlp& l_h,
                           const Tensor& x, const Tensor& x_next,
                           double h, const EffortFieldRecorder& effort_field,
                           const JacobianFieldRecorder& jacobian_field,
                           const JacobianPenalty& penalty) {
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
  return explicit_mean_l1(integrator, x, x_next, h, field, penalty);
}

// The DG step of a PH model, its loss (+ the penalty of df/dx at x) and
// backward (file comment); the field at x, created first, goes back last.
Tensor ph_dg_mean_l1(const StackedMlp& l_h, const Tensor& x_in,
                     const Tensor& x_next_in, double h, double min_dx_norm,
                     bool dissipation_at_start, const EffortFieldRecorder& effort_field,
                     const JacobianFieldRecorder& jacobian_field, const JacobianPenalty& penalty) {
  const Tensor x = x_in.contiguous(), x_next = x_next_in.contiguous();
  const TapedField at_x = penalty ? jacobian_field(x) : TapedField{};
  const Tensor dx = x_next - x, m = add_scaled(x, 0.5, dx);
  const TapedEnds ends(l_h, x, dx);
  const TapedGradient mid(l_h, m);
  const Tensor effort = gonzalez_forward(ends.h0, ends.h1, mid.grad, dx, min_dx_norm);
  const TapedEffortField field = effort_field(effort, dissipation_at_start ? x : m);
  Tensor f_bar, dfdx_bar;
  const Tensor loss = add_penalty(mean_l1_loss(x_next, add_scaled(x, h, field.f), h, h, &f_bar),
                                  penalty, at_x.dfdx, &dfdx_bar);
  const auto g = gonzalez_backward(ends.h0, ends.h1, mid.grad, dx, min_dx_norm,
                                   field.backward(f_bar, false).first);
  mid.backward(g.grad, false);
  ends.backward(g.h0, g.h1);
  if (penalty) at_x.backward(Tensor(), dfdx_bar, false);
  return loss;
}

// The DG4 step, port_hamiltonian.cpp's discrete_gradient4_field without a
// graph (docs/METHOD.md "DG4: a fourth-order discrete gradient"):
//   g = (5/18) gradH(x + c1 dx) + (8/18) gradH(m) + (5/18) gradH(x + c3 dx),
//       c1,3 = 1/2 -+ sqrt(15)/10 (3-point Gauss-Legendre on [0, 1]),
//   e = g + (H(x + dx) - H(x) - g.dx) / |dx|^2 dx  (= g below min_dx_norm),
//   Q = the Hessian of H at m,  phi(s) = F(m + s, e + Q s) to order 2,
//   f4 = v + h^2 (phi''[v, v] / 24 - A A v / 12),  x^ = x + h f4.
// Backward: the correction (-> phi~), phi (-> e~, Q~), the curvature from
// Q~, the projection (-> g~, H0~, H1~), the Gauss points from the weighted
// g~, the ends; the field at x (penalty), created first, last.
Tensor ph_dg4_mean_l1(const StackedMlp& l_h, const Tensor& x_in, const Tensor& x_next_in, double h,
                      double min_dx_norm, const EffortJet2Recorder& field_jet,
                      const JacobianFieldRecorder& jacobian_field, const JacobianPenalty& penalty) {
  const Tensor x = x_in.contiguous(), x_next = x_next_in.contiguous();
  const TapedField at_x = penalty ? jacobian_field(x) : TapedField{};
  const int64_t B = x.size(1);
  const double c = std::sqrt(15.0) / 10.0, w_end = 5.0 / 18.0, w_mid = 8.0 / 18.0;
  const Tensor dx = x_next - x, m = add_scaled(x, 0.5, dx);
  const TapedEnds ends(l_h, x, dx);
  const TapedGradient gauss(
      l_h, torch::cat({add_scaled(x, 0.5 - c, dx), m, add_scaled(x, 0.5 + c, dx)}, /*dim=*/1));
  const Tensor g = (gauss.grad.narrow(1, 0, B) * w_end + gauss.grad.narrow(1, B, B) * w_mid) +
                   gauss.grad.narrow(1, 2 * B, B) * w_end;
  const Tensor effort = gonzalez_forward(ends.h0, ends.h1, g, dx, min_dx_norm);
  const TapedCurvature curvature(l_h, m);
  const TapedFieldJet2 phi = field_jet(effort, curvature.effort.hessian, m);
  const FieldJet2 jet{phi.f, phi.g, phi.h};
  Tensor f_bar, dfdx_bar;
  const Tensor x_hat = add_scaled(x, h, dg4_correction_forward(jet, h));
  const Tensor loss =
      add_penalty(mean_l1_loss(x_next, x_hat, h, h, &f_bar), penalty, at_x.dfdx, &dfdx_bar);
  const FieldJet2 jet_bar = dg4_correction_backward(jet, h, f_bar);
  const auto [e_bar, q_bar] = phi.backward(jet_bar.f, jet_bar.g, jet_bar.h);
  curvature.backward(Tensor(), q_bar);
  const auto adj = gonzalez_backward(ends.h0, ends.h1, g, dx, min_dx_norm, e_bar);
  gauss.backward(torch::cat({adj.grad * w_end, adj.grad * w_mid, adj.grad * w_end}, /*dim=*/1),
                 false);
  ends.backward(adj.h0, adj.h1);
  if (penalty) at_x.backward(Tensor(), dfdx_bar, false);
  return loss;
}

Tensor node_explicit_mean_l1(IntegratorKind integrator, const StackedMlp& mlp, const Tensor& x,
                             const Tensor& x_next, const Tensor& u, double h,
                             const JacobianPenalty& penalty) {
  const int n_x = static_cast<int>(x.size(-1));
  const FieldRecorder field = [&](const Tensor& y, bool jacobian) {
    auto net = std::make_shared<TapedNet>(TapedNet{mlp, nullptr});
    const auto out = net->forward(cat_rows(y, u), jacobian ? n_x : 0, jacobian ? 1 : 0);
    TapedField t{out.v, jacobian ? out.g.transpose(-1, -2) : Tensor(), {}};
    t.backward = [=](const Tensor& f_bar, const Tensor& dfdx_bar, bool input) {
      std::vector<Tensor> grads{f_bar};
      if (dfdx_bar.defined()) grads.push_back(dfdx_bar.transpose(-1, -2).contiguous());
      const Tensor c = net->backward(grads, input);
      return input ? c.narrow(-1, 0, n_x) : Tensor();
    };
    return t;
  };
  return explicit_mean_l1(integrator, x, x_next, h, field, penalty);
}

}  // namespace manual
}  // namespace internal
}  // namespace phnn
