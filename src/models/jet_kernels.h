// src/models/jet_kernels.h — the elementwise part of a tanh layer's jet and
// its adjoint (formulas (F) and (B) in fused_mlp.cpp), compiled for
// AVX-512, AVX2 and baseline x86-64 and chosen by kernel_isa.h.
#pragma once

#include <cstdint>

namespace phnn {
namespace internal {

/// Channels of a jet with d directions up to `order`: 0 the value,
/// 1..d the tangents, then the d(d+1)/2 pairs (i <= j) in row order.
/// Each array holds E members of C channels of n values.

/// (F): activations a from pre-activations z and t = tanh(z_0) [E][n].
void tanh_jet_forward(int64_t d, int64_t order, int64_t E, int64_t n, const double* z,
                      const double* t, double* a);

/// (B): adjoint z_bar of the pre-activations from the adjoint a_bar of the
/// activations (separate buffers).
void tanh_jet_backward(int64_t d, int64_t order, int64_t E, int64_t n, const double* z,
                       const double* t, const double* a_bar, double* z_bar);

}  // namespace internal
}  // namespace phnn
