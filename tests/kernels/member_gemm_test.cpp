// tests/kernels/member_gemm_test.cpp — the member GEMM against its documented
// element formula (one std::fma chain over the inner index, in order), bit
// for bit, on every instruction set this CPU has, for tile-edge shapes and
// strided, transposed, broadcast and accumulating operands; and against a
// long-double product within the forward error bound.
#include "kernels/member_gemm.h"

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "kernels/kernel_isa.h"

namespace phnn {
namespace internal {
namespace {

struct Shape {
  int64_t E, rows, K, cols;
};

template <typename T>
std::vector<T> random_values(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<T> v(n);
  for (auto& x : v) x = static_cast<T>(u(rng));
  return v;
}

template <typename T>
T at(const MatrixView<T>& m, int64_t e, int64_t r, int64_t c) {
  return m.data[e * m.member_stride + r * m.row_stride + c * m.col_stride];
}

// The formula of member_gemm.h, element by element.
template <typename T>
std::vector<T> chain(const Shape& s, const MatrixView<T>& a, const MatrixView<T>& b,
                     const std::vector<T>& c0, bool accumulate) {
  std::vector<T> c(static_cast<std::size_t>(s.E * s.rows * s.cols));
  for (int64_t e = 0; e < s.E; ++e)
    for (int64_t i = 0; i < s.rows; ++i)
      for (int64_t j = 0; j < s.cols; ++j) {
        const auto k = static_cast<std::size_t>((e * s.rows + i) * s.cols + j);
        T acc = accumulate ? c0[k] : T(0);
        for (int64_t p = 0; p < s.K; ++p) acc = std::fma(at(a, e, i, p), at(b, e, p, j), acc);
        c[k] = acc;
      }
  return c;
}

template <typename T>
void check_shape(const Shape& s, bool transpose_a, bool transpose_b, bool broadcast_b,
                 bool accumulate) {
  const auto av = random_values<T>(static_cast<std::size_t>(s.E * s.rows * s.K), 1);
  const auto bv = random_values<T>(static_cast<std::size_t>(s.E * s.K * s.cols), 2);
  const auto c0 = random_values<T>(static_cast<std::size_t>(s.E * s.rows * s.cols), 3);
  const MatrixView<T> a = transpose_a ? MatrixView<T>{av.data(), s.rows * s.K, 1, s.rows}
                                      : MatrixView<T>{av.data(), s.rows * s.K, s.K, 1};
  MatrixView<T> b = transpose_b ? MatrixView<T>{bv.data(), s.K * s.cols, 1, s.K}
                                : MatrixView<T>{bv.data(), s.K * s.cols, s.cols, 1};
  if (broadcast_b) b.member_stride = 0;
  const auto expected = chain(s, a, b, c0, accumulate);
  for (const KernelIsa isa : {KernelIsa::kBaseline, KernelIsa::kAvx2, KernelIsa::kAvx512}) {
    const ScopedKernelIsa pin(isa);
    std::vector<T> c = c0;
    member_gemm(s.E, s.rows, s.K, s.cols, a, b, c.data(), accumulate);
    ASSERT_EQ(0, std::memcmp(c.data(), expected.data(), c.size() * sizeof(T)))
        << "isa " << kernel_isa_name(kernel_isa()) << " E " << s.E << " rows " << s.rows << " K "
        << s.K << " cols " << s.cols << " transposed " << transpose_a << transpose_b
        << " broadcast " << broadcast_b << " accumulate " << accumulate;
  }
}

TEST(MemberGemmTest, EveryInstructionSetGivesTheDocumentedChainBitForBit) {
  // Columns around the 16/8/4/1 tiles, rows around the 8- and 4-row blocks
  // and their 1-3 row rests, K = 0; with a transposed A, fewer than 8
  // columns over 8, 16 and 16 + 3 rows (the kernels over rows).
  const std::vector<Shape> shapes{
      {2, 1, 1, 1},     {3, 4, 16, 16}, {2, 5, 3, 17},  {1, 7, 2, 31}, {2, 9, 16, 3},
      {1, 64, 16, 16},  {2, 3, 0, 5},   {1, 13, 33, 12}, {2, 192, 2, 16}, {1, 16, 192, 16},
      {2, 19, 40, 6},   {1, 16, 7, 7},  {2, 8, 5, 1},   {1, 26, 3, 2},  {1, 14, 9, 4},
      {2, 11, 4, 9}};
  for (const auto& s : shapes)
    for (int flags = 0; flags < 16; ++flags) {
      check_shape<double>(s, flags & 1, flags & 2, flags & 4, flags & 8);
      check_shape<float>(s, flags & 1, flags & 2, flags & 4, flags & 8);
    }
}

// Independent check of the values: |c - exact| <= K u sum |a||b| (the
// forward error bound of a dot product, u = 2^-53), exact taken in long
// double (64-bit mantissa: its own error is 2^-11 of that bound).
TEST(MemberGemmTest, WithinTheDotProductErrorBound) {
  const Shape s{2, 11, 40, 19};
  const auto av = random_values<double>(static_cast<std::size_t>(s.E * s.rows * s.K), 4);
  const auto bv = random_values<double>(static_cast<std::size_t>(s.E * s.K * s.cols), 5);
  std::vector<double> c(static_cast<std::size_t>(s.E * s.rows * s.cols));
  member_gemm(s.E, s.rows, s.K, s.cols, {av.data(), s.rows * s.K, s.K, 1},
              {bv.data(), s.K * s.cols, s.cols, 1}, c.data(), false);
  for (int64_t e = 0; e < s.E; ++e)
    for (int64_t i = 0; i < s.rows; ++i)
      for (int64_t j = 0; j < s.cols; ++j) {
        long double exact = 0, magnitude = 0;
        for (int64_t p = 0; p < s.K; ++p) {
          const long double x = av[static_cast<std::size_t>((e * s.rows + i) * s.K + p)];
          const long double y = bv[static_cast<std::size_t>((e * s.K + p) * s.cols + j)];
          exact += x * y;
          magnitude += std::fabs(x * y);
        }
        const double got = c[static_cast<std::size_t>((e * s.rows + i) * s.cols + j)];
        EXPECT_LE(std::fabs(static_cast<long double>(got) - exact),
                  static_cast<long double>(s.K) * std::ldexp(1.0L, -53) * magnitude)
            << e << " " << i << " " << j;
      }
}

}  // namespace
}  // namespace internal
}  // namespace phnn
