// tests/kernels/stacked_matmul_test.cpp — the per-member dgemm product against
// torch::bmm, values and gradients, for plain, transposed and broadcast operands;
// the sgemm product of float32 training.
#include "kernels/stacked_matmul.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

namespace phnn {
namespace {

double max_abs_diff(const torch::Tensor& a, const torch::Tensor& b) {
  return (a - b).abs().max().item<double>();
}

TEST(StackedMatmulTest, MatchesBmmForPlainTransposedAndBroadcastOperands) {
  torch::manual_seed(0);
  const auto opts = torch::TensorOptions().dtype(torch::kFloat64);
  const auto a = torch::randn({4, 7, 5}, opts);
  const auto b = torch::randn({4, 5, 3}, opts);
  // Tolerance: K = 5 products of O(1) numbers; dgemm and bmm may sum in
  // different orders.
  const double tol = 1e-14;
  EXPECT_LE(max_abs_diff(internal::stacked_matmul(a, b), torch::bmm(a, b)), tol);
  const auto at = torch::randn({4, 5, 7}, opts).transpose(1, 2);  // transposed view
  EXPECT_LE(max_abs_diff(internal::stacked_matmul(at, b), torch::bmm(at, b)), tol);
  const auto bt = torch::randn({4, 3, 5}, opts).transpose(1, 2);
  EXPECT_LE(max_abs_diff(internal::stacked_matmul(a, bt), torch::bmm(a, bt)), tol);
  const auto bb = torch::randn({1, 5, 3}, opts).expand({4, 5, 3});  // stride 0 along E
  EXPECT_LE(max_abs_diff(internal::stacked_matmul(a, bb), torch::bmm(a, bb)), tol);
  const auto strided = torch::randn({4, 7, 10}, opts).narrow(2, 2, 5);  // ld > cols
  EXPECT_LE(max_abs_diff(internal::stacked_matmul(strided, b), torch::bmm(strided, b)), tol);
}

TEST(StackedMatmulTest, GradientsMatchBmmToSecondOrder) {
  torch::manual_seed(1);
  const auto opts = torch::TensorOptions().dtype(torch::kFloat64);
  auto a1 = torch::randn({3, 6, 4}, opts).requires_grad_(true);
  auto b1 = torch::randn({3, 4, 2}, opts).requires_grad_(true);
  auto a2 = a1.detach().clone().requires_grad_(true);
  auto b2 = b1.detach().clone().requires_grad_(true);
  const auto w = torch::randn({3, 6, 2}, opts);
  const auto y1 = (torch::tanh(internal::stacked_matmul(a1, b1)) * w).sum();
  const auto y2 = (torch::tanh(torch::bmm(a2, b2)) * w).sum();
  const auto g1 = torch::autograd::grad({y1}, {a1, b1}, {}, true, /*create_graph=*/true);
  const auto g2 = torch::autograd::grad({y2}, {a2, b2}, {}, true, /*create_graph=*/true);
  EXPECT_LE(max_abs_diff(g1[0], g2[0]), 1e-13);
  EXPECT_LE(max_abs_diff(g1[1], g2[1]), 1e-13);
  // Second order: gradient of |dy/da|^2 w.r.t. b.
  const auto h1 = torch::autograd::grad({g1[0].pow(2).sum()}, {b1})[0];
  const auto h2 = torch::autograd::grad({g2[0].pow(2).sum()}, {b2})[0];
  EXPECT_LE(max_abs_diff(h1, h2), 1e-12);
}

TEST(StackedMatmulTest, RejectsMismatchedShapes) {
  const auto opts = torch::TensorOptions().dtype(torch::kFloat64);
  EXPECT_THROW(internal::stacked_matmul(torch::zeros({2, 3, 4}, opts), torch::zeros({2, 5, 1}, opts)),
               c10::Error);
  EXPECT_THROW(internal::stacked_matmul(torch::zeros({2, 3, 4}, torch::kFloat32),
                                        torch::zeros({2, 4, 1}, opts)),
               c10::Error);
  EXPECT_THROW(internal::stacked_matmul(torch::zeros({2, 3, 4}, torch::kInt32),
                                        torch::zeros({2, 4, 1}, torch::kInt32)),
               c10::Error);
}

// float32 operands (float32 training): a float32 product and gradient equal
// to the float64 product of the same values to float32 round-off (K = 5
// products of O(1) numbers: ~1e-6), and each member's product bitwise the
// one it has alone (one sgemm per member), also for a transposed operand.
TEST(StackedMatmulTest, Float32IsOneSgemmPerMember) {
  torch::manual_seed(2);
  const auto a = torch::randn({4, 7, 5}, torch::kFloat32).requires_grad_(true);
  const auto b = torch::randn({4, 3, 5}, torch::kFloat32).transpose(1, 2);
  const auto c = internal::stacked_matmul(a, b);
  ASSERT_EQ(c.scalar_type(), torch::kFloat32);
  const auto exact = torch::bmm(a.detach().to(torch::kFloat64), b.to(torch::kFloat64));
  EXPECT_LE(max_abs_diff(c.detach().to(torch::kFloat64), exact), 1e-5);
  EXPECT_GT(max_abs_diff(c.detach().to(torch::kFloat64), exact), 0.0);
  for (int64_t e = 0; e < 4; ++e) {
    const auto alone = internal::stacked_matmul(a.detach().narrow(0, e, 1), b.narrow(0, e, 1));
    EXPECT_TRUE(torch::equal(alone[0], c.detach()[e])) << e;
  }
  const auto g = torch::autograd::grad({c.sum()}, {a})[0];
  ASSERT_EQ(g.scalar_type(), torch::kFloat32);
  // d sum(A B) / dA = 1 B^T: each row the column sums of B^T.
  const auto expected = b.sum(2).unsqueeze(1).expand({4, 7, 5}).to(torch::kFloat64);
  EXPECT_LE(max_abs_diff(g.to(torch::kFloat64), expected), 1e-5);
}

}  // namespace
}  // namespace phnn
