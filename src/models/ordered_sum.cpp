// src/models/ordered_sum.cpp — see ordered_sum.h.
#include "models/ordered_sum.h"

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

}  // namespace

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
  return ordered_sum((a.unsqueeze(-1) * b.unsqueeze(-3)).transpose(-1, -2), 1);
}

}  // namespace internal
}  // namespace phnn
