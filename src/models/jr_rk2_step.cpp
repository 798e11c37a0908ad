// src/models/jr_rk2_step.cpp — the hand-written training step of the 2-state
// fused PHNN-JR with the explicit midpoint rule (RK2) and the mean-L1 loss:
// forward, loss and backward without an autograd graph, through the same
// kernels as the autograd path (fused_mlp_taped, the heads' taped forms) and
// with the same operations in the same order, so the gradients are bitwise
// those of loss.sum().backward() (tests/models/jr_rk2_step_test.cpp).
// Touches only the model's flat gradient buffer (the networks' sinks).
//
// Forward (per member, batch rows b, h the step):
//   k1 = f(x),  x2 = x + (h/2) k1,  k2 = f(x2),  x^ = x + h k2,
//   L = (sum_{b,i} |(x_next - x^)_bi / h|) / N              (N = 2 B)
// with f(y) = F(gradH(y), L_R(y, u), u) (jr_field_head), gradH from L_H's
// first-order jet (hamiltonian_head). Backward, as autograd takes it:
//   x^~ = -(((1 / N) sgn(.)) / h),  k2~ = x^~ h,
//   stage 2: F~ -> L_R (its input adjoint c), gradH~ -> hamiltonian head (its
//   x adjoint b) -> L_H (its input adjoint a);  x2~ = (c + b) + a   (the order
//   autograd's engine accumulates them in: later-created nodes run first),
//   k1~ = x2~ (h/2),  stage 1: the same without input adjoints.
// Parameter gradients are added stage 2 first, then stage 1, as autograd does.
#include <memory>

#include "models/fused_heads.h"
#include "models/fused_mlp.h"
#include "phnn/models/port_hamiltonian.h"

namespace phnn {
namespace {

using torch::Tensor;

// What one field evaluation keeps for its backward.
struct FieldTape {
  std::shared_ptr<internal::FusedMlpTape> l_h, l_r;
  internal::HamiltonianTape hamiltonian;
  Tensor effort, o_r, f;  // gradH [E, B, 2], L_R outputs [E, B, 6], f [E, B, 2]
};

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

}  // namespace

torch::Tensor PhnnJr::rk2_mean_l1_step(const torch::Tensor& x_in, const torch::Tensor& x_next_in,
                                       const torch::Tensor& u_in, double h) const {
  const StackedMlp &l_h = *nets_[0], &l_r = *nets_[1];
  if (!l_h.options().fused || options().dtype != torch::kFloat64 || l_h.gradient_sinks().empty()) {
    return {};
  }
  torch::NoGradGuard no_grad;
  const int64_t E = x_in.size(0), B = x_in.size(1);
  const Tensor x = x_in.contiguous(), x_next = x_next_in.contiguous();
  const Tensor u = u_in.expand({E, B, 1}).contiguous();
  const auto field = [&](const Tensor& y) {
    FieldTape t;
    const auto o_h = internal::fused_mlp_taped(l_h.weights(), l_h.biases(), y, {2, 1}, &t.l_h);
    t.effort = internal::hamiltonian_head_taped(o_h.v, o_h.g, y, &t.hamiltonian).grad;
    t.o_r = internal::fused_mlp_taped(l_r.weights(), l_r.biases(), cat_rows(y, u), {0, 0}, &t.l_r).v;
    t.f = internal::jr_field_forward(t.effort, t.o_r, u, J_);
    return t;
  };
  const FieldTape s1 = field(x);
  const Tensor x2 = add_scaled(x, 0.5 * h, s1.f);
  const FieldTape s2 = field(x2);
  const Tensor x_hat = add_scaled(x, h, s2.f);

  // The loss and x^~, per member over its 2 B components in row-major order.
  const int64_t n = 2 * B;
  const double count = static_cast<double>(n), seed = 1.0 / count;
  Tensor loss = torch::empty({E}, x.options()), k2_bar = torch::empty_like(x);
  const double *pn = x_next.data_ptr<double>(), *ph = x_hat.data_ptr<double>();
  double *pl = loss.data_ptr<double>(), *pk = k2_bar.data_ptr<double>();
  for (int64_t e = 0; e < E; ++e) {
    double sum = 0.0;
    for (int64_t k = e * n; k < (e + 1) * n; ++k) {
      const double scaled = (pn[k] - ph[k]) / h;
      sum += std::fabs(scaled);
      const double sign = static_cast<double>((0.0 < scaled) - (scaled < 0.0));
      pk[k] = (-((seed * sign) / h)) * h;
    }
    pl[e] = sum / count;
  }

  // Stage 2, with the adjoint of its input x2.
  const auto back = [&](const FieldTape& t, const Tensor& f_bar, bool input) {
    const auto jr = internal::jr_field_backward(t.effort, t.o_r, u, J_, f_bar);
    const Tensor c = internal::fused_mlp_taped_backward(*t.l_r, l_r.weights(), l_r.gradient_sinks(),
                                                        {jr.o}, input);
    const auto ham = internal::hamiltonian_head_backward(t.hamiltonian, Tensor(), jr.effort);
    const Tensor a = internal::fused_mlp_taped_backward(*t.l_h, l_h.weights(), l_h.gradient_sinks(),
                                                        {ham.o, ham.o_g}, input);
    return input ? (c.narrow(-1, 0, 2) + ham.x) + a : Tensor();
  };
  const Tensor x2_bar = back(s2, k2_bar, true);
  back(s1, x2_bar * (0.5 * h), false);
  return loss;
}

}  // namespace phnn
