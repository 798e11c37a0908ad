// src/models/fused_mlp.cpp — forward and hand-written backward of a stacked
// tanh MLP's jet (docs/METHOD.md "Fused networks").
//
// Layout. A jet of a layer's activations is stored per member as C channels
// of [B, n] row-major blocks, tensor [E, C, B, n]:
//   channel 0            the value a
//   channel 1 + i        the tangent  da/dx_i            (order >= 1, i < d)
//   channel 1 + d + p    the curvature d2a/dx_i dx_j     (order 2, pair p = (i <= j))
// A linear layer acts on every channel alike (the bias on channel 0 only), so
// one dgemm per member maps all C*B rows: Z = A W (+ b on channel 0).
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

#include <utility>

#include "models/vector_math.h"
#include "phnn/common/check.h"

extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n,
                       const int* k, const double* alpha, const double* a, const int* lda,
                       const double* b, const int* ldb, const double* beta, double* c,
                       const int* ldc);

namespace phnn {
namespace internal {
namespace {

using torch::Tensor;
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// Channel bookkeeping of one jet.
struct Channels {
  int64_t d = 0, order = 0;
  std::vector<std::pair<int64_t, int64_t>> pairs;  // (i, j), i <= j

  Channels(int64_t directions, int64_t jet_order) : d(directions), order(jet_order) {
    if (order >= 2)
      for (int64_t i = 0; i < d; ++i)
        for (int64_t j = i; j < d; ++j) pairs.emplace_back(i, j);
  }
  int64_t count() const { return 1 + (order >= 1 ? d : 0) + static_cast<int64_t>(pairs.size()); }
  int64_t tangent(int64_t i) const { return 1 + i; }
  int64_t pair(std::size_t p) const { return 1 + d + static_cast<int64_t>(p); }
};

// Row-major per member: C[e] = A[e] B[e] with A [rows, k], B [k, cols]
// (column-major C^T = B^T A^T). trans_b: B[e] is stored as [cols, k].
void gemm_nn(int64_t E, int rows, int k, int cols, const double* a, const double* b, double* c,
             bool transpose_b, double beta) {
  const double one = 1.0;
  const char tb = transpose_b ? 'T' : 'N', ta = 'N';
  const int ldb = transpose_b ? k : cols;
  for (int64_t e = 0; e < E; ++e) {
    dgemm_(&tb, &ta, &cols, &rows, &k, &one, b + e * k * cols, &ldb, a + e * rows * k, &k, &beta,
           c + e * rows * cols, &cols);
  }
}

// Per member: W~[e] = A[e]^T Z~[e], A [rows, n_in], Z~ [rows, n_out].
void gemm_tn(int64_t E, int rows, int n_in, int n_out, const double* a, const double* z,
             double* w) {
  const double one = 1.0, zero = 0.0;
  const char tz = 'N', ta = 'T';
  for (int64_t e = 0; e < E; ++e) {
    dgemm_(&tz, &ta, &n_out, &n_in, &rows, &one, z + e * rows * n_out, &n_out,
           a + e * rows * n_in, &n_in, &zero, w + e * n_in * n_out, &n_out);
  }
}

// Copies a strided [E, B, n] view into channel c of a packed [E, C, B, n].
void pack_channel(const Tensor& src, Tensor* packed, int64_t c) {
  packed->select(1, c).copy_(src);
}

// The input jet as packed channels.
Tensor pack_input(const Tensor& x_v, const Tensor& x_g, const Tensor& x_h, const Channels& ch) {
  const int64_t E = x_v.size(0), B = x_v.size(1), n = x_v.size(2);
  Tensor packed = torch::empty({E, ch.count(), B, n}, x_v.options());
  pack_channel(x_v, &packed, 0);
  if (ch.order >= 1) {
    if (x_g.defined()) {
      for (int64_t i = 0; i < ch.d; ++i) pack_channel(x_g.select(2, i), &packed, ch.tangent(i));
    } else {  // d x / d x_i = e_i
      packed.narrow(1, 1, ch.d).zero_();
      for (int64_t i = 0; i < ch.d; ++i) packed.select(1, ch.tangent(i)).select(-1, i).fill_(1.0);
    }
  }
  for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
    auto dst = packed.select(1, ch.pair(p));
    if (x_h.defined()) {
      dst.copy_(x_h.select(2, ch.pairs[p].first).select(2, ch.pairs[p].second));
    } else {
      dst.zero_();
    }
  }
  return packed;
}

// (F): activations a of layer l+1 from its pre-activations z, t = tanh(z_0).
void tanh_jet_forward(const Channels& ch, int64_t E, int64_t bn, const double* z, const double* t,
                      double* a) {
  const int64_t C = ch.count();
  for (int64_t e = 0; e < E; ++e) {
    const double* ze = z + e * C * bn;
    const double* te = t + e * bn;
    double* ae = a + e * C * bn;
    for (int64_t k = 0; k < bn; ++k) ae[k] = te[k];
    if (ch.order < 1) continue;
    for (int64_t i = 0; i < ch.d; ++i) {
      const double* zi = ze + ch.tangent(i) * bn;
      double* ai = ae + ch.tangent(i) * bn;
      for (int64_t k = 0; k < bn; ++k) ai[k] = (1.0 - te[k] * te[k]) * zi[k];
    }
    for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
      const double* zi = ze + ch.tangent(ch.pairs[p].first) * bn;
      const double* zj = ze + ch.tangent(ch.pairs[p].second) * bn;
      const double* zp = ze + ch.pair(p) * bn;
      double* ap = ae + ch.pair(p) * bn;
      for (int64_t k = 0; k < bn; ++k) {
        const double s = 1.0 - te[k] * te[k];
        ap[k] = s * zp[k] - 2.0 * te[k] * s * zi[k] * zj[k];
      }
    }
  }
}

// (B): adjoint z_bar of the pre-activations from the adjoint a_bar of the
// activations (separate buffers).
void tanh_jet_backward(const Channels& ch, int64_t E, int64_t bn, const double* z, const double* t,
                       const double* a_bar, double* z_bar) {
  const int64_t C = ch.count();
  for (int64_t e = 0; e < E; ++e) {
    const double* ze = z + e * C * bn;
    const double* te = t + e * bn;
    const double* ab = a_bar + e * C * bn;
    double* zb = z_bar + e * C * bn;
    for (int64_t k = 0; k < bn; ++k) zb[k] = (1.0 - te[k] * te[k]) * ab[k];
    if (ch.order < 1) continue;
    for (int64_t i = 0; i < ch.d; ++i) {
      const double* zi = ze + ch.tangent(i) * bn;
      const double* abi = ab + ch.tangent(i) * bn;
      double* zbi = zb + ch.tangent(i) * bn;
      for (int64_t k = 0; k < bn; ++k) {
        const double s = 1.0 - te[k] * te[k];
        zb[k] += -2.0 * te[k] * s * abi[k] * zi[k];
        zbi[k] = s * abi[k];
      }
    }
    for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
      const int64_t i = ch.pairs[p].first, j = ch.pairs[p].second;
      const double* zi = ze + ch.tangent(i) * bn;
      const double* zj = ze + ch.tangent(j) * bn;
      const double* zp = ze + ch.pair(p) * bn;
      const double* abp = ab + ch.pair(p) * bn;
      double* zbi = zb + ch.tangent(i) * bn;
      double* zbj = zb + ch.tangent(j) * bn;
      double* zbp = zb + ch.pair(p) * bn;
      for (int64_t k = 0; k < bn; ++k) {
        const double tt = te[k] * te[k], s = 1.0 - tt, s1 = -2.0 * te[k] * s;
        zb[k] += abp[k] * (s1 * zp[k] + s * (6.0 * tt - 2.0) * zi[k] * zj[k]);
        zbp[k] = s * abp[k];
        zbi[k] += s1 * abp[k] * zj[k];  // i == j: this line and the next give 2 s1 a~_ii z_i
        zbj[k] += s1 * abp[k] * zi[k];
      }
    }
  }
}

// Layer sizes and the jet's channels, fixed for one call.
struct Shape {
  int64_t E = 0, B = 0;
  std::vector<int64_t> widths;  // n_0 .. n_L
  int64_t layers() const { return static_cast<int64_t>(widths.size()) - 1; }
};

// The forward pass; fills the saved activations A_l (l = 0..L-1, packed
// inputs of each linear layer), pre-activations Z_l and tanh values T_l of
// the hidden layers, and returns Z_L packed.
Tensor forward_packed(const std::vector<Tensor>& W, const std::vector<Tensor>& b, Tensor a,
                      const Channels& ch, const Shape& shape, std::vector<Tensor>* acts,
                      std::vector<Tensor>* pre, std::vector<Tensor>* tanhs) {
  const int64_t C = ch.count(), E = shape.E, B = shape.B;
  for (int64_t l = 0; l < shape.layers(); ++l) {
    const int64_t n_in = shape.widths[l], n_out = shape.widths[l + 1];
    Tensor z = torch::empty({E, C, B, n_out}, a.options());
    const Tensor w = W[l].contiguous(), bias = b[l].contiguous();
    gemm_nn(E, static_cast<int>(C * B), static_cast<int>(n_in), static_cast<int>(n_out),
            a.data_ptr<double>(), w.data_ptr<double>(), z.data_ptr<double>(), false, 0.0);
    z.select(1, 0).add_(bias);  // bias [E, 1, n_out] broadcasts over the batch
    acts->push_back(a);
    if (l + 1 == shape.layers()) return z;
    Tensor t = torch::empty({E, B, n_out}, a.options());  // tanh of the value channel
    for (int64_t e = 0; e < E; ++e) {
      tanh_array(z.data_ptr<double>() + e * C * B * n_out, t.data_ptr<double>() + e * B * n_out,
                 B * n_out);
    }
    Tensor next = torch::empty_like(z);
    tanh_jet_forward(ch, E, B * n_out, z.data_ptr<double>(), t.data_ptr<double>(),
                     next.data_ptr<double>());
    pre->push_back(z);
    tanhs->push_back(t);
    a = next;
  }
  return a;  // not reached: a network has at least one layer
}

// Unpacks the output channels into the jet's [E, B, ...] tensors.
FusedMlpJet unpack_output(const Tensor& z, const Channels& ch) {
  FusedMlpJet out;
  out.v = z.select(1, 0).clone();
  if (ch.order >= 1) out.g = z.narrow(1, 1, ch.d).permute({0, 2, 1, 3}).contiguous();
  if (ch.order >= 2) {
    const int64_t E = z.size(0), B = z.size(2), n = z.size(3);
    out.h = torch::empty({E, B, ch.d, ch.d, n}, z.options());
    for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
      const auto [i, j] = ch.pairs[p];
      const Tensor src = z.select(1, ch.pair(p));
      out.h.select(2, i).select(2, j).copy_(src);
      if (i != j) out.h.select(2, j).select(2, i).copy_(src);
    }
  }
  return out;
}

// Adjoint of unpack_output: the packed Z_L adjoint from the outputs' adjoints
// (undefined = 0); a symmetric pair gathers both of its copies.
Tensor pack_output_adjoint(const variable_list& grads, const Channels& ch, const Shape& shape) {
  const int64_t n = shape.widths.back();
  Tensor bar = torch::zeros({shape.E, ch.count(), shape.B, n}, torch::kFloat64);
  if (grads[0].defined()) bar.select(1, 0).copy_(grads[0]);
  if (ch.order >= 1 && grads.size() > 1 && grads[1].defined()) {
    bar.narrow(1, 1, ch.d).copy_(grads[1].permute({0, 2, 1, 3}));
  }
  if (ch.order >= 2 && grads.size() > 2 && grads[2].defined()) {
    for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
      const auto [i, j] = ch.pairs[p];
      auto dst = bar.select(1, ch.pair(p));
      dst.copy_(grads[2].select(2, i).select(2, j));
      if (i != j) dst.add_(grads[2].select(2, j).select(2, i));
    }
  }
  return bar;
}

class FusedMlpFunction : public torch::autograd::Function<FusedMlpFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& x_v,
                               const c10::optional<Tensor>& x_g, const c10::optional<Tensor>& x_h,
                               at::TensorList weights, at::TensorList biases, int64_t directions,
                               int64_t order) {
    const Channels ch(directions, order);
    Shape shape{x_v.size(0), x_v.size(1), {x_v.size(2)}};
    for (const auto& w : weights) shape.widths.push_back(w.size(2));
    const Tensor g = x_g.has_value() ? *x_g : Tensor(), h = x_h.has_value() ? *x_h : Tensor();
    std::vector<Tensor> W(weights.begin(), weights.end()), b(biases.begin(), biases.end());
    std::vector<Tensor> acts, pre, tanhs;
    const Tensor z = forward_packed(W, b, pack_input(x_v, g, h, ch), ch, shape, &acts, &pre, &tanhs);
    ctx->saved_data["W"] = W;
    ctx->saved_data["A"] = acts;
    ctx->saved_data["Z"] = pre;
    ctx->saved_data["T"] = tanhs;
    ctx->saved_data["shape"] = shape.widths;
    ctx->saved_data["directions"] = directions;
    ctx->saved_data["order"] = order;
    ctx->saved_data["has_g"] = g.defined();
    ctx->saved_data["has_h"] = h.defined();
    const FusedMlpJet out = unpack_output(z, ch);
    variable_list result{out.v};
    if (order >= 1) result.push_back(out.g);
    if (order >= 2) result.push_back(out.h);
    return result;
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const Channels ch(ctx->saved_data["directions"].toInt(), ctx->saved_data["order"].toInt());
    const std::vector<Tensor> W = ctx->saved_data["W"].toTensorVector();
    const std::vector<Tensor> A = ctx->saved_data["A"].toTensorVector();
    const std::vector<Tensor> Z = ctx->saved_data["Z"].toTensorVector();
    const std::vector<Tensor> T = ctx->saved_data["T"].toTensorVector();
    Shape shape{A[0].size(0), A[0].size(2), ctx->saved_data["shape"].toIntVector()};
    const int64_t L = shape.layers(), C = ch.count(), E = shape.E, B = shape.B;
    std::vector<Tensor> w_bar(static_cast<std::size_t>(L)), b_bar(static_cast<std::size_t>(L));
    // needs_input_grad counts variable inputs only: x_v, then x_g and x_h
    // where they were given.
    const bool has_g = ctx->saved_data["has_g"].toBool(), has_h = ctx->saved_data["has_h"].toBool();
    const bool need_v = ctx->needs_input_grad(0);
    const bool need_g = has_g && ctx->needs_input_grad(1);
    const bool need_h = has_h && ctx->needs_input_grad(has_g ? 2 : 1);
    const bool input_grad = need_v || need_g || need_h;
    Tensor z_bar = pack_output_adjoint(grads, ch, shape);
    Tensor a_bar;
    for (int64_t l = L - 1; l >= 0; --l) {
      const auto ul = static_cast<std::size_t>(l);
      const int64_t n_in = shape.widths[ul], n_out = shape.widths[ul + 1];
      w_bar[ul] = torch::empty({E, n_in, n_out}, torch::kFloat64);
      gemm_tn(E, static_cast<int>(C * B), static_cast<int>(n_in), static_cast<int>(n_out),
              A[ul].data_ptr<double>(), z_bar.data_ptr<double>(), w_bar[ul].data_ptr<double>());
      b_bar[ul] = z_bar.select(1, 0).sum(1, /*keepdim=*/true);
      if (l == 0 && !input_grad) break;
      a_bar = torch::empty({E, C, B, n_in}, torch::kFloat64);
      const Tensor w = W[ul].contiguous();
      gemm_nn(E, static_cast<int>(C * B), static_cast<int>(n_out), static_cast<int>(n_in),
              z_bar.data_ptr<double>(), w.data_ptr<double>(), a_bar.data_ptr<double>(),
              /*transpose_b=*/true, 0.0);
      if (l == 0) break;
      z_bar = torch::empty_like(a_bar);
      tanh_jet_backward(ch, E, B * n_in, Z[ul - 1].data_ptr<double>(),
                        T[ul - 1].data_ptr<double>(), a_bar.data_ptr<double>(),
                        z_bar.data_ptr<double>());
    }
    variable_list out;
    out.push_back(need_v ? a_bar.select(1, 0) : Tensor());
    out.push_back(need_g ? a_bar.narrow(1, 1, ch.d).permute({0, 2, 1, 3}) : Tensor());
    out.push_back(need_h ? input_curvature_adjoint(a_bar, ch) : Tensor());
    for (auto& w : w_bar) out.push_back(w);
    for (auto& b : b_bar) out.push_back(b);
    out.emplace_back();  // directions
    out.emplace_back();  // order
    return out;
  }

 private:
  // Adjoint of x_h [E, B, d, d, n]: pack_input read x_h[i][j] (i <= j) only;
  // the adjoint is split evenly over both symmetric copies.
  static Tensor input_curvature_adjoint(const Tensor& a_bar, const Channels& ch) {
    const int64_t E = a_bar.size(0), B = a_bar.size(2), n = a_bar.size(3);
    Tensor out = torch::zeros({E, B, ch.d, ch.d, n}, a_bar.options());
    for (std::size_t p = 0; p < ch.pairs.size(); ++p) {
      const auto [i, j] = ch.pairs[p];
      const Tensor src = a_bar.select(1, ch.pair(p));
      if (i == j) {
        out.select(2, i).select(2, j).copy_(src);
      } else {
        out.select(2, i).select(2, j).copy_(0.5 * src);
        out.select(2, j).select(2, i).copy_(0.5 * src);
      }
    }
    return out;
  }
};

}  // namespace

FusedMlpJet fused_mlp(const std::vector<torch::Tensor>& weights,
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
  const c10::optional<Tensor> g = x_g.defined() ? c10::optional<Tensor>(x_g) : c10::nullopt;
  const c10::optional<Tensor> h = x_h.defined() ? c10::optional<Tensor>(x_h) : c10::nullopt;
  const variable_list out = FusedMlpFunction::apply(x_v, g, h, at::TensorList(weights),
                                                    at::TensorList(biases), options.directions,
                                                    options.order);
  FusedMlpJet jet;
  jet.v = out[0];
  if (options.order >= 1) jet.g = out[1];
  if (options.order >= 2) jet.h = out[2];
  return jet;
}

}  // namespace internal
}  // namespace phnn
