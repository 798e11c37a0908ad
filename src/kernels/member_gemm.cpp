// src/kernels/member_gemm.cpp — see member_gemm.h. Three kernels chosen by
// kernel_isa(): AVX-512 and AVX2 + FMA with intrinsics, and the portable
// tiles below for baseline x86-64 (and for float). All name their fused
// multiply-adds (an FMA instruction or std::fma: one rounding, by IEEE 754,
// in hardware or in libm) and the file has no contraction, so all three
// give the same bits.
//
// Blocking: C is cut into tiles of MR rows x NR columns held in registers
// while the inner index p runs 0..K-1; a tile's element (i, j) is the chain
//   s = c0;  for p: s = fma(A(i, p), B(p, j), s)
// and nothing else, so the tile shape (16, 8, 4, 1 columns; 8, 4, 3, 2 or 1
// rows), or AVX-512's lanes running over rows instead of columns, changes
// the speed, never the value.
#include "kernels/member_gemm.h"

#include <immintrin.h>

#include <cmath>
#include <vector>

#include "kernels/kernel_isa.h"

namespace phnn {
namespace internal {
namespace {

template <typename T>
struct Problem {
  int64_t rows, K, cols;
  const T* a;
  int64_t a_row, a_col;  // strides of A
  const T* b;            // row-major [K x cols], unit column stride
  int64_t ldb;
  T* c;                  // row-major [rows x cols]
  bool accumulate;
};

template <typename T, int MR, int NR>
PHNN_KERNEL_INLINE void tile(const Problem<T>& q, int64_t i, int64_t j) {
  T s[MR][NR];
  for (int r = 0; r < MR; ++r)
    for (int n = 0; n < NR; ++n) s[r][n] = q.accumulate ? q.c[(i + r) * q.cols + j + n] : T(0);
  const T* a = q.a + i * q.a_row;
  for (int64_t p = 0; p < q.K; ++p) {
    const T* bp = q.b + p * q.ldb + j;
    for (int r = 0; r < MR; ++r) {
      const T ar = a[r * q.a_row + p * q.a_col];
      for (int n = 0; n < NR; ++n) s[r][n] = std::fma(ar, bp[n], s[r][n]);
    }
  }
  for (int r = 0; r < MR; ++r)
    for (int n = 0; n < NR; ++n) q.c[(i + r) * q.cols + j + n] = s[r][n];
}

template <typename T, int MR>
PHNN_KERNEL_INLINE void row_block(const Problem<T>& q, int64_t i) {
  int64_t j = 0;
  for (; j + 16 <= q.cols; j += 16) tile<T, MR, 16>(q, i, j);
  if (j + 8 <= q.cols) {
    tile<T, MR, 8>(q, i, j);
    j += 8;
  }
  if (j + 4 <= q.cols) {
    tile<T, MR, 4>(q, i, j);
    j += 4;
  }
  for (; j < q.cols; ++j) tile<T, MR, 1>(q, i, j);
}

template <typename T>
PHNN_KERNEL_INLINE void gemm_body(const Problem<T>& q) {
  int64_t i = 0;
  for (; i + 4 <= q.rows; i += 4) row_block<T, 4>(q, i);
  for (; i < q.rows; ++i) row_block<T, 1>(q, i);
}

// AVX-512 and AVX2 for double, written with intrinsics so the tiles stay in
// registers: a tile is MR rows x NV vectors of columns, the last vector
// masked (lanes past the last column are neither loaded nor stored). Each
// lane runs the same chain as tile() above: same bits, ~3x its speed.
// The tile loops over r and v are unrolled by pragma: otherwise GCC kept the
// accumulators in a stack array and stored all of them on every p (8
// stores per 8 FMAs).
template <int MR, int NV>
__attribute__((target("arch=x86-64-v4"))) void tile_avx512(const Problem<double>& q, int64_t i,
                                                           int64_t j, __mmask8 tail) {
  const int64_t K = q.K, a_row = q.a_row, a_col = q.a_col, ldb = q.ldb, ldc = q.cols;
  const double* const a = q.a + i * a_row;
  const double* const b = q.b + j;
  double* const c = q.c + i * ldc + j;
  const auto mask = [tail](int v) { return v + 1 == NV ? tail : __mmask8(0xFF); };
  __m512d s[MR][NV];
#pragma GCC unroll 8
  for (int r = 0; r < MR; ++r)
#pragma GCC unroll 2
    for (int v = 0; v < NV; ++v)
      s[r][v] = q.accumulate ? _mm512_maskz_loadu_pd(mask(v), c + r * ldc + 8 * v)
                             : _mm512_setzero_pd();
  for (int64_t p = 0; p < K; ++p) {
    const double* bp = b + p * ldb;
    const double* ap = a + p * a_col;
    __m512d bv[NV];
#pragma GCC unroll 2
    for (int v = 0; v < NV; ++v)
      bv[v] = v + 1 == NV ? _mm512_maskz_loadu_pd(mask(v), bp + 8 * v)
                          : _mm512_loadu_pd(bp + 8 * v);
#pragma GCC unroll 8
    for (int r = 0; r < MR; ++r) {
      const __m512d ar = _mm512_set1_pd(ap[r * a_row]);
#pragma GCC unroll 2
      for (int v = 0; v < NV; ++v) s[r][v] = _mm512_fmadd_pd(ar, bv[v], s[r][v]);
    }
  }
#pragma GCC unroll 8
  for (int r = 0; r < MR; ++r)
#pragma GCC unroll 2
    for (int v = 0; v < NV; ++v) _mm512_mask_storeu_pd(c + r * ldc + 8 * v, mask(v), s[r][v]);
}

template <int MR>
__attribute__((target("arch=x86-64-v4"))) void rows_avx512(const Problem<double>& q, int64_t i) {
  int64_t j = 0;
  for (; j + 16 <= q.cols; j += 16) tile_avx512<MR, 2>(q, i, j, 0xFF);
  const int64_t rest = q.cols - j;
  if (rest > 8) tile_avx512<MR, 2>(q, i, j, static_cast<__mmask8>((1u << (rest - 8)) - 1));
  else if (rest > 0) tile_avx512<MR, 1>(q, i, j, static_cast<__mmask8>((1u << rest) - 1));
}

// Fewer than 8 columns with A's rows at unit stride (A is a transpose: the
// weight gradients x^T dY): the lanes run over 8 rows of C instead of its
// columns, 16 rows and NC columns at a time (2 NC independent chains where
// the row tiles had MR). Lane (i, j) is still the chain over p in order.
template <int NC>
__attribute__((target("arch=x86-64-v4"))) void columns_avx512(const Problem<double>& q) {
  const int64_t K = q.K, a_col = q.a_col, ldb = q.ldb, ldc = q.cols;
  const __m512i lane = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  const __m512i to_row = _mm512_mullo_epi64(lane, _mm512_set1_epi64(ldc));  // lane -> C offset
  for (int64_t i = 0; i < q.rows; i += 16) {
    const int64_t left = q.rows - i;
    const __mmask8 m0 = left >= 8 ? __mmask8(0xFF) : static_cast<__mmask8>((1u << left) - 1);
    const __mmask8 m1 = left >= 16 ? __mmask8(0xFF)
                        : left > 8 ? static_cast<__mmask8>((1u << (left - 8)) - 1)
                                   : __mmask8(0);
    double* const c = q.c + i * ldc;
    __m512d s0[NC], s1[NC];
#pragma GCC unroll 8
    for (int j = 0; j < NC; ++j) {
      s0[j] = _mm512_setzero_pd();
      s1[j] = _mm512_setzero_pd();
    }
    if (q.accumulate) {
#pragma GCC unroll 8
      for (int j = 0; j < NC; ++j) {
        s0[j] = _mm512_mask_i64gather_pd(s0[j], m0, to_row, c + j, 8);
        s1[j] = _mm512_mask_i64gather_pd(s1[j], m1, to_row, c + 8 * ldc + j, 8);
      }
    }
    const double* const a = q.a + i;  // A(i + l, p) = a[l + p * a_col]
    for (int64_t p = 0; p < K; ++p) {
      const __m512d a0 = _mm512_maskz_loadu_pd(m0, a + p * a_col);
      const __m512d a1 = _mm512_maskz_loadu_pd(m1, a + p * a_col + 8);
      const double* bp = q.b + p * ldb;
#pragma GCC unroll 8
      for (int j = 0; j < NC; ++j) {
        const __m512d bj = _mm512_set1_pd(bp[j]);
        s0[j] = _mm512_fmadd_pd(a0, bj, s0[j]);
        s1[j] = _mm512_fmadd_pd(a1, bj, s1[j]);
      }
    }
#pragma GCC unroll 8
    for (int j = 0; j < NC; ++j) {
      _mm512_mask_i64scatter_pd(c + j, m0, to_row, s0[j], 8);
      _mm512_mask_i64scatter_pd(c + 8 * ldc + j, m1, to_row, s1[j], 8);
    }
  }
}

__attribute__((target("arch=x86-64-v4"))) bool columns_avx512_for(const Problem<double>& q) {
  if (q.a_row != 1 || q.rows < 8) return false;
  switch (q.cols) {
    case 1: columns_avx512<1>(q); return true;
    case 2: columns_avx512<2>(q); return true;
    case 3: columns_avx512<3>(q); return true;
    case 4: columns_avx512<4>(q); return true;
    case 5: columns_avx512<5>(q); return true;
    case 6: columns_avx512<6>(q); return true;
    case 7: columns_avx512<7>(q); return true;
    default: return false;
  }
}

// Row blocks of 8 (8 or 16 independent chains per tile), then 4, then the
// 1-3 rows left in one tile.
__attribute__((target("arch=x86-64-v4"))) void run_avx512(const Problem<double>& q) {
  if (columns_avx512_for(q)) return;
  int64_t i = 0;
  for (; i + 8 <= q.rows; i += 8) rows_avx512<8>(q, i);
  for (; i + 4 <= q.rows; i += 4) rows_avx512<4>(q, i);
  switch (q.rows - i) {
    case 3: rows_avx512<3>(q, i); break;
    case 2: rows_avx512<2>(q, i); break;
    case 1: rows_avx512<1>(q, i); break;
    default: break;
  }
}

// AVX2: 4 lanes. Full vectors use plain loads and stores; only the last,
// partial vector of a row is masked (vmaskmovpd stores are microcoded on
// AMD CPUs: masking every vector cost 1.5x the whole training step).
__attribute__((target("arch=x86-64-v3"))) __m256i lanes_avx2(int64_t n) {
  return _mm256_cmpgt_epi64(_mm256_set1_epi64x(n), _mm256_setr_epi64x(0, 1, 2, 3));
}

__attribute__((target("arch=x86-64-v3"))) inline __m256d load_avx2(const double* p, __m256i mask,
                                                                    bool masked) {
  return masked ? _mm256_maskload_pd(p, mask) : _mm256_loadu_pd(p);
}

template <bool kMasked>
__attribute__((target("arch=x86-64-v3"))) inline void store_avx2(double* p, __m256i mask, __m256d v) {
  if (kMasked) {
    _mm256_maskstore_pd(p, mask, v);
  } else {
    _mm256_storeu_pd(p, v);
  }
}

// MR rows x NV vectors; when kMasked, the last vector holds `tail` lanes.
// Unrolled by pragma as tile_avx512.
template <int MR, int NV, bool kMasked>
__attribute__((target("arch=x86-64-v3"))) void tile_avx2(const Problem<double>& q, int64_t i,
                                                         int64_t j, int64_t tail) {
  const int64_t K = q.K, a_row = q.a_row, a_col = q.a_col, ldb = q.ldb, ldc = q.cols;
  const double* const a = q.a + i * a_row;
  const double* const b = q.b + j;
  double* const c = q.c + i * ldc + j;
  const __m256i mask = lanes_avx2(tail);
  __m256d s[MR][NV];
#pragma GCC unroll 4
  for (int r = 0; r < MR; ++r)
#pragma GCC unroll 2
    for (int v = 0; v < NV; ++v)
      s[r][v] = q.accumulate ? load_avx2(c + r * ldc + 4 * v, mask, kMasked && v + 1 == NV)
                             : _mm256_setzero_pd();
  for (int64_t p = 0; p < K; ++p) {
    const double* bp = b + p * ldb;
    const double* ap = a + p * a_col;
    __m256d bv[NV];
#pragma GCC unroll 2
    for (int v = 0; v < NV; ++v) bv[v] = load_avx2(bp + 4 * v, mask, kMasked && v + 1 == NV);
#pragma GCC unroll 4
    for (int r = 0; r < MR; ++r) {
      const __m256d ar = _mm256_set1_pd(ap[r * a_row]);
#pragma GCC unroll 2
      for (int v = 0; v < NV; ++v) s[r][v] = _mm256_fmadd_pd(ar, bv[v], s[r][v]);
    }
  }
#pragma GCC unroll 4
  for (int r = 0; r < MR; ++r)
#pragma GCC unroll 2
    for (int v = 0; v < NV; ++v) {
      if (v + 1 == NV) {
        store_avx2<kMasked>(c + r * ldc + 4 * v, mask, s[r][v]);
      } else {
        _mm256_storeu_pd(c + r * ldc + 4 * v, s[r][v]);
      }
    }
}

template <int MR>
__attribute__((target("arch=x86-64-v3"))) void rows_avx2(const Problem<double>& q, int64_t i) {
  int64_t j = 0;
  for (; j + 8 <= q.cols; j += 8) tile_avx2<MR, 2, false>(q, i, j, 4);
  const int64_t rest = q.cols - j;
  if (rest == 4) tile_avx2<MR, 1, false>(q, i, j, 4);
  else if (rest > 4) tile_avx2<MR, 2, true>(q, i, j, rest - 4);
  else if (rest > 0) tile_avx2<MR, 1, true>(q, i, j, rest);
}

__attribute__((target("arch=x86-64-v3"))) void run_avx2(const Problem<double>& q) {
  int64_t i = 0;
  for (; i + 4 <= q.rows; i += 4) rows_avx2<4>(q, i);
  for (; i < q.rows; ++i) rows_avx2<1>(q, i);
}

void run(const Problem<double>& q) {
  switch (kernel_isa()) {
    case KernelIsa::kAvx512: return run_avx512(q);
    case KernelIsa::kAvx2: return run_avx2(q);
    case KernelIsa::kBaseline: break;
  }
  gemm_body(q);
}

// float (float32 training only): the portable tiles, compiled per set.
PHNN_KERNEL_VARIANTS(void, run, (const Problem<float>& q), (q), gemm_body)

thread_local std::uint64_t g_multiply_adds = 0;

template <typename T>
void gemm_members(int64_t members, int64_t rows, int64_t K, int64_t cols, MatrixView<T> a,
                  MatrixView<T> b, T* c, bool accumulate) {
  g_multiply_adds += static_cast<std::uint64_t>(members * rows * K * cols);
  thread_local std::vector<T> packed;  // B with unit column stride, when it has not
  const bool pack = b.col_stride != 1;
  if (pack) packed.resize(static_cast<std::size_t>(K * cols));
  for (int64_t e = 0; e < members; ++e) {
    const T* be = b.data + e * b.member_stride;
    if (pack && (e == 0 || b.member_stride != 0)) {  // a broadcast B is packed once
      for (int64_t p = 0; p < K; ++p)
        for (int64_t j = 0; j < cols; ++j)
          packed[static_cast<std::size_t>(p * cols + j)] = be[p * b.row_stride + j * b.col_stride];
    }
    const Problem<T> q{rows,         K,          cols, a.data + e * a.member_stride,
                       a.row_stride, a.col_stride, pack ? packed.data() : be,
                       pack ? cols : b.row_stride, c + e * rows * cols, accumulate};
    run(q);
  }
}

}  // namespace

std::uint64_t gemm_multiply_adds() { return g_multiply_adds; }

void member_gemm(int64_t members, int64_t rows, int64_t K, int64_t cols, MatrixView<double> a,
                 MatrixView<double> b, double* c, bool accumulate) {
  gemm_members(members, rows, K, cols, a, b, c, accumulate);
}

void member_gemm(int64_t members, int64_t rows, int64_t K, int64_t cols, MatrixView<float> a,
                 MatrixView<float> b, float* c, bool accumulate) {
  gemm_members(members, rows, K, cols, a, b, c, accumulate);
}

}  // namespace internal
}  // namespace phnn
