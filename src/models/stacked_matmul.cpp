// src/models/stacked_matmul.cpp
#include "models/stacked_matmul.h"

#include "models/blas.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {
namespace {

// A row-major [rows x cols] matrix inside a 3-D tensor: plain (row stride
// ld, unit column stride) or the transpose of a plain [cols x rows] matrix.
struct Operand {
  torch::Tensor keep;  // owns the data if a contiguous copy was needed
  const double* data = nullptr;
  int64_t member_stride = 0;
  int ld = 0;
  bool transposed = false;
};

Operand describe(const torch::Tensor& t) {
  Operand op;
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
  op.data = op.keep.data_ptr<double>();
  op.member_stride = op.keep.stride(0);
  return op;
}

torch::Tensor forward_product(const torch::Tensor& a, const torch::Tensor& b) {
  TORCH_CHECK(a.dim() == 3 && b.dim() == 3, "stacked_matmul: expected 3-D operands, got ",
              a.sizes(), " and ", b.sizes());
  TORCH_CHECK(a.size(0) == b.size(0) && a.size(2) == b.size(1),
              "stacked_matmul: shapes do not match: ", a.sizes(), " @ ", b.sizes());
  TORCH_CHECK(a.scalar_type() == torch::kFloat64 && b.scalar_type() == torch::kFloat64,
              "stacked_matmul: expected float64 operands");
  const int64_t E = a.size(0), R = a.size(1), K = a.size(2), N = b.size(2);
  auto c = torch::empty({E, R, N}, a.options());
  if (R == 0 || N == 0) return c;
  if (K == 0) return c.zero_();
  const Operand A = describe(a), B = describe(b);
  // Row-major C = A B is column-major C^T = B^T A^T.
  const char ta = A.transposed ? 'T' : 'N', tb = B.transposed ? 'T' : 'N';
  const int m = static_cast<int>(N), n = static_cast<int>(R), k = static_cast<int>(K);
  const int ldc = static_cast<int>(N);
  const double one = 1.0, zero = 0.0;
  double* out = c.data_ptr<double>();
  for (int64_t e = 0; e < E; ++e) {
    dgemm_(&tb, &ta, &m, &n, &k, &one, B.data + e * B.member_stride, &B.ld,
           A.data + e * A.member_stride, &A.ld, &zero, out + e * R * N, &ldc);
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
