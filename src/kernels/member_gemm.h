// src/kernels/member_gemm.h — the matrix products of the stacked networks
// (one small GEMM per ensemble member), computed by our own kernel so the
// bits do not depend on which BLAS kernels the CPU gets (docs/METHOD.md
// "Deterministic kernels"). Replaces the dgemm_/sgemm_ calls of fused_mlp.cpp
// and stacked_matmul.cpp; touches nothing else.
#pragma once

#include <cstdint>

namespace phnn {
namespace internal {

/// A [rows x cols] matrix per member: element (r, c) of member e is
/// data[e * member_stride + r * row_stride + c * col_stride].
template <typename T>
struct MatrixView {
  const T* data = nullptr;
  int64_t member_stride = 0;
  int64_t row_stride = 0;
  int64_t col_stride = 1;
};

/// For every member e < members, row-major dense C[e] [rows x cols]
/// (member stride rows * cols):
///
///   C(i, j) = fma(A(i, K-1), B(K-1, j), ... fma(A(i, 1), B(1, j), fma(A(i, 0), B(0, j), c0)))
///
/// c0 = 0, or C(i, j) itself when `accumulate`. Each element is that one
/// chain of correctly rounded fused multiply-adds over the inner index in
/// order, whatever the instruction set (kernel_isa.h) vectorizes over j:
/// the result is the same bits on every x86-64 CPU. A is [rows x K], B is
/// [K x cols]; K = 0 gives c0.
void member_gemm(int64_t members, int64_t rows, int64_t K, int64_t cols, MatrixView<double> a,
                 MatrixView<double> b, double* c, bool accumulate);
void member_gemm(int64_t members, int64_t rows, int64_t K, int64_t cols, MatrixView<float> a,
                 MatrixView<float> b, float* c, bool accumulate);

/// Multiply-adds of every member_gemm call of this thread so far
/// (members x rows x K x cols each): bench/ counts a step's matrix products
/// with it (the FLOP bound of docs/BENCHMARKS.md).
std::uint64_t gemm_multiply_adds();

}  // namespace internal
}  // namespace phnn
