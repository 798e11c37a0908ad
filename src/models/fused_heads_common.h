// src/models/fused_heads_common.h — shared by the fused heads of src/models
// only (general*_heads.cpp, general_curvature_head.cpp; manual_step.cpp for rows_like):
// softplus/sigmoid from one exp, and the row and lower-triangle indexing of
// the n-state heads.
#pragma once

#include <torch/torch.h>

#include <cmath>
#include <vector>

#include "models/head_sizes.h"
#include "kernels/vector_math.h"

namespace phnn {
namespace internal {
namespace heads {

using torch::Tensor;
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// sigmoid(x) from z = exp(-|x|), without overflow for either sign.
inline double sigmoid_from(double x, double z) {
  return x >= 0.0 ? 1.0 / (1.0 + z) : z / (1.0 + z);
}

// sigmoid(x) alone (one exp).
inline double sigmoid_of(double x) { return sigmoid_from(x, exp_nonpositive(-std::fabs(x))); }

// softplus(x) and sigmoid(x) from one exp(-|x|); above x = 20 softplus is x
// and its slope 1, as in LibTorch's softplus (threshold 20).
struct SoftplusSigmoid {
  double softplus, sigmoid, slope;
  explicit SoftplusSigmoid(double x) {
    const double z = exp_nonpositive(-std::fabs(x));
    sigmoid = sigmoid_from(x, z);
    softplus = x > 20.0 ? x : std::fmax(x, 0.0) + log1p_unit(z);
    slope = x > 20.0 ? 1.0 : sigmoid;
  }
};

// SoftplusSigmoid of some columns of a row-major [rows, width] array, for
// all rows in one softplus_sigmoid_array call (vectorized; the same bits as
// SoftplusSigmoid row by row). Stored in `data` [3][columns][rows]
// (softplus, sigmoid, slope), which a head may save for its backward.
class SoftplusColumns {
 public:
  static int64_t size(int columns, int64_t rows) { return 3 * columns * rows; }
  static SoftplusColumns compute(const double* o, int64_t width, const std::vector<int>& columns,
                                 int64_t rows, double* data) {
    const auto n = static_cast<int64_t>(columns.size()) * rows;
    thread_local std::vector<double> in;
    in.resize(static_cast<std::size_t>(n));
    int64_t k = 0;
    for (const int column : columns)
      for (int64_t r = 0; r < rows; ++r) in[static_cast<std::size_t>(k++)] = o[r * width + column];
    softplus_sigmoid_array(in.data(), n, data, data + n, data + 2 * n);
    return saved(static_cast<int>(columns.size()), rows, data);
  }
  static SoftplusColumns saved(int columns, int64_t rows, const double* data) {
    return SoftplusColumns(columns, rows, data);
  }
  // Of the k-th column asked for, row r.
  double softplus(int k, int64_t r) const { return data_[k * rows_ + r]; }
  double sigmoid(int k, int64_t r) const { return data_[(columns_ + k) * rows_ + r]; }
  double slope(int k, int64_t r) const { return data_[(2 * columns_ + k) * rows_ + r]; }

 private:
  SoftplusColumns(int columns, int64_t rows, const double* data)
      : columns_(columns), rows_(rows), data_(data) {}
  int columns_;
  int64_t rows_;
  const double* data_;
};

inline Tensor dense(const Tensor& t) { return t.contiguous(); }

// Rows of an [E, B, ...] tensor: one member and one batch element each.
inline int64_t rows_of(const Tensor& t) { return t.size(0) * t.size(1); }

// u [.., .., n_u] broadcast to the rows of `like` and made contiguous.
inline Tensor rows_like(const Tensor& u, const Tensor& like) {
  return u.expand({like.size(0), like.size(1), u.size(-1)}).contiguous();
}

// Row-major lower triangle: entry (r, c), c <= r, is output r (r + 1) / 2 + c.
inline int tri(int r, int c) { return r * (r + 1) / 2 + c; }

// y = L x and x = L^T y for a lower-triangular n x n L stored as its
// row-major triangle, each entry one sum in index order (N: head_sizes.h).
template <int N = 0>
void lower_times(const double* L, const double* x, int n_rt, double* y) {
  const int n = size_of<N>(n_rt);
  for (int r = 0; r < n; ++r) {
    double s = 0.0;
    for (int c = 0; c <= r; ++c) s += L[tri(r, c)] * x[c];
    y[r] = s;
  }
}
template <int N = 0>
void lower_transpose_times(const double* L, const double* y, int n_rt, double* x) {
  const int n = size_of<N>(n_rt);
  for (int c = 0; c < n; ++c) {
    double s = 0.0;
    for (int r = c; r < n; ++r) s += L[tri(r, c)] * y[r];
    x[c] = s;
  }
}

// (K - K^T)_rc of a port network's outputs o [n (n + 1) / 2 + n (n - 1) / 2]:
// L's triangle, then K's strictly lower triangle row by row.
inline double skew_entry(const double* o, int n, int r, int c) {
  if (r == c) return 0.0;
  const int base = n * (n + 1) / 2;
  return r > c ? o[base + r * (r - 1) / 2 + c] : -o[base + c * (c - 1) / 2 + r];
}

}  // namespace heads
}  // namespace internal
}  // namespace phnn
