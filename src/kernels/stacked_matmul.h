// src/kernels/stacked_matmul.h — per-member matrix products of a model stack.
#pragma once

#include <torch/torch.h>

namespace phnn {
namespace internal {

/// c[e] = a[e] @ b[e] for a [E, R, K], b [E, K, N] (float64, or float32 for
/// float32 training; either operand may be a transposed view or broadcast
/// along E with stride 0), as one autograd node whose forward and backward
/// call member_gemm.h's kernel on raw pointers (same bits on every CPU; it
/// replaced one BLAS dgemm/sgemm per member). LibTorch 1.13's
/// CPU bmm instead creates a view tensor per member and dispatches addmm_ on
/// it: for E = 10 small matrices that bookkeeping was ~60 % of a training
/// step (measured with the autograd profiler). The backward is built from
/// stacked_matmul itself, so the product stays differentiable to any order.
torch::Tensor stacked_matmul(const torch::Tensor& a, const torch::Tensor& b);

}  // namespace internal
}  // namespace phnn
