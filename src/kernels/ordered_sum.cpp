// src/kernels/ordered_sum.cpp — see ordered_sum.h.
#include "kernels/ordered_sum.h"

#include "phnn/common/check.h"

namespace phnn {
namespace internal {
namespace {

template <typename T>
void sum_rows(const torch::Tensor& in, int64_t outer, int64_t inner, torch::Tensor* out) {
  const T* p = in.data_ptr<T>();
  T* s = out->data_ptr<T>();
  for (int64_t o = 0; o < outer; ++o) {
    T acc = 0;
    for (int64_t k = 0; k < inner; ++k) acc += p[o * inner + k];
    s[o] = acc;
  }
}

torch::Tensor sum_forward(const torch::Tensor& t, int64_t dims) {
  const auto sizes = t.sizes();
  const std::vector<int64_t> kept(sizes.begin(), sizes.end() - dims);
  int64_t inner = 1;
  for (int64_t d = t.dim() - dims; d < t.dim(); ++d) inner *= sizes[static_cast<std::size_t>(d)];
  const torch::Tensor in = t.contiguous();
  torch::Tensor out = torch::empty(kept, t.options());
  const int64_t outer = out.numel();
  if (t.scalar_type() == torch::kFloat32) {
    sum_rows<float>(in, outer, inner, &out);
  } else {
    sum_rows<double>(in, outer, inner, &out);
  }
  return out;
}

class OrderedSum : public torch::autograd::Function<OrderedSum> {
 public:
  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& t,
                               int64_t dims) {
    ctx->saved_data["sizes"] = t.sizes().vec();
    ctx->saved_data["dims"] = dims;
    return sum_forward(t, dims);
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grads) {
    const auto sizes = ctx->saved_data["sizes"].toIntVector();
    const int64_t dims = ctx->saved_data["dims"].toInt();
    auto shape = std::vector<int64_t>(sizes.begin(), sizes.end() - dims);
    shape.resize(sizes.size(), 1);
    return {grads[0].reshape(shape).expand(sizes), torch::Tensor()};
  }
};

// t summed down to `shape` (same dimension count; 1 where t was broadcast):
// all broadcast dimensions at once by ordered_sum, their elements in
// row-major order (the order LibTorch's scalar reduction takes for the small
// sums of the op-by-op reference path).
torch::Tensor sum_to_shape(const torch::Tensor& t, const std::vector<int64_t>& shape) {
  std::vector<int64_t> kept, summed;
  for (int64_t d = 0; d < t.dim(); ++d) {
    const bool broadcast = shape[static_cast<std::size_t>(d)] == 1 && t.size(d) != 1;
    (broadcast ? summed : kept).push_back(d);
  }
  if (summed.empty()) return t;
  std::vector<int64_t> order(kept);
  order.insert(order.end(), summed.begin(), summed.end());
  return ordered_sum(t.permute(order), static_cast<int64_t>(summed.size())).reshape(shape);
}

class OrderedBroadcastMul : public torch::autograd::Function<OrderedBroadcastMul> {
 public:
  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& a,
                               const torch::Tensor& b) {
    ctx->save_for_backward({a, b});
    return a * b;
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grads) {
    const auto saved = ctx->get_saved_variables();
    const auto &a = saved[0], &b = saved[1];
    torch::Tensor ga, gb;
    if (ctx->needs_input_grad(0)) ga = sum_to_shape(ordered_broadcast_mul(grads[0], b), a.sizes().vec());
    if (ctx->needs_input_grad(1)) gb = sum_to_shape(ordered_broadcast_mul(grads[0], a), b.sizes().vec());
    return {ga, gb};
  }
};

// t.expand(sizes) whose backward sums the adjoint down to t's shape by
// sum_to_shape (autograd's ExpandBackward would use LibTorch's sum).
class OrderedExpand : public torch::autograd::Function<OrderedExpand> {
 public:
  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& t,
                               std::vector<int64_t> sizes) {
    ctx->saved_data["shape"] = t.sizes().vec();
    return t.expand(sizes);
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grads) {
    return {sum_to_shape(grads[0], ctx->saved_data["shape"].toIntVector()), torch::Tensor()};
  }
};

}  // namespace

torch::Tensor ordered_broadcast_mul(const torch::Tensor& a, const torch::Tensor& b) {
  PHNN_CHECK(a.dim() == b.dim(), "ordered_broadcast_mul: expected operands of one dimension "
                                 "count, got " << a.sizes() << " and " << b.sizes());
  if (!torch::GradMode::is_enabled() || !(a.requires_grad() || b.requires_grad())) return a * b;
  return OrderedBroadcastMul::apply(a, b);
}

torch::Tensor ordered_expand(const torch::Tensor& t, const std::vector<int64_t>& sizes) {
  PHNN_CHECK(static_cast<int64_t>(sizes.size()) == t.dim(),
             "ordered_expand: expected " << t.dim() << " sizes, got " << sizes.size());
  if (!torch::GradMode::is_enabled() || !t.requires_grad()) return t.expand(sizes);
  return OrderedExpand::apply(t, sizes);
}

torch::Tensor ordered_sum(const torch::Tensor& t, int64_t dims) {
  PHNN_CHECK(dims >= 0 && dims <= t.dim(),
             "ordered_sum: cannot sum the last " << dims << " of " << t.dim() << " dimensions");
  PHNN_CHECK(t.scalar_type() == torch::kFloat64 || t.scalar_type() == torch::kFloat32,
             "ordered_sum: expected float64 or float32");
  if (dims == 0) return t;
  if (!torch::GradMode::is_enabled() || !t.requires_grad()) return sum_forward(t, dims);
  return OrderedSum::apply(t, dims);
}

torch::Tensor ordered_mean(const torch::Tensor& t, int64_t dims) {
  int64_t count = 1;
  for (int64_t d = t.dim() - dims; d < t.dim(); ++d) count *= t.size(d);
  return ordered_sum(t, dims) / static_cast<double>(count);
}

torch::Tensor ordered_matmul(const torch::Tensor& a, const torch::Tensor& b) {
  PHNN_CHECK(a.dim() >= 2 && b.dim() >= 2 && a.size(-1) == b.size(-2),
             "ordered_matmul: shapes do not match: " << a.sizes() << " @ " << b.sizes());
  // [..., n, m, 1] * [..., 1, m, k] -> [..., n, k, m], summed over m.
  // Batch dimensions padded to one count, so the product's backward can sum
  // each operand's broadcast dimensions in order.
  torch::Tensor ea = a.unsqueeze(-1), eb = b.unsqueeze(-3);
  while (ea.dim() < eb.dim()) ea = ea.unsqueeze(0);
  while (eb.dim() < ea.dim()) eb = eb.unsqueeze(0);
  return ordered_sum(ordered_broadcast_mul(ea, eb).transpose(-1, -2), 1);
}

}  // namespace internal
}  // namespace phnn
