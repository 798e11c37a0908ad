// src/kernels/ordered_sum.h — sums over trailing dimensions in one fixed
// order, differentiable: the reductions of the loss, the regularizers and
// the rollout errors. LibTorch's sum and mean add in an order set by the
// vector width of the kernel it dispatches to (ATEN_CPU_CAPABILITY: 4
// doubles under AVX2, 8 under AVX-512), so their bits changed with the CPU
// (docs/METHOD.md "Deterministic kernels").
#pragma once

#include <vector>

#include <torch/torch.h>

namespace phnn {
namespace internal {

/// s[o] = (((t[o, 0] + t[o, 1]) + t[o, 2]) + ...) over the last `dims`
/// dimensions of t (row-major), one rounding per addition, left to right.
/// float64 or float32; dims = 0 returns t. Differentiable to any order (the
/// adjoint of a sum is a broadcast); first derivatives keep the fixed order,
/// second derivatives sum the broadcast's adjoint with LibTorch's sum (none
/// of our training paths takes them). Example: ordered_sum(x, 2) of
/// [E, B, n] is [E].
torch::Tensor ordered_sum(const torch::Tensor& t, int64_t dims);

/// ordered_sum(t, dims) / (number of summed elements).
torch::Tensor ordered_mean(const torch::Tensor& t, int64_t dims);

/// a * b with broadcasting, whose backward sums each operand's adjoint over
/// all its broadcast dimensions at once by ordered_sum, their elements in
/// row-major order (LibTorch's autograd would use its own sum there, in an
/// order set by the vector width). Same dimension count for both operands.
torch::Tensor ordered_broadcast_mul(const torch::Tensor& a, const torch::Tensor& b);

/// t.expand(sizes) (same dimension count; t's broadcast dimensions of size
/// 1), whose backward sums the adjoint over the expanded dimensions at once
/// by ordered_sum, in row-major order: a bias added to a batch, a weight row
/// broadcast over a batch.
torch::Tensor ordered_expand(const torch::Tensor& t, const std::vector<int64_t>& sizes);

/// torch::matmul(a, b) for a [..., n, m] and b [..., m, k] (batch
/// dimensions broadcast; at least 2-D each), each element summed over m in
/// order by ordered_sum: for the small products of the op-by-op model paths,
/// where torch::matmul would call BLAS kernels chosen by CPU.
torch::Tensor ordered_matmul(const torch::Tensor& a, const torch::Tensor& b);

}  // namespace internal
}  // namespace phnn
