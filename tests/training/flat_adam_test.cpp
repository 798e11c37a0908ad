// tests/training/flat_adam_test.cpp
#include "phnn/training/flat_adam.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/models/dynamics_model.h"

namespace phnn {
namespace {

torch::Tensor loss_of(const DynamicsModel& model, int step) {
  torch::manual_seed(static_cast<uint64_t>(step));
  const auto x = torch::rand({2, 32, 2}, torch::kFloat64) - 0.5;
  const auto u = torch::rand({2, 32, 1}, torch::kFloat64) - 0.5;
  return model.field(x, u, false).f.pow(2).sum();
}

// The independent reference: torch::optim::Adam on the separate tensors.
TEST(FlatAdamTest, MatchesTorchAdamBitForBit) {
  const ModelOptions options{ModelKind::kPhnnJr, ModelSize::kSmall, SystemKind::kDuffing};
  auto reference = DynamicsModel::create(options, {3, 4});
  auto flat_model = DynamicsModel::create(options, {3, 4});
  TrainerOptions trainer;
  trainer.learning_rate = 1e-2;
  torch::optim::Adam adam(reference->parameters(),
                          torch::optim::AdamOptions(trainer.learning_rate)
                              .betas(std::make_tuple(trainer.adam_beta1, trainer.adam_beta2))
                              .eps(trainer.adam_eps));
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
    EXPECT_TRUE(torch::equal(a[k], b[k])) << "parameter " << k << " max diff "
                                          << (a[k] - b[k]).abs().max().item<double>();
  }
  EXPECT_EQ(flat_adam.steps_taken(), 50);
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
