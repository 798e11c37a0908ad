// src/kernels/jet_kernels.h — the elementwise part of a tanh layer's jet and
// its adjoint (formulas (F) and (B) in fused_mlp.cpp), and the bias of a
// linear layer and its adjoint, compiled for AVX-512, AVX2 and baseline
// x86-64 and chosen by kernel_isa.h.
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

/// z[e][r][k] += b[e][k] for the B rows r < B of each member's block of
/// `stride` values in z (the value channel of a jet), k < n.
void add_bias(int64_t E, int64_t B, int64_t n, int64_t stride, const double* b, double* z);

/// b_bar[e][k] += z_bar[e][r][k] over r = 0, 1, ..., B - 1 in that order (so
/// each element is one chain of additions whatever the vector width), for
/// the B rows of each member's block of `stride` values in z_bar.
void sum_bias(int64_t E, int64_t B, int64_t n, int64_t stride, const double* z_bar,
              double* b_bar);

}  // namespace internal
}  // namespace phnn
