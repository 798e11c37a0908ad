// src/models/fused_mlp.cpp — forward and hand-written backward of a stacked
// tanh MLP's jet (docs/DECISIONS.md "Fused networks").
// Size: one autograd node; its layout, plan, forward and backward share the
// derivation written below and are read together.
//
// Layout. A jet of a layer's activations is stored per member as C channels
// of [B, n] row-major blocks, tensor [E, C, B, n]:
//   channel 0            the value a
//   channel 1 + i        the tangent  da/dx_i            (order >= 1, i < d)
//   channel 1 + d + p    the curvature d2a/dx_i dx_j     (order 2, pair p = (i <= j))
// A linear layer acts on every channel alike (the bias on channel 0 only), so
// one GEMM per member maps all C*B rows: Z = A W (+ b on channel 0).
//
// tanh layer, elementwise with t = tanh(z_0), s = 1 - t^2 = tanh',
// s1 = -2 t s = tanh'', s2 = s (6 t^2 - 2) = tanh''' (chain rule of a jet):
//   a_0 = t,   a_i = s z_i,   a_ij = s z_ij + s1 z_i z_j                  (F)
// Backward of (F), given the adjoints a~ of every channel:
//   z~_ij = s a~_ij
//   z~_i  = s a~_i + s1 sum_j a~_ij z_j       (a~_ij over the full symmetric
//                                              pair set: a diagonal pair counts
//                                              twice, 2 s1 a~_ii z_i)
//   z~_0  = s a~_0 + s1 sum_i a~_i z_i + sum_{i<=j} a~_ij (s1 z_ij + s2 z_i z_j)   (B)
// Backward of Z = A W + b (all channels stacked as rows, per member):
//   W~ = A^T Z~,   b~ = sum over the batch of channel 0 of Z~,   A~ = Z~ W^T.
#include "models/fused_mlp.h"
#include "models/fused_mlp_plan.h"

#include <algorithm>
#include <utility>

#include <torch/csrc/autograd/functions/utils.h>

#include "kernels/jet_kernels.h"
#include "kernels/member_gemm.h"
#include "kernels/vector_math.h"

namespace phnn {
namespace internal {

using torch::Tensor;

// Row-major per member: C[e] = A[e] B[e] with A [rows, k], B [k, cols]
// (trans_b: B[e] is stored as [cols, k]); member_gemm.h's kernel.
void gemm_nn(int64_t E, int rows, int k, int cols, const double* a, const double* b, double* c,
             bool transpose_b) {
  const MatrixView<double> av{a, int64_t{rows} * k, k, 1};
  const MatrixView<double> bv = transpose_b ? MatrixView<double>{b, int64_t{k} * cols, 1, k}
                                            : MatrixView<double>{b, int64_t{k} * cols, cols, 1};
  member_gemm(E, rows, k, cols, av, bv, c, /*accumulate=*/false);
}

// Per member: W~[e] (+)= A[e]^T Z~[e], A [rows, n_in], Z~ [rows, n_out].
void gemm_tn(int64_t E, int rows, int n_in, int n_out, const double* a, const double* z,
             double* w, bool accumulate) {
  const MatrixView<double> at{a, int64_t{rows} * n_in, 1, n_in};
  const MatrixView<double> zv{z, int64_t{rows} * n_out, n_out, 1};
  member_gemm(E, n_in, rows, n_out, at, zv, w, accumulate);
}

// A workspace buffer of `numel` doubles, reused across calls: the per-thread
// cache hands out a buffer again once nobody else holds it (the backward
// node that kept it has run), so every step reuses the previous step's
// memory. Without it, medium and large networks' buffers (MBs) went back to
// the OS after each step and were page-faulted in again (~20 % of a medium
// step in perf).
Tensor reusable_buffer(int64_t numel) {
  constexpr std::size_t kMaxCached = 48;
  thread_local std::vector<Tensor> cache;
  for (const Tensor& t : cache) {
    if (t.numel() == numel && t.use_count() == 1) return t;
  }
  Tensor fresh = torch::empty({numel}, torch::kFloat64);
  if (cache.size() < kMaxCached) {
    cache.push_back(fresh);
  } else {
    for (Tensor& t : cache) {
      if (t.use_count() == 1) {
        t = fresh;
        break;
      }
    }
  }
  return fresh;
}

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// dst[e][b][k] = src[e][b][k] for a 3-D view with any strides (expanded
// inputs too); dst is dense [E, B, n] with the given member stride.
void gather_3d(const Tensor& src, double* dst, int64_t dst_member_stride) {
  const int64_t E = src.size(0), B = src.size(1), n = src.size(2);
  const int64_t se = src.stride(0), sb = src.stride(1), sk = src.stride(2);
  const double* p = src.data_ptr<double>();
  for (int64_t e = 0; e < E; ++e)
    for (int64_t b = 0; b < B; ++b)
      for (int64_t k = 0; k < n; ++k) dst[e * dst_member_stride + b * n + k] = p[e * se + b * sb + k * sk];
}

// The inverse: a dense [B, n] block per member (member stride given) into a
// 3-D view with any strides.
void scatter_3d(const double* src, int64_t src_member_stride, Tensor* dst) {
  const int64_t E = dst->size(0), B = dst->size(1), n = dst->size(2);
  const int64_t se = dst->stride(0), sb = dst->stride(1), sk = dst->stride(2);
  double* p = dst->data_ptr<double>();
  for (int64_t e = 0; e < E; ++e)
    for (int64_t b = 0; b < B; ++b)
      for (int64_t k = 0; k < n; ++k) p[e * se + b * sb + k * sk] = src[e * src_member_stride + b * n + k];
}

// The input jet into the packed A_0 (channels per the file comment).
void pack_input(const Tensor& x_v, const Tensor& x_g, const Tensor& x_h, const Plan& plan,
                double* a0) {
  const int64_t n = plan.widths[0], bn = plan.B * n, stride = plan.block(n);
  const Channels& ch = plan.ch;
  gather_3d(x_v, a0, stride);
  for (int64_t i = 0; i < ch.d && ch.order >= 1; ++i) {
    double* dst = a0 + ch.tangent(i) * bn;
    if (x_g.defined()) {
      gather_3d(x_g.select(2, i), dst, stride);
      continue;
    }
    for (int64_t e = 0; e < plan.E; ++e)  // d x / d x_i = e_i
      for (int64_t k = 0; k < bn; ++k) dst[e * stride + k] = (k % n == i) ? 1.0 : 0.0;
  }
  for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
    double* dst = a0 + ch.pair(p) * bn;
    if (x_h.defined()) {
      gather_3d(x_h.select(2, ch.pairs[p].first).select(2, ch.pairs[p].second), dst, stride);
      continue;
    }
    for (int64_t e = 0; e < plan.E; ++e) std::fill(dst + e * stride, dst + e * stride + bn, 0.0);
  }
}

// Z = A W + b (b on channel 0 only), per member.
void linear_forward(const Plan& plan, int64_t l, const double* a, const Tensor& w, const Tensor& b,
                    double* z) {
  const int64_t n_in = plan.widths[l], n_out = plan.widths[l + 1];
  gemm_nn(plan.E, static_cast<int>(plan.rows()), static_cast<int>(n_in), static_cast<int>(n_out),
          a, w.data_ptr<double>(), z, /*transpose_b=*/false);
  add_bias(plan.E, plan.B, n_out, plan.block(n_out), b.data_ptr<double>(), z);
}

// Unpacks Z_L into the jet's [E, B, ...] outputs.
FusedMlpJet unpack_output(const Plan& plan, const double* z, const torch::TensorOptions& options) {
  const Channels& ch = plan.ch;
  const int64_t n = plan.widths.back(), bn = plan.B * n, stride = plan.block(n);
  FusedMlpJet out;
  out.v = torch::empty({plan.E, plan.B, n}, options);
  scatter_3d(z, stride, &out.v);
  if (ch.order >= 1) {
    out.g = torch::empty({plan.E, plan.B, ch.d, n}, options);
    for (int64_t i = 0; i < ch.d; ++i) {
      Tensor gi = out.g.select(2, i);
      scatter_3d(z + ch.tangent(i) * bn, stride, &gi);
    }
  }
  for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
    if (!out.h.defined()) out.h = torch::empty({plan.E, plan.B, ch.d, ch.d, n}, options);
    const auto [i, j] = ch.pairs[p];
    Tensor hij = out.h.select(2, i).select(2, j), hji = out.h.select(2, j).select(2, i);
    scatter_3d(z + ch.pair(p) * bn, stride, &hij);
    if (i != j) scatter_3d(z + ch.pair(p) * bn, stride, &hji);
  }
  return out;
}

// Adjoint of unpack_output: the packed adjoint of Z_L from the outputs'
// adjoints (undefined = 0); an off-diagonal pair gathers both its copies.
void pack_output_adjoint(const Plan& plan, const torch::autograd::variable_list& grads, double* bar) {
  const Channels& ch = plan.ch;
  const int64_t n = plan.widths.back(), bn = plan.B * n, stride = plan.block(n);
  std::fill(bar, bar + plan.E * stride, 0.0);
  if (grads[0].defined()) gather_3d(grads[0], bar, stride);
  if (ch.order >= 1 && grads.size() > 1 && grads[1].defined()) {
    for (int64_t i = 0; i < ch.d; ++i) gather_3d(grads[1].select(2, i), bar + ch.tangent(i) * bn, stride);
  }
  if (ch.order < 2 || grads.size() < 3 || !grads[2].defined()) return;
  std::vector<double> tmp(static_cast<std::size_t>(plan.E * stride));
  for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
    const auto [i, j] = ch.pairs[p];
    double* dst = bar + ch.pair(p) * bn;
    gather_3d(grads[2].select(2, i).select(2, j), dst, stride);
    if (i == j) continue;
    gather_3d(grads[2].select(2, j).select(2, i), tmp.data(), stride);
    for (int64_t e = 0; e < plan.E; ++e)
      for (int64_t k = 0; k < bn; ++k) dst[e * stride + k] += tmp[static_cast<std::size_t>(e * stride + k)];
  }
}

// a[k] += b[k], k < n.
void add_into(const double* b, int64_t n, double* a) {
  for (int64_t k = 0; k < n; ++k) a[k] += b[k];
}

// The adjoint of x_v's channel `channel` ([E, B, n_0]) from the packed A~_0.
Tensor input_adjoint(const Plan& plan, const double* a_bar, int64_t channel) {
  const int64_t n = plan.widths[0];
  Tensor t = torch::empty({plan.E, plan.B, n}, torch::kFloat64);
  scatter_3d(a_bar + channel * plan.B * n, plan.block(n), &t);
  return t;
}

// Adjoint of x_h [E, B, d, d, n]: pack_input read x_h[i][j] (i <= j) only;
// the adjoint is split evenly over both symmetric copies.
Tensor input_curvature_adjoint(const Plan& plan, const double* a_bar) {
  const Channels& ch = plan.ch;
  const int64_t n = plan.widths[0];
  Tensor out = torch::zeros({plan.E, plan.B, ch.d, ch.d, n}, torch::kFloat64);
  for (std::size_t q = 0; q < ch.pairs.size(); ++q) {
    const auto [i, j] = ch.pairs[q];
    const Tensor src = input_adjoint(plan, a_bar, ch.pair(q));
    if (i == j) {
      out.select(2, i).select(2, j).copy_(src);
    } else {
      out.select(2, i).select(2, j).copy_(0.5 * src);
      out.select(2, j).select(2, i).copy_(0.5 * src);
    }
  }
  return out;
}

// The backward of one call, given the output adjoints `grads` (v~, g~, h~;
// undefined = 0): parameter gradients added into `sinks` (or, without
// sinks, returned as out[3 + l] and out[3 + L + l] where `need` asks), and
// the input adjoints x_v~, x_g~, x_h~ (out[0..2]) where `need` asks.
// `need` has one entry per output (3 + 2 L). `act_extra` (order 0 only;
// empty, or one per layer l with entry 0 unused): adjoints [E, B, n_l] added
// to the hidden activations' adjoints A~_l before their tanh backward (the
// reverse-mode gradient's second pass, fused_mlp_gradient.cpp).
variable_list backward_pass(const Plan& p, const Tensor& workspace,
                            const std::vector<Tensor>& weights, const std::vector<Tensor>& sinks,
                            const variable_list& grads, const std::vector<bool>& need,
                            const std::vector<const double*>& act_extra = {}) {
  const int64_t L = p.layers(), E = p.E;
  const bool need_v = need[0], need_g = need[1], need_h = need[2];
  const int64_t widest = *std::max_element(p.widths.begin(), p.widths.end());
  Tensor scratch = reusable_buffer(2 * E * p.block(widest));
  double* z_bar = scratch.data_ptr<double>();
  double* a_bar = z_bar + E * p.block(widest);
  const double* ws = workspace.data_ptr<double>();
  pack_output_adjoint(p, grads, z_bar);
  variable_list out(static_cast<std::size_t>(3 + 2 * L));
  for (int64_t l = L - 1; l >= 0; --l) {
    const int64_t n_in = p.widths[l], n_out = p.widths[l + 1];
    const auto ul = static_cast<std::size_t>(l);
    const bool sink = !sinks.empty();
    if (sink || need[static_cast<std::size_t>(3 + l)]) {  // W~ = A^T Z~
      Tensor w_bar = sink ? sinks[ul] : torch::empty({E, n_in, n_out}, torch::kFloat64);
      gemm_tn(E, static_cast<int>(p.rows()), static_cast<int>(n_in), static_cast<int>(n_out),
              ws + p.act[ul], z_bar, w_bar.data_ptr<double>(), /*accumulate=*/sink);
      if (!sink) out[3 + ul] = w_bar;
    }
    if (sink || need[static_cast<std::size_t>(3 + L + l)]) {  // b~ = sum_batch Z~_0
      Tensor b_bar = torch::zeros({E, 1, n_out}, torch::kFloat64);
      double* pb = b_bar.data_ptr<double>();
      sum_bias(E, p.B, n_out, p.block(n_out), z_bar, pb);
      if (sink) {
        double* dst = sinks[static_cast<std::size_t>(L) + ul].data_ptr<double>();
        for (int64_t k = 0; k < E * n_out; ++k) dst[k] += pb[k];
      } else {
        out[3 + L + ul] = b_bar;
      }
    }
    if (l == 0 && !(need_v || need_g || need_h)) break;
    gemm_nn(E, static_cast<int>(p.rows()), static_cast<int>(n_out), static_cast<int>(n_in), z_bar,
            weights[ul].data_ptr<double>(), a_bar, /*transpose_b=*/true);  // A~ = Z~ W^T
    if (l == 0) break;
    if (!act_extra.empty()) add_into(act_extra[ul], E * p.B * n_in, a_bar);
    tanh_jet_backward(p.ch.d, p.ch.order, E, p.B * n_in, ws + p.pre[ul - 1], ws + p.tanh[ul - 1],
                      a_bar, z_bar);
  }
  if (need_v) out[0] = input_adjoint(p, a_bar, 0);
  if (need_g) {
    Tensor g = torch::empty({E, p.B, p.ch.d, p.widths[0]}, torch::kFloat64);
    for (int64_t i = 0; i < p.ch.d; ++i) {
      Tensor gi = g.select(2, i);
      scatter_3d(a_bar + p.ch.tangent(i) * p.B * p.widths[0], p.block(p.widths[0]), &gi);
    }
    out[1] = g;
  }
  if (need_h) out[2] = input_curvature_adjoint(p, a_bar);
  return out;
}

// The backward node of one fused call. Holds the forward's workspace (A_l,
// Z_l, T_l) and the weights; its next edges are, in order, x_v, x_g, x_h,
// W_0..W_{L-1}, b_0..b_{L-1} (an undefined input has an empty edge).
class FusedMlpBackward : public torch::autograd::Node {
 public:
  FusedMlpBackward(Plan plan, Tensor workspace, std::vector<Tensor> weights,
                   std::vector<Tensor> sinks)
      : plan_(std::move(plan)),
        workspace_(std::move(workspace)),
        weights_(std::move(weights)),
        sinks_(std::move(sinks)) {}
  std::string name() const override { return "FusedMlpBackward"; }
  void release_variables() override {
    workspace_.reset();
    weights_.clear();
    sinks_.clear();
  }
  variable_list apply(variable_list&& grads) override {
    TORCH_CHECK(workspace_.defined(), "FusedMlpBackward: backward through the graph a second time");
    std::vector<bool> need(static_cast<std::size_t>(3 + 2 * plan_.layers()));
    for (std::size_t k = 0; k < need.size(); ++k) need[k] = should_compute_output(k);
    return backward_pass(plan_, workspace_, weights_, sinks_, grads, need);
  }

 private:
  Plan plan_;
  Tensor workspace_;
  std::vector<Tensor> weights_;
  std::vector<Tensor> sinks_;  // W_0..W_{L-1}, b_0..b_{L-1} gradient buffers, or empty
};

// The forward of one call: the checks, the plan, the workspace (kept for
// the backward) and the outputs.
struct ForwardPass {
  Plan plan;
  Tensor workspace;
  FusedMlpJet jet;
};

ForwardPass forward_pass(const std::vector<torch::Tensor>& weights,
                         const std::vector<torch::Tensor>& biases, const torch::Tensor& x_v,
                         const torch::Tensor& x_g, const torch::Tensor& x_h,
                         const FusedMlpOptions& options) {
  TORCH_CHECK(x_v.dim() == 3 && x_v.scalar_type() == torch::kFloat64,
              "fused_mlp: expected a float64 input [E, B, n], got ", x_v.sizes());
  TORCH_CHECK(!weights.empty() && weights.size() == biases.size(),
              "fused_mlp: expected one bias per weight");
  TORCH_CHECK(options.order >= 0 && options.order <= 2, "fused_mlp: order must be 0, 1 or 2");
  TORCH_CHECK(options.order == 0 || options.directions >= 1, "fused_mlp: directions must be >= 1");
  TORCH_CHECK(options.order == 0 || x_g.defined() || options.directions <= x_v.size(2),
              "fused_mlp: the input-coordinate jet has at most ", x_v.size(2), " directions");
  std::vector<int64_t> widths{x_v.size(2)};
  for (std::size_t l = 0; l < weights.size(); ++l) {
    TORCH_CHECK(weights[l].is_contiguous() && biases[l].is_contiguous() &&
                    weights[l].size(0) == x_v.size(0) && weights[l].size(1) == widths.back(),
                "fused_mlp: layer ", l, " weights ", weights[l].sizes(), " do not fit input width ",
                widths.back(), " and ", x_v.size(0), " members (or are not contiguous)");
    widths.push_back(weights[l].size(2));
  }
  const Channels ch(options.order >= 1 ? options.directions : 0, options.order);
  ForwardPass pass{Plan(ch, x_v.size(0), x_v.size(1), widths), Tensor(), {}};
  const Plan& plan = pass.plan;
  pass.workspace = reusable_buffer(plan.total);
  double* ws = pass.workspace.data_ptr<double>();
  pack_input(x_v, x_g, x_h, plan, ws + plan.act[0]);
  for (int64_t l = 0; l < plan.layers(); ++l) {
    const auto ul = static_cast<std::size_t>(l);
    const bool last = l + 1 == plan.layers();
    double* z = ws + (last ? plan.out : plan.pre[ul]);
    linear_forward(plan, l, ws + plan.act[ul], weights[ul], biases[ul], z);
    if (last) break;
    const int64_t n = plan.widths[ul + 1];
    double* t = ws + plan.tanh[ul];
    for (int64_t e = 0; e < plan.E; ++e) tanh_array(z + e * plan.block(n), t + e * plan.B * n, plan.B * n);
    tanh_jet_forward(ch.d, ch.order, plan.E, plan.B * n, z, t, ws + plan.act[ul + 1]);
  }
  pass.jet = unpack_output(plan, ws + plan.out, x_v.options());
  return pass;
}

}  // namespace

FusedMlpJet fused_mlp(const std::vector<torch::Tensor>& weights,
                      const std::vector<torch::Tensor>& biases, const torch::Tensor& x_v,
                      const torch::Tensor& x_g, const torch::Tensor& x_h,
                      const FusedMlpOptions& options,
                      const std::vector<torch::Tensor>& gradient_sinks) {
  TORCH_CHECK(gradient_sinks.empty() || gradient_sinks.size() == 2 * weights.size(),
              "fused_mlp: expected one gradient sink per weight and bias");
  ForwardPass pass = forward_pass(weights, biases, x_v, x_g, x_h, options);
  FusedMlpJet jet = pass.jet;
  std::vector<Tensor> inputs{x_v, x_g, x_h};
  inputs.insert(inputs.end(), weights.begin(), weights.end());
  inputs.insert(inputs.end(), biases.begin(), biases.end());
  if (!torch::GradMode::is_enabled() ||
      std::none_of(inputs.begin(), inputs.end(), [](const Tensor& t) { return t.defined() && t.requires_grad(); })) {
    return jet;
  }
  auto node = std::shared_ptr<FusedMlpBackward>(
      new FusedMlpBackward(std::move(pass.plan), std::move(pass.workspace), weights, gradient_sinks),
      torch::autograd::deleteNode);
  if (!gradient_sinks.empty()) {  // parameters: written into the sinks, no edges
    inputs.resize(3);
    inputs.resize(3 + 2 * weights.size());
  }
  node->set_next_edges(torch::autograd::collect_next_edges(inputs));
  for (Tensor* t : {&jet.v, &jet.g, &jet.h}) {
    if (t->defined()) torch::autograd::set_history(*t, node);
  }
  return jet;
}

FusedMlpJet fused_mlp_taped(const std::vector<torch::Tensor>& weights,
                            const std::vector<torch::Tensor>& biases, const torch::Tensor& x_v,
                            const FusedMlpOptions& options, std::shared_ptr<FusedMlpTape>* tape,
                            const torch::Tensor& x_g) {
  ForwardPass pass = forward_pass(weights, biases, x_v, x_g, {}, options);
  *tape = std::make_shared<FusedMlpTape>(
      FusedMlpTape{std::move(pass.plan), std::move(pass.workspace)});
  return pass.jet;
}

namespace {
// A taped call's backward into the sinks, with the input adjoints x_v~
// (need_v) and x_g~ (need_g) where asked for.
variable_list taped_backward(const FusedMlpTape& tape, const std::vector<torch::Tensor>& weights,
                             const std::vector<torch::Tensor>& gradient_sinks,
                             const std::vector<torch::Tensor>& grads, bool need_v, bool need_g,
                             const std::vector<const double*>& act_extra = {}) {
  TORCH_CHECK(gradient_sinks.size() == 2 * weights.size(),
              "fused_mlp_taped_backward: expected one gradient sink per weight and bias");
  std::vector<bool> need(static_cast<std::size_t>(3 + 2 * tape.plan.layers()), false);
  need[0] = need_v;
  need[1] = need_g;
  return backward_pass(tape.plan, tape.workspace, weights, gradient_sinks, grads, need, act_extra);
}
}  // namespace

torch::Tensor fused_mlp_taped_backward(const FusedMlpTape& tape,
                                       const std::vector<torch::Tensor>& weights,
                                       const std::vector<torch::Tensor>& gradient_sinks,
                                       const std::vector<torch::Tensor>& grads, bool input_adjoint) {
  return taped_backward(tape, weights, gradient_sinks, grads, input_adjoint, false)[0];
}

torch::Tensor fused_mlp_taped_backward(const FusedMlpTape& tape,
                                       const std::vector<torch::Tensor>& weights,
                                       const std::vector<torch::Tensor>& gradient_sinks,
                                       const torch::Tensor& v_bar,
                                       const std::vector<const double*>& act_extra, bool input_adjoint) {
  TORCH_CHECK(tape.plan.ch.order == 0 && act_extra.size() == weights.size(),
              "fused_mlp_taped_backward: activation adjoints need an order-0 tape, one per layer");
  return taped_backward(tape, weights, gradient_sinks, {v_bar}, input_adjoint, false, act_extra)[0];
}

std::pair<torch::Tensor, torch::Tensor> fused_mlp_taped_jet_backward(
    const FusedMlpTape& tape, const std::vector<torch::Tensor>& weights,
    const std::vector<torch::Tensor>& gradient_sinks, const std::vector<torch::Tensor>& grads) {
  auto out = taped_backward(tape, weights, gradient_sinks, grads, true, true);
  return {out[0], out[1]};
}

}  // namespace internal
}  // namespace phnn
