// tests/models/pinned_activations_test.cpp — the op-by-op activations in
// float32: each element is the float64 pinned kernel's value rounded to
// float, whatever the tensor's layout or length (so a member's bits do not
// depend on its place in a stack), and the slopes are the closed forms.
#include "models/pinned_activations.h"

#include <cmath>
#include <functional>

#include <gtest/gtest.h>
#include <torch/torch.h>

namespace phnn {
namespace internal {
namespace {

using Activation = std::function<torch::Tensor(const torch::Tensor&)>;

// Arguments across the ranges the networks see, with both signs, the
// softplus threshold (20) and values near zero.
torch::Tensor arguments() {
  torch::manual_seed(7);
  auto x = torch::randn({4099}, torch::kFloat64) * 6.0;
  x.narrow(0, 0, 5).copy_(torch::tensor({0.0, -0.0, 20.0, 20.5, -30.0}, torch::kFloat64));
  return x.to(torch::kFloat32);
}

void expect_rounded_float64(const Activation& f, const char* name) {
  const auto x = arguments();
  const auto y32 = f(x);
  ASSERT_EQ(y32.scalar_type(), torch::kFloat32) << name;
  const auto y64 = f(x.to(torch::kFloat64)).to(torch::kFloat32);
  EXPECT_TRUE(torch::equal(y32, y64)) << name;
  // Strided, and in 7-element pieces: the same bits element by element.
  const auto wide = torch::stack({x, -x, x}, 1);  // [n, 3]; column 0 is x, strided
  EXPECT_TRUE(torch::equal(f(wide.select(1, 0)), y32)) << name;
  for (int64_t k = 0; k + 7 <= x.size(0); k += 7) {
    ASSERT_TRUE(torch::equal(f(x.narrow(0, k, 7)), y32.narrow(0, k, 7))) << name << " at " << k;
  }
}

TEST(PinnedActivationsTest, Float32IsTheFloat64KernelRounded) {
  expect_rounded_float64(pinned_tanh, "tanh");
  expect_rounded_float64(pinned_softplus, "softplus");
  expect_rounded_float64(pinned_sigmoid, "sigmoid");
}

TEST(PinnedActivationsTest, Float32SlopesAreTheClosedForms) {
  const auto x = arguments().requires_grad_(true);
  const auto t = pinned_tanh(x);
  const auto gt = torch::autograd::grad({t.sum()}, {x})[0];
  EXPECT_TRUE(torch::equal(gt, 1.0 - t.detach() * t.detach()));
  const auto s = pinned_sigmoid(x);
  const auto gs = torch::autograd::grad({s.sum()}, {x})[0];
  EXPECT_TRUE(torch::equal(gs, s.detach() * (1.0 - s.detach())));
  const auto sp = pinned_softplus(x);
  const auto gsp = torch::autograd::grad({sp.sum()}, {x})[0];
  const auto xd = x.detach();
  EXPECT_TRUE(torch::equal(gsp, torch::where(xd > 20.0, torch::ones_like(xd), pinned_sigmoid(xd))));
  // And they are the derivatives: tanh' against a float64 central difference.
  const auto x64 = xd.to(torch::kFloat64);
  const double h = 1e-6;
  const auto fd = (torch::tanh(x64 + h) - torch::tanh(x64 - h)) / (2 * h);
  EXPECT_LT((gt.to(torch::kFloat64) - fd).abs().max().item<double>(), 2e-7);
}

}  // namespace
}  // namespace internal
}  // namespace phnn
