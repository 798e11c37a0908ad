// src/kernels/stacked_matmul.cpp — per-member matrix products of a model stack
// (kernels/stacked_matmul.h).
#include "kernels/stacked_matmul.h"

#include "kernels/member_gemm.h"

namespace phnn {
namespace internal {
namespace {

// A row-major [rows x cols] matrix inside a 3-D tensor: plain (row stride
// ld, unit column stride) or the transpose of a plain [cols x rows] matrix.
template <typename T>
struct Operand {
  torch::Tensor keep;  // owns the data if a contiguous copy was needed
  const T* data = nullptr;
  int64_t member_stride = 0;
  int ld = 0;
  bool transposed = false;
};

template <typename T>
Operand<T> describe(const torch::Tensor& t) {
  Operand<T> op;
  const int64_t rows = t.size(1), cols = t.size(2);
  if (t.stride(2) == 1 && t.stride(1) >= std::max<int64_t>(cols, 1)) {
    op.keep = t;
    op.ld = static_cast<int>(t.stride(1));
  } else if (t.stride(1) == 1 && t.stride(2) >= std::max<int64_t>(rows, 1)) {
    op.keep = t;
    op.ld = static_cast<int>(t.stride(2));
    op.transposed = true;
  } else {
    op.keep = t.contiguous();
    op.ld = static_cast<int>(std::max<int64_t>(cols, 1));
  }
  op.data = op.keep.template data_ptr<T>();
  op.member_stride = op.keep.stride(0);
  return op;
}

// One product per member into c [E, R, N] (T = double or float), by
// member_gemm.h's kernel (the same bits on every CPU).
template <typename T>
void member_products(const torch::Tensor& a, const torch::Tensor& b, torch::Tensor* c) {
  const int64_t E = a.size(0), R = a.size(1), K = a.size(2), N = b.size(2);
  const Operand<T> A = describe<T>(a), B = describe<T>(b);
  const auto view = [](const Operand<T>& op) {
    return op.transposed ? MatrixView<T>{op.data, op.member_stride, 1, op.ld}
                         : MatrixView<T>{op.data, op.member_stride, op.ld, 1};
  };
  member_gemm(E, R, K, N, view(A), view(B), c->data_ptr<T>(), /*accumulate=*/false);
}

torch::Tensor forward_product(const torch::Tensor& a, const torch::Tensor& b) {
  TORCH_CHECK(a.dim() == 3 && b.dim() == 3, "stacked_matmul: expected 3-D operands, got ",
              a.sizes(), " and ", b.sizes());
  TORCH_CHECK(a.size(0) == b.size(0) && a.size(2) == b.size(1),
              "stacked_matmul: shapes do not match: ", a.sizes(), " @ ", b.sizes());
  const bool f64 = a.scalar_type() == torch::kFloat64 && b.scalar_type() == torch::kFloat64;
  const bool f32 = a.scalar_type() == torch::kFloat32 && b.scalar_type() == torch::kFloat32;
  TORCH_CHECK(f64 || f32, "stacked_matmul: expected two float64 or two float32 operands, got ",
              a.scalar_type(), " and ", b.scalar_type());
  const int64_t E = a.size(0), R = a.size(1), K = a.size(2), N = b.size(2);
  auto c = torch::empty({E, R, N}, a.options());
  if (R == 0 || N == 0) return c;
  if (K == 0) return c.zero_();
  if (f64) {
    member_products<double>(a, b, &c);
  } else {
    member_products<float>(a, b, &c);
  }
  return c;
}

class StackedMatmul : public torch::autograd::Function<StackedMatmul> {
 public:
  static torch::Tensor forward(torch::autograd::AutogradContext* ctx, const torch::Tensor& a,
                               const torch::Tensor& b) {
    ctx->save_for_backward({a, b});
    return forward_product(a, b);
  }
  static torch::autograd::tensor_list backward(torch::autograd::AutogradContext* ctx,
                                               torch::autograd::tensor_list grad_outputs) {
    const auto saved = ctx->get_saved_variables();
    const auto& a = saved[0];
    const auto& b = saved[1];
    const auto& g = grad_outputs[0];
    torch::Tensor grad_a, grad_b;
    // dA = G B^T, dB = A^T G (members with a broadcast operand sum below).
    if (ctx->needs_input_grad(0)) grad_a = stacked_matmul(g, b.transpose(1, 2));
    if (ctx->needs_input_grad(1)) grad_b = stacked_matmul(a.transpose(1, 2), g);
    return {grad_a, grad_b};
  }
};

}  // namespace

torch::Tensor stacked_matmul(const torch::Tensor& a, const torch::Tensor& b) {
  if (!torch::GradMode::is_enabled() || !(a.requires_grad() || b.requires_grad())) {
    return forward_product(a, b);
  }
  return StackedMatmul::apply(a, b);
}

}  // namespace internal
}  // namespace phnn
