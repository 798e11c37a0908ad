// src/kernels/jet_kernels.cpp — see jet_kernels.h. Each loop lives in its own
// inline function with restrict-qualified channel pointers (the channels of
// one buffer never overlap), so the compiler vectorizes it; compiled without
// FMA contraction so every clone gives the same bits.
#include "kernels/jet_kernels.h"

#include "kernels/kernel_isa.h"

namespace phnn {
namespace internal {
namespace {

using Out = double* __restrict__;
using In = const double* __restrict__;

PHNN_KERNEL_INLINE int64_t pair_count(int64_t d, int64_t order) { return order >= 2 ? d * (d + 1) / 2 : 0; }
PHNN_KERNEL_INLINE int64_t channels(int64_t d, int64_t order) {
  return 1 + (order >= 1 ? d : 0) + pair_count(d, order);
}

// a_i = s z_i, s = 1 - t^2.
PHNN_KERNEL_INLINE void tangent_forward(In t, In zi, Out ai, int64_t n) {
  for (int64_t k = 0; k < n; ++k) ai[k] = (1.0 - t[k] * t[k]) * zi[k];
}
// a_ij = s z_ij - 2 t s z_i z_j.
PHNN_KERNEL_INLINE void pair_forward(In t, In zi, In zj, In zp, Out ap, int64_t n) {
  for (int64_t k = 0; k < n; ++k) {
    const double s = 1.0 - t[k] * t[k];
    ap[k] = s * zp[k] - 2.0 * t[k] * s * zi[k] * zj[k];
  }
}
// z~_0 = s a~_0.
PHNN_KERNEL_INLINE void value_backward(In t, In ab, Out zb, int64_t n) {
  for (int64_t k = 0; k < n; ++k) zb[k] = (1.0 - t[k] * t[k]) * ab[k];
}
// z~_0 += s1 a~_i z_i,  z~_i = s a~_i.
PHNN_KERNEL_INLINE void tangent_backward(In t, In zi, In abi, Out zb0, Out zbi, int64_t n) {
  for (int64_t k = 0; k < n; ++k) {
    const double s = 1.0 - t[k] * t[k];
    zb0[k] += -2.0 * t[k] * s * abi[k] * zi[k];
    zbi[k] = s * abi[k];
  }
}
// Pair (i, j), i != j: z~_0 += a~_ij (s1 z_ij + s2 z_i z_j), z~_ij = s a~_ij,
// z~_i += s1 a~_ij z_j, z~_j += s1 a~_ij z_i.
PHNN_KERNEL_INLINE void pair_backward(In t, In zi, In zj, In zp, In abp, Out zb0, Out zbi, Out zbj, Out zbp,
                          int64_t n) {
  for (int64_t k = 0; k < n; ++k) {
    const double tt = t[k] * t[k], s = 1.0 - tt, s1 = -2.0 * t[k] * s;
    zb0[k] += abp[k] * (s1 * zp[k] + s * (6.0 * tt - 2.0) * zi[k] * zj[k]);
    zbp[k] = s * abp[k];
    zbi[k] += s1 * abp[k] * zj[k];
    zbj[k] += s1 * abp[k] * zi[k];
  }
}
// Pair (i, i): as above with z~_i += 2 s1 a~_ii z_i.
PHNN_KERNEL_INLINE void diagonal_pair_backward(In t, In zi, In zp, In abp, Out zb0, Out zbi, Out zbp, int64_t n) {
  for (int64_t k = 0; k < n; ++k) {
    const double tt = t[k] * t[k], s = 1.0 - tt, s1 = -2.0 * t[k] * s;
    zb0[k] += abp[k] * (s1 * zp[k] + s * (6.0 * tt - 2.0) * zi[k] * zi[k]);
    zbp[k] = s * abp[k];
    zbi[k] += s1 * abp[k] * zi[k] + s1 * abp[k] * zi[k];
  }
}

// Order 1 with D <= 4 directions (L_H of the 2- to 4-state models): the
// passes above fused into one loop per element, with the same operations in
// the same order (so the same bits), t and z~_0 read once instead of D + 1
// times. Channel c of a member's block starts at c n.
template <int D>
PHNN_KERNEL_INLINE void forward_order1(In t, In z, Out a, int64_t n) {
  for (int64_t k = 0; k < n; ++k) {
    const double s = 1.0 - t[k] * t[k];
    a[k] = t[k];
#pragma GCC unroll 4
    for (int i = 1; i <= D; ++i) a[i * n + k] = s * z[i * n + k];
  }
}
template <int D>
PHNN_KERNEL_INLINE void backward_order1(In t, In z, In ab, Out zb, int64_t n) {
  for (int64_t k = 0; k < n; ++k) {
    const double s = 1.0 - t[k] * t[k];
    double value = s * ab[k];
#pragma GCC unroll 4
    for (int i = 1; i <= D; ++i) {
      value += -2.0 * t[k] * s * ab[i * n + k] * z[i * n + k];
      zb[i * n + k] = s * ab[i * n + k];
    }
    zb[k] = value;
  }
}

// Runs the fused order-1 loops for d <= 4; false for the general passes.
PHNN_KERNEL_INLINE bool order1_forward(int64_t d, In t, In z, Out a, int64_t n) {
  switch (d) {
    case 1: forward_order1<1>(t, z, a, n); return true;
    case 2: forward_order1<2>(t, z, a, n); return true;
    case 3: forward_order1<3>(t, z, a, n); return true;
    case 4: forward_order1<4>(t, z, a, n); return true;
    default: return false;
  }
}
PHNN_KERNEL_INLINE bool order1_backward(int64_t d, In t, In z, In ab, Out zb, int64_t n) {
  switch (d) {
    case 1: backward_order1<1>(t, z, ab, zb, n); return true;
    case 2: backward_order1<2>(t, z, ab, zb, n); return true;
    case 3: backward_order1<3>(t, z, ab, zb, n); return true;
    case 4: backward_order1<4>(t, z, ab, zb, n); return true;
    default: return false;
  }
}

PHNN_KERNEL_INLINE void forward_body(int64_t d, int64_t order, int64_t E, int64_t n, const double* z,
                      const double* t, double* a) {
  const int64_t C = channels(d, order);
  for (int64_t e = 0; e < E; ++e) {
    const double* ze = z + e * C * n;
    const double* te = t + e * n;
    double* ae = a + e * C * n;
    if (order == 1 && order1_forward(d, te, ze, ae, n)) continue;
    for (int64_t k = 0; k < n; ++k) ae[k] = te[k];
    if (order < 1) continue;
    for (int64_t i = 0; i < d; ++i) tangent_forward(te, ze + (1 + i) * n, ae + (1 + i) * n, n);
    int64_t p = 1 + d;
    for (int64_t i = 0; i < d && order >= 2; ++i) {
      for (int64_t j = i; j < d; ++j, ++p) {
        pair_forward(te, ze + (1 + i) * n, ze + (1 + j) * n, ze + p * n, ae + p * n, n);
      }
    }
  }
}

PHNN_KERNEL_INLINE void backward_body(int64_t d, int64_t order, int64_t E, int64_t n, const double* z,
                       const double* t, const double* a_bar, double* z_bar) {
  const int64_t C = channels(d, order);
  for (int64_t e = 0; e < E; ++e) {
    const double* ze = z + e * C * n;
    const double* te = t + e * n;
    const double* ab = a_bar + e * C * n;
    double* zb = z_bar + e * C * n;
    if (order == 1 && order1_backward(d, te, ze, ab, zb, n)) continue;
    value_backward(te, ab, zb, n);
    if (order < 1) continue;
    for (int64_t i = 0; i < d; ++i) {
      tangent_backward(te, ze + (1 + i) * n, ab + (1 + i) * n, zb, zb + (1 + i) * n, n);
    }
    int64_t p = 1 + d;
    for (int64_t i = 0; i < d && order >= 2; ++i) {
      for (int64_t j = i; j < d; ++j, ++p) {
        if (i == j) {
          diagonal_pair_backward(te, ze + (1 + i) * n, ze + p * n, ab + p * n, zb,
                                 zb + (1 + i) * n, zb + p * n, n);
        } else {
          pair_backward(te, ze + (1 + i) * n, ze + (1 + j) * n, ze + p * n, ab + p * n, zb,
                        zb + (1 + i) * n, zb + (1 + j) * n, zb + p * n, n);
        }
      }
    }
  }
}

PHNN_KERNEL_INLINE void add_bias_body(int64_t E, int64_t B, int64_t n, int64_t stride, In b,
                                      Out z) {
  for (int64_t e = 0; e < E; ++e)
    for (int64_t r = 0; r < B; ++r) {
      double* __restrict__ row = z + e * stride + r * n;
      const double* __restrict__ be = b + e * n;
      for (int64_t k = 0; k < n; ++k) row[k] += be[k];
    }
}

PHNN_KERNEL_INLINE void sum_bias_body(int64_t E, int64_t B, int64_t n, int64_t stride, In z_bar,
                                      Out b_bar) {
  for (int64_t e = 0; e < E; ++e)
    for (int64_t r = 0; r < B; ++r) {
      const double* __restrict__ row = z_bar + e * stride + r * n;
      double* __restrict__ be = b_bar + e * n;
      for (int64_t k = 0; k < n; ++k) be[k] += row[k];
    }
}

}  // namespace

PHNN_KERNEL_VARIANTS(void, add_bias,
                     (int64_t E, int64_t B, int64_t n, int64_t stride, const double* b, double* z),
                     (E, B, n, stride, b, z), add_bias_body)
PHNN_KERNEL_VARIANTS(void, sum_bias,
                     (int64_t E, int64_t B, int64_t n, int64_t stride, const double* z_bar,
                      double* b_bar),
                     (E, B, n, stride, z_bar, b_bar), sum_bias_body)

PHNN_KERNEL_VARIANTS(void, tanh_jet_forward,
                     (int64_t d, int64_t order, int64_t E, int64_t n, const double* z,
                      const double* t, double* a),
                     (d, order, E, n, z, t, a), forward_body)
PHNN_KERNEL_VARIANTS(void, tanh_jet_backward,
                     (int64_t d, int64_t order, int64_t E, int64_t n, const double* z,
                      const double* t, const double* a_bar, double* z_bar),
                     (d, order, E, n, z, t, a_bar, z_bar), backward_body)

}  // namespace internal
}  // namespace phnn
