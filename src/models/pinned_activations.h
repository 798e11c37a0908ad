// src/models/pinned_activations.h — tanh, softplus and sigmoid on tensors by
// our own scalar kernels (vector_math.h), differentiable to any order, for
// the op-by-op model paths (the reference jets, DG4's effort jets, float64
// networks that are not fused). LibTorch's versions go through Sleef under
// AVX2/AVX-512 and through the C library otherwise, so their last bits
// changed with ATEN_CPU_CAPABILITY (docs/METHOD.md "Deterministic kernels").
#pragma once

#include <torch/torch.h>

namespace phnn {
namespace internal {

/// tanh(x), float64 or float32 (float32 elements: the float64 kernel's
/// value rounded to float, so float32 training is pinned too).
torch::Tensor pinned_tanh(const torch::Tensor& x);

/// log(1 + e^x), and x above 20 as LibTorch's threshold; slope sigmoid(x)
/// (1 above 20). float64 or float32 (as pinned_tanh).
torch::Tensor pinned_softplus(const torch::Tensor& x);

/// 1 / (1 + e^-x), slope s (1 - s). float64 or float32 (as pinned_tanh).
torch::Tensor pinned_sigmoid(const torch::Tensor& x);

}  // namespace internal
}  // namespace phnn
