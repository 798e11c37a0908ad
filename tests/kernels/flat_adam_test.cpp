// tests/kernels/flat_adam_test.cpp
#include "phnn/kernels/flat_adam.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "kernels/kernel_isa.h"
#include "phnn/models/dynamics_model.h"

namespace phnn {
namespace {

torch::Tensor loss_of(const DynamicsModel& model, int step) {
  torch::manual_seed(static_cast<uint64_t>(step));
  const auto x = torch::rand({2, 32, 2}, torch::kFloat64) - 0.5;
  const auto u = torch::rand({2, 32, 1}, torch::kFloat64) - 0.5;
  return model.field(x, u, false).f.pow(2).sum();
}

// The independent reference: torch::optim::Adam on the separate tensors. It
// rounds differently (its vectorized kernels fuse b1 m + (1 - b1) g into one
// FMA, its bias corrections use std::pow), so the two agree to round-off:
// 50 steps of a learning rate 1e-2 move each weight by up to ~0.5, and
// differences of a few ulp per step stay far below 1e-12 of that.
TEST(FlatAdamTest, MatchesTorchAdamToRoundOff) {
  const ModelOptions options{ModelKind::kPhnnJr, ModelSize::kSmall, SystemKind::kDuffing};
  auto reference = DynamicsModel::create(options, {3, 4});
  auto flat_model = DynamicsModel::create(options, {3, 4});
  TrainerOptions trainer;
  trainer.learning_rate = 1e-2;
  torch::optim::Adam adam(reference->parameters(),
                          torch::optim::AdamOptions(trainer.learning_rate)
                              .betas(std::make_tuple(trainer.adam_beta1, trainer.adam_beta2))
                              .eps(trainer.adam_eps));
  std::vector<torch::Tensor> before;
  for (const auto& p : reference->parameters()) before.push_back(p.detach().clone());
  const auto flat = flat_model->flatten_parameters();
  FlatAdam flat_adam(flat.values, flat.gradients, trainer);
  for (int step = 0; step < 50; ++step) {
    adam.zero_grad();
    loss_of(*reference, step).backward();
    adam.step();
    flat_adam.zero_grad();
    loss_of(*flat_model, step).backward();
    flat_adam.step();
  }
  const auto a = reference->parameters(), b = flat_model->parameters();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double diff = (a[k] - b[k]).abs().max().item<double>();
    EXPECT_LE(diff, 1e-12) << "parameter " << k;
    EXPECT_GT((a[k] - before[k]).abs().max().item<double>(), 1e-3) << "parameter " << k << " did not move";
  }
  EXPECT_EQ(flat_adam.steps_taken(), 50);
}

// One step by hand, in the documented order (flat_adam.h): t = 1 and t = 2
// with beta powers written out, so the bias corrections are checked too.
TEST(FlatAdamTest, TwoStepsByHand) {
  TrainerOptions trainer;
  trainer.learning_rate = 0.1;
  auto p = torch::tensor({1.0, -2.0, 0.5}, torch::kFloat64);
  auto g = torch::zeros_like(p);
  FlatAdam adam(p, g, trainer);
  const double b1 = trainer.adam_beta1, b2 = trainer.adam_beta2, eps = trainer.adam_eps;
  const std::vector<std::vector<double>> grads{{0.3, -1.0, 0.0}, {-0.2, 4.0, 1e-3}};
  std::vector<double> ref{1.0, -2.0, 0.5}, m(3, 0.0), v(3, 0.0);
  for (int t = 1; t <= 2; ++t) {
    const auto& gt = grads[static_cast<std::size_t>(t - 1)];
    g.copy_(torch::tensor(gt, torch::kFloat64));
    adam.step();
    const double bc1 = 1 - (t == 1 ? b1 : b1 * b1), bc2 = 1 - (t == 1 ? b2 : b2 * b2);
    for (std::size_t k = 0; k < 3; ++k) {
      m[k] = b1 * m[k] + (1 - b1) * gt[k];
      v[k] = b2 * v[k] + (1 - b2) * gt[k] * gt[k];
      ref[k] += -trainer.learning_rate / bc1 * m[k] / (std::sqrt(v[k]) / std::sqrt(bc2) + eps);
      EXPECT_DOUBLE_EQ(p[static_cast<int64_t>(k)].item<double>(), ref[k]) << "t " << t << " k " << k;
    }
  }
}

// The update loop is compiled per instruction set: every set gives the same
// bits, in float64 and float32, over lengths that leave vector tails, with
// gradients spanning many magnitudes (and zeros).
TEST(FlatAdamTest, EveryInstructionSetGivesTheSameBits) {
  using internal::KernelIsa;
  for (const auto dtype : {torch::kFloat64, torch::kFloat32}) {
    for (const int64_t n : {int64_t{1}, int64_t{7}, int64_t{29}, int64_t{1000}}) {
      std::vector<torch::Tensor> finals;
      for (const auto isa : {KernelIsa::kBaseline, KernelIsa::kAvx2, KernelIsa::kAvx512}) {
        const internal::ScopedKernelIsa scope(isa);
        torch::manual_seed(7);
        auto p = torch::randn({n}, torch::kFloat64).to(dtype);
        auto g = torch::zeros_like(p);
        FlatAdam adam(p, g, TrainerOptions{});
        for (int step = 0; step < 5; ++step) {
          const auto scale = torch::pow(10.0, torch::randint(-8, 3, {n}));
          const auto kept = torch::rand({n}) > 0.1;
          g.copy_(torch::randn({n}, torch::kFloat64).mul(scale).mul(kept).to(dtype));
          adam.step();
        }
        finals.push_back(p.clone());
      }
      for (std::size_t k = 1; k < finals.size(); ++k)
        EXPECT_TRUE(torch::equal(finals[k], finals[0])) << "n " << n << " set " << k;
    }
  }
}

TEST(FlatAdamTest, FlattenKeepsValuesAndShapes) {
  auto model = DynamicsModel::create({ModelKind::kPhnnS, ModelSize::kMedium, SystemKind::kHarmonic}, {0, 1, 2});
  std::vector<torch::Tensor> before;
  for (const auto& p : model->parameters()) before.push_back(p.detach().clone());
  const auto flat = model->flatten_parameters();
  EXPECT_EQ(flat.values.numel(), 3 * model->parameter_count());
  const auto after = model->parameters();
  for (std::size_t k = 0; k < before.size(); ++k) {
    EXPECT_TRUE(torch::equal(before[k], after[k]));
    EXPECT_TRUE(after[k].is_leaf());
  }
  const auto views = model->unflatten(flat.values);
  for (std::size_t k = 0; k < before.size(); ++k) EXPECT_TRUE(torch::equal(views[k], before[k]));
  // Gradients accumulate into the flat gradient buffer.
  torch::manual_seed(0);
  const auto x = torch::rand({3, 8, 2}, torch::kFloat64);
  model->field(x, x.narrow(-1, 0, 1), false).f.sum().backward();
  const auto grads = model->unflatten(flat.gradients);
  for (std::size_t k = 0; k < before.size(); ++k) {
    EXPECT_TRUE(torch::equal(after[k].grad(), grads[k]));
  }
  EXPECT_GT(flat.gradients.abs().sum().item<double>(), 0.0);
}

}  // namespace
}  // namespace phnn
