// include/phnn/common/small_lu.h — Gaussian elimination with partial
// pivoting of a small dense row-major matrix, in one fixed order of
// operations: the same bits on every CPU (LAPACK's solve runs kernels chosen
// by CPU) and no blocked path for tiny sizes (Eigen's PartialPivLU). Shared
// by the n-dimensional DG step (a factor reused across Newton iterations)
// and the learned models' implicit inference. A singular matrix gives
// inf/NaN, never an exception: callers mark such a step non-finite.
#pragma once

#include <cmath>
#include <utility>

namespace phnn {

/// Factors the n x n row-major `a` in place: the multipliers of L (unit
/// diagonal) below the diagonal, U on and above it; row k was swapped with
/// row perm[k] >= k at step k (the first largest |a_ik|).
inline void lu_factor(double* a, int* perm, int n) {
  for (int k = 0; k < n; ++k) {
    int pivot = k;
    for (int i = k + 1; i < n; ++i) {
      if (std::fabs(a[i * n + k]) > std::fabs(a[pivot * n + k])) pivot = i;
    }
    perm[k] = pivot;
    if (pivot != k) {
      for (int j = 0; j < n; ++j) std::swap(a[k * n + j], a[pivot * n + j]);
    }
    for (int i = k + 1; i < n; ++i) {
      a[i * n + k] /= a[k * n + k];
      for (int j = k + 1; j < n; ++j) a[i * n + j] -= a[i * n + k] * a[k * n + j];
    }
  }
}

/// b <- x with A x = b, from lu_factor's `lu` and `perm`: the row swaps in
/// order, then L, then U (each b_i receives the same operations, in the
/// same order, as when the swaps and L are applied during elimination).
inline void lu_solve(const double* lu, const int* perm, double* b, int n) {
  for (int k = 0; k < n; ++k) {
    if (perm[k] != k) std::swap(b[k], b[perm[k]]);
  }
  for (int k = 0; k < n; ++k) {
    for (int i = k + 1; i < n; ++i) b[i] -= lu[i * n + k] * b[k];
  }
  for (int i = n - 1; i >= 0; --i) {
    for (int j = i + 1; j < n; ++j) b[i] -= lu[i * n + j] * b[j];
    b[i] /= lu[i * n + i];
  }
}

}  // namespace phnn
