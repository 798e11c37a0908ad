// tests/models/stacked_matmul_test.cpp — the per-member dgemm product against
// torch::bmm, values and gradients, for plain, transposed and broadcast operands.
#include "models/stacked_matmul.h"

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
                                        torch::zeros({2, 4, 1}, torch::kFloat32)),
               c10::Error);
}

}  // namespace
}  // namespace phnn
