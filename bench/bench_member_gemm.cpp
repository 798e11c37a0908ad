// bench/bench_member_gemm.cpp — µs per call and multiply-add rate of our
// member GEMM (src/kernels/member_gemm.h) on the shapes of one small
// PHNN-JR-RK2 training step (E = 10, batch 64, hidden 16: L_H's jet rows
// 192 = 64 x 3 channels, L_R's 64), on every instruction set this CPU has.
// Not a test; numbers in docs/BENCHMARKS.md ("Our own kernels").
//
//   bench_member_gemm [repeats]   best of `repeats` passes of 300 calls per shape
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "kernels/kernel_isa.h"
#include "kernels/member_gemm.h"

namespace {

using phnn::internal::MatrixView;

// C [rows x cols] (+)= A [rows x K] B [K x cols] per member. transpose_a: A
// is stored as [K x rows] (the weight gradients x^T dY); transpose_b: B is
// stored as [cols x K] (the backward products dY W^T).
struct Shape {
  const char* what;
  int rows, K, cols;
  bool transpose_a, transpose_b, accumulate;
};

const Shape kShapes[] = {
    {"L_H first layer", 192, 2, 16, false, false, false},
    {"L_H hidden", 192, 16, 16, false, false, false},
    {"L_H output", 192, 16, 3, false, false, false},
    {"L_H output, dX", 192, 3, 16, false, true, false},
    {"L_H hidden, dX", 192, 16, 16, false, true, false},
    {"L_H output, dW", 16, 192, 3, true, false, true},
    {"L_H hidden, dW", 16, 192, 16, true, false, true},
    {"L_H first, dW", 2, 192, 16, true, false, true},
    {"L_R first layer", 64, 3, 16, false, false, false},
    {"L_R hidden", 64, 16, 16, false, false, false},
    {"L_R output", 64, 16, 6, false, false, false},
    {"L_R output, dX", 64, 6, 16, false, true, false},
    {"L_R output, dW", 16, 64, 6, true, false, true},
    {"L_R first, dW", 3, 64, 16, true, false, true},
};

double best_seconds(const Shape& s, int repeats, std::vector<double>& a, std::vector<double>& b,
                    std::vector<double>& c) {
  constexpr int kMembers = 10, kCalls = 300;
  const MatrixView<double> av =
      s.transpose_a ? MatrixView<double>{a.data(), int64_t{s.K} * s.rows, 1, s.rows}
                    : MatrixView<double>{a.data(), int64_t{s.rows} * s.K, s.K, 1};
  const MatrixView<double> bv =
      s.transpose_b ? MatrixView<double>{b.data(), int64_t{s.K} * s.cols, 1, s.K}
                    : MatrixView<double>{b.data(), int64_t{s.K} * s.cols, s.cols, 1};
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kCalls; ++i)
      phnn::internal::member_gemm(kMembers, s.rows, s.K, s.cols, av, bv, c.data(), s.accumulate);
    const std::chrono::duration<double> t = std::chrono::steady_clock::now() - t0;
    best = std::min(best, t.count() / kCalls);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 15;
  std::vector<double> a(10 * 192 * 192), b(a.size()), c(a.size(), 0.125);
  for (std::size_t i = 0; i < a.size(); ++i) {
    a[i] = 0.5 + 1e-3 * static_cast<double>(i % 17);
    b[i] = 0.25 - 1e-3 * static_cast<double>(i % 13);
  }
  using phnn::internal::KernelIsa;
  for (const auto isa : {KernelIsa::kAvx512, KernelIsa::kAvx2, KernelIsa::kBaseline}) {
    const phnn::internal::ScopedKernelIsa scope(isa);
    if (phnn::internal::kernel_isa() != isa) continue;  // this CPU lacks it
    std::printf("\n%s, E = 10, best of %d x 300 calls\n\n", phnn::internal::kernel_isa_name(isa).c_str(),
                repeats);
    std::printf("| product | rows x K x cols | µs per call | G multiply-adds/s |\n");
    std::printf("|---|---|---|---|\n");
    double total = 0.0;
    for (const Shape& s : kShapes) {
      const double t = best_seconds(s, repeats, a, b, c);
      total += t;
      std::printf("| %s | %d x %d x %d | %.2f | %.2f |\n", s.what, s.rows, s.K, s.cols, t * 1e6,
                  10.0 * s.rows * s.K * s.cols / t * 1e-9);
    }
    std::printf("| all of the above | | %.1f | |\n", total * 1e6);
  }
  return 0;
}
