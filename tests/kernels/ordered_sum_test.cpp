// tests/kernels/ordered_sum_test.cpp — the fixed-order sums: values equal the
// left-to-right loop bit for bit, gradients are the broadcast of the
// adjoint (first and second order), float32 too; the broadcast product's
// backward sums its broadcast dimensions in row-major order, and so does an
// ordered expand's.
#include "kernels/ordered_sum.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

namespace phnn {
namespace internal {
namespace {

TEST(OrderedSumTest, LeftToRightBitForBit) {
  torch::manual_seed(3);
  // Values of very different sizes, so another order would round differently.
  const auto t = torch::randn({3, 5, 7}, torch::kFloat64) * torch::pow(10.0, torch::randint(-8, 8, {3, 5, 7}).to(torch::kFloat64));
  const auto s = ordered_sum(t, 2);
  ASSERT_EQ(s.sizes(), torch::IntArrayRef({3}));
  for (int64_t o = 0; o < 3; ++o) {
    double acc = 0;
    for (int64_t i = 0; i < 5; ++i)
      for (int64_t k = 0; k < 7; ++k) acc += t[o][i][k].item<double>();
    EXPECT_EQ(s[o].item<double>(), acc) << o;
  }
  EXPECT_TRUE(torch::equal(ordered_sum(t, 0), t));
  EXPECT_TRUE(torch::allclose(ordered_sum(t, 3), t.sum().reshape({}), 1e-12, 1e-6));
  // A strided (non-contiguous) input sums in its logical order.
  const auto tt = t.transpose(1, 2);
  EXPECT_TRUE(torch::equal(ordered_sum(tt, 2), ordered_sum(tt.contiguous(), 2)));
  EXPECT_TRUE(torch::equal(ordered_mean(t, 1), ordered_sum(t, 1) / 7.0));
}

TEST(OrderedSumTest, GradientsFirstAndSecondOrder) {
  torch::manual_seed(4);
  const auto x = torch::randn({4, 6}, torch::kFloat64).requires_grad_(true);
  const auto w = torch::randn({4}, torch::kFloat64);
  // d/dx sum_o w_o sum_k x_ok^3 = 3 w_o x_ok^2; second order through the graph.
  const auto y = (ordered_sum(x * x * x, 1) * w).sum();
  const auto g = torch::autograd::grad({y}, {x}, {}, /*retain_graph=*/true, /*create_graph=*/true)[0];
  EXPECT_TRUE(torch::allclose(g, 3 * w.unsqueeze(1) * x * x, 1e-14, 0));
  const auto gg = torch::autograd::grad({g.sum()}, {x})[0];
  EXPECT_TRUE(torch::allclose(gg, 6 * w.unsqueeze(1) * x, 1e-14, 0));
  // The mean's gradient is 1 / count.
  const auto xm = torch::randn({2, 3, 5}, torch::kFloat64).requires_grad_(true);
  ordered_mean(xm, 2).sum().backward();
  EXPECT_TRUE(torch::allclose(xm.grad(), torch::full_like(xm, 1.0 / 15.0), 0, 0));
}

// a [2, 1, 3, 1] * b [2, 4, 3, 5]: a's adjoint sums 4 x 5 = 20 products per
// element over two broadcast dimensions that are not adjacent, in the order
// (j, l) row-major, one rounding per addition (the loop below).
TEST(OrderedSumTest, BroadcastProductSumsItsAdjointInRowMajorOrder) {
  torch::manual_seed(5);
  const auto scale = [](std::vector<int64_t> shape) {
    return torch::pow(10.0, torch::randint(-8, 8, shape).to(torch::kFloat64));
  };
  const auto a = (torch::randn({2, 1, 3, 1}, torch::kFloat64)).requires_grad_(true);
  const auto b = torch::randn({2, 4, 3, 5}, torch::kFloat64);
  const auto adj = torch::randn({2, 4, 3, 5}, torch::kFloat64) * scale({2, 4, 3, 5});
  const auto y = ordered_broadcast_mul(a, b);
  EXPECT_TRUE(torch::equal(y, a * b));
  const auto ga = torch::autograd::grad({y}, {a}, {adj})[0];
  ASSERT_EQ(ga.sizes(), a.sizes());
  for (int64_t i = 0; i < 2; ++i) {
    for (int64_t k = 0; k < 3; ++k) {
      double acc = 0;
      for (int64_t j = 0; j < 4; ++j)
        for (int64_t l = 0; l < 5; ++l) acc += adj[i][j][k][l].item<double>() * b[i][j][k][l].item<double>();
      EXPECT_EQ(ga[i][0][k][0].item<double>(), acc) << i << ", " << k;
    }
  }
}

TEST(OrderedSumTest, Float32) {
  const auto t = torch::tensor({1e8f, 1.0f, -1e8f, 1.0f}, torch::kFloat32).reshape({1, 4});
  EXPECT_EQ(ordered_sum(t, 1)[0].item<float>(), 1.0f);  // ((1e8 + 1) - 1e8) + 1 in float
}

// A bias [E, 1, n] expanded over a batch of B: its adjoint is summed over
// the batch in order, for a row of 48 floats (long enough for LibTorch's
// vectorized sum, whose order follows the vector width).
TEST(OrderedSumTest, ExpandSumsItsAdjointInRowMajorOrder) {
  torch::manual_seed(6);
  const auto bias = torch::randn({2, 1, 48}, torch::kFloat32).requires_grad_(true);
  const auto adj = torch::randn({2, 64, 48}, torch::kFloat32) *
                   torch::pow(10.0, torch::randint(-6, 6, {2, 64, 48})).to(torch::kFloat32);
  const auto y = ordered_expand(bias, {2, 64, 48});
  EXPECT_TRUE(torch::equal(y, bias.expand({2, 64, 48})));
  const auto g = torch::autograd::grad({y}, {bias}, {adj})[0];
  ASSERT_EQ(g.sizes(), bias.sizes());
  const auto a = adj.accessor<float, 3>();
  for (int64_t e = 0; e < 2; ++e) {
    for (int64_t k = 0; k < 48; ++k) {
      float acc = 0;
      for (int64_t b = 0; b < 64; ++b) acc += a[e][b][k];
      EXPECT_EQ(g[e][0][k].item<float>(), acc) << e << ", " << k;
    }
  }
  // Without a gradient to track it is a plain expand.
  const auto plain = ordered_expand(bias.detach(), {2, 64, 48});
  EXPECT_FALSE(plain.requires_grad());
  EXPECT_THROW(ordered_expand(bias, {64, 48}), std::exception);
}

}  // namespace
}  // namespace internal
}  // namespace phnn
