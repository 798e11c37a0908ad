// src/models/fused_mlp_gradient.cpp — the reverse-mode input gradient of a
// taped fused tanh MLP and its backward (fused_mlp_gradient.h).
//
// The value pass (fused_mlp.cpp, order 0) keeps per layer l the input A_l
// [B, n_l] (A_0 = x, A_{l+1} = tanh(A_l W_l + b_l)); the output is
// v = A_{L-1} W_{L-1} + b_{L-1}. Per member, with c [B, n_L]:
//   S_{L-1} = c W_{L-1}^T,
//   U_{l-1} = S_l (.) (1 - A_l^2),  S_{l-1} = U_{l-1} W_{l-1}^T   (l = L-1 .. 1),
//   s = S_0 = J(x)^T c, row by row.
// Backward from s~ = S~_0 (S~_l is the forward tangent of A_l along s~):
//   for l = 1 .. L-1:  W~_{l-1} += S~_{l-1}^T U_{l-1},  U~ = S~_{l-1} W_{l-1},
//                      S~_l = U~ (.) (1 - A_l^2),
//                      A~_l += U~ (.) S_l (.) A_l (-2)      (left for the value pass)
//   W~_{L-1} += S~_{L-1}^T c,  c~ = S~_{L-1} W_{L-1}.
// The value pass's backward then runs from v~ with those A~_l added.
// No bias enters s, so the biases' gradients come from the value pass only.
#include "models/fused_mlp_gradient.h"

#include <algorithm>

#include "models/fused_mlp_plan.h"
#include "kernels/jet_kernels.h"

namespace phnn {
namespace internal {

using torch::Tensor;

struct FusedMlpVjpTape {
  const FusedMlpTape* value = nullptr;  // the value pass this product belongs to
  Tensor c;     // [E, B, n_L], dense
  Tensor work;  // S_l (l < L), U_l (l < L - 1), then the A~_l left by the backward (0 < l < L)
  std::vector<int64_t> s, u, extra;  // offsets into work
  bool backward_done = false;          // the A~_l are written
};

namespace {

// Dense float64 [E, B, n] with the expected sizes.
Tensor dense_rows(const Tensor& t, const Plan& p, int64_t n, const char* what) {
  TORCH_CHECK(t.dim() == 3 && t.size(0) == p.E && t.size(1) == p.B && t.size(2) == n &&
                  t.scalar_type() == torch::kFloat64,
              "fused_mlp_taped_vjp: ", what, " must be float64 [", p.E, ", ", p.B, ", ", n,
              "], got ", t.sizes());
  return t.contiguous();
}

// The offsets of one tape's buffers (struct comment).
std::shared_ptr<FusedMlpVjpTape> new_tape(const Plan& p, Tensor c) {
  auto t = std::make_shared<FusedMlpVjpTape>();
  t->c = std::move(c);
  const int64_t L = p.layers(), EB = p.E * p.B;
  int64_t total = 0;
  for (int64_t l = 0; l < L; ++l) t->s.push_back(total), total += EB * p.widths[l];
  for (int64_t l = 0; l + 1 < L; ++l) t->u.push_back(total), total += EB * p.widths[l + 1];
  t->extra.push_back(-1);
  for (int64_t l = 1; l < L; ++l) t->extra.push_back(total), total += EB * p.widths[l];
  t->work = reusable_buffer(total);
  return t;
}

int as_int(int64_t v) { return static_cast<int>(v); }

}  // namespace

Tensor fused_mlp_taped_vjp(const FusedMlpTape& tape, const std::vector<Tensor>& weights,
                           const Tensor& c_in, std::shared_ptr<FusedMlpVjpTape>* vjp) {
  const Plan& p = tape.plan;
  TORCH_CHECK(p.ch.order == 0, "fused_mlp_taped_vjp: needs an order-0 taped call");
  const int64_t L = p.layers(), E = p.E, B = p.B;
  auto t = new_tape(p, dense_rows(c_in, p, p.widths.back(), "the cotangent"));
  t->value = &tape;
  double* w = t->work.data_ptr<double>();
  const double* ws = tape.workspace.data_ptr<double>();
  gemm_nn(E, as_int(B), as_int(p.widths[L]), as_int(p.widths[L - 1]), t->c.data_ptr<double>(),
          weights[L - 1].data_ptr<double>(), w + t->s[L - 1], /*transpose_b=*/true);
  for (int64_t l = L - 1; l >= 1; --l) {
    const double* a = ws + p.act[l];  // A_l = tanh(Z_{l-1}): U_{l-1} is tanh's backward of S_l
    double* u = w + t->u[l - 1];
    tanh_jet_backward(0, 0, E, B * p.widths[l], a, a, w + t->s[l], u);
    gemm_nn(E, as_int(B), as_int(p.widths[l]), as_int(p.widths[l - 1]), u,
            weights[l - 1].data_ptr<double>(), w + t->s[l - 1], /*transpose_b=*/true);
  }
  Tensor out = torch::empty({E, B, p.widths[0]}, torch::kFloat64);
  std::copy(w + t->s[0], w + t->s[0] + E * B * p.widths[0], out.data_ptr<double>());
  *vjp = std::move(t);
  return out;
}

Tensor fused_mlp_taped_vjp_backward(FusedMlpVjpTape& vjp, const FusedMlpTape& tape,
                                    const std::vector<Tensor>& weights,
                                    const std::vector<Tensor>& gradient_sinks,
                                    const Tensor& s_bar_in) {
  const Plan& p = tape.plan;
  TORCH_CHECK(gradient_sinks.size() == 2 * weights.size(),
              "fused_mlp_taped_vjp_backward: expected one gradient sink per weight and bias");
  TORCH_CHECK(vjp.value == &tape && !vjp.backward_done,
              "fused_mlp_taped_vjp_backward: the product's tape belongs to another value pass, "
              "or its backward ran already");
  const int64_t L = p.layers(), E = p.E, B = p.B;
  const int64_t widest = *std::max_element(p.widths.begin(), p.widths.end());
  const Tensor s_bar = dense_rows(s_bar_in, p, p.widths[0], "the gradient's adjoint");
  Tensor scratch = reusable_buffer(2 * E * B * widest);
  double *sb = scratch.data_ptr<double>(), *ub = sb + E * B * widest;
  std::copy(s_bar.data_ptr<double>(), s_bar.data_ptr<double>() + s_bar.numel(), sb);
  double* w = vjp.work.data_ptr<double>();
  const double* ws = tape.workspace.data_ptr<double>();
  for (int64_t l = 1; l < L; ++l) {
    const int n_in = as_int(p.widths[l - 1]), n_out = as_int(p.widths[l]);
    gemm_tn(E, as_int(B), n_in, n_out, sb, w + vjp.u[l - 1],
            gradient_sinks[l - 1].data_ptr<double>(), /*accumulate=*/true);
    gemm_nn(E, as_int(B), n_in, n_out, sb, weights[l - 1].data_ptr<double>(), ub,
            /*transpose_b=*/false);
    const double *a = ws + p.act[l], *s = w + vjp.s[l];
    double* extra = w + vjp.extra[l];
    for (int64_t k = 0; k < E * B * n_out; ++k) extra[k] = ((ub[k] * s[k]) * a[k]) * -2.0;
    tanh_jet_backward(0, 0, E, B * n_out, a, a, ub, sb);  // S~_l = U~ (.) (1 - A_l^2)
  }
  const int n_last = as_int(p.widths[L - 1]), n_out = as_int(p.widths[L]);
  gemm_tn(E, as_int(B), n_last, n_out, sb, vjp.c.data_ptr<double>(),
          gradient_sinks[L - 1].data_ptr<double>(), /*accumulate=*/true);
  Tensor c_bar = torch::empty({E, B, p.widths[L]}, torch::kFloat64);
  gemm_nn(E, as_int(B), n_last, n_out, sb, weights[L - 1].data_ptr<double>(),
          c_bar.data_ptr<double>(), /*transpose_b=*/false);
  vjp.backward_done = true;
  return c_bar;
}

Tensor fused_mlp_vjp_value_backward(const FusedMlpVjpTape& vjp, const FusedMlpTape& tape,
                                    const std::vector<Tensor>& weights,
                                    const std::vector<Tensor>& gradient_sinks, const Tensor& v_bar,
                                    bool input_adjoint) {
  TORCH_CHECK(vjp.value == &tape && vjp.backward_done,
              "fused_mlp_vjp_value_backward: run fused_mlp_taped_vjp_backward of this value "
              "pass's product first");
  const double* w = vjp.work.data_ptr<double>();
  std::vector<const double*> extra(weights.size(), nullptr);
  for (std::size_t l = 1; l < extra.size(); ++l) extra[l] = w + vjp.extra[l];
  return fused_mlp_taped_backward(tape, weights, gradient_sinks, v_bar, extra, input_adjoint);
}

}  // namespace internal
}  // namespace phnn
