// tests/training/discrete_step_test.cpp
#include "phnn/training/discrete_step.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/models/port_hamiltonian.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace {

torch::Tensor states(int64_t E, int64_t B, uint64_t seed) {
  torch::manual_seed(seed);
  return torch::rand({E, B, 2}, torch::kFloat64) - 0.5;
}

// Feeding the Newton solution back as the data step reproduces it: the
// training (inverse-explicit) and inference (implicit) DG paths agree.
TEST(DiscreteStepTest, DgTrainingStepEqualsInferenceStepAtNewtonSolution) {
  for (ModelKind kind : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (SystemKind sys : all_systems()) {
      const auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, sys}, {0, 1});
      torch::NoGradGuard no_grad;
      const auto x = states(2, 64, 1);
      const auto u = states(2, 64, 2).narrow(-1, 0, 1);
      const auto s = dg_inference_step(*model, x, u, 0.01);
      ASSERT_TRUE(s.converged.all().item<bool>());
      const auto x_hat = dg_training_step(*model, x, s.x_next, u, 0.01, 6e-6);
      EXPECT_LE((x_hat - s.x_next).abs().max().item<double>(), 1e-10);
    }
  }
}

TEST(DiscreteStepTest, Rk2IsExplicitMidpointOfTheField) {
  const auto model = DynamicsModel::create(ModelOptions{ModelKind::kNode, ModelSize::kSmall, SystemKind::kHarmonic}, {0});
  torch::NoGradGuard no_grad;
  const auto x = states(1, 8, 3);
  const auto u = states(1, 8, 4).narrow(-1, 0, 1);
  const double h = 0.01;
  const auto f1 = model->field(x, u, false).f;
  const auto expected = x + h * model->field(x + 0.5 * h * f1, u, false).f;
  EXPECT_TRUE(torch::allclose(rk2_step(*model, x, u, h), expected, 0.0, 0.0));
}

// A PHNN trained for 1 000 steps on the harmonic oscillator (N_train = 100).
std::unique_ptr<DynamicsModel> learned_model(ModelKind kind) {
  DatasetOptions options;
  options.num_validation = 100;
  options.num_inference = 2;
  static const SystemData data =
      make_system_data(OscillatorOptions::defaults(SystemKind::kHarmonic), options, 100);
  CellSpec cell;
  cell.model = kind;
  cell.integrator = IntegratorKind::kDg;
  cell.n_train = 100;
  cell.seeds = {0};
  cell.training.steps = 1000;
  std::unique_ptr<DynamicsModel> model;
  const auto results = train_cell(cell, data, {}, &model);
  EXPECT_LT(results[0].best_validation_loss, 0.2 * results[0].trace.front().validation_loss);
  return model;
}

// DG with u = 0: H_theta(x_{n+1}) - H_theta(x_n) = h dg^T f_bar + dg^T r,
// dg^T f_bar <= 0 by structure, |r| <= Newton tolerance: non-increasing to
// round-off over 500 steps.
TEST(DiscreteStepTest, DgRolloutWithoutInputNeverIncreasesLearnedEnergy) {
  for (ModelKind kind : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    const auto model = learned_model(kind);
    torch::NoGradGuard no_grad;
    auto x = states(1, 32, 5);
    const auto u = torch::zeros({1, 32, 1}, torch::kFloat64);
    double worst = -1.0;
    auto H = model->hamiltonian(x);
    for (int n = 0; n < 500; ++n) {
      const auto s = dg_inference_step(*model, x, u, 0.01);
      ASSERT_TRUE(s.converged.all().item<bool>()) << "step " << n;
      const auto H1 = model->hamiltonian(s.x_next);
      const double scale = H.abs().max().item<double>() + 1e-300;
      worst = std::max(worst, ((H1 - H).max().item<double>()) / scale);
      x = s.x_next;
      H = H1;
    }
    EXPECT_LE(worst, 1e-10) << to_string(kind);
  }
}

// RK2 is not passive: with a coarse step the same structure gains energy.
TEST(DiscreteStepTest, Rk2RolloutCanIncreaseLearnedEnergy) {
  const auto model = learned_model(ModelKind::kPhnnJr);
  torch::NoGradGuard no_grad;
  auto x = states(1, 256, 6);
  const auto u = torch::zeros({1, 256, 1}, torch::kFloat64);
  const auto H0 = model->hamiltonian(x);
  const auto x1 = rk2_step(*model, x, u, 0.5);
  const auto gain = (model->hamiltonian(x1) - H0) / H0;
  EXPECT_GT(gain.max().item<double>(), 1e-3);
  // ... while DG at the same step stays passive.
  const auto s = dg_inference_step(*model, x, u, 0.5);
  const auto dg_gain = (model->hamiltonian(s.x_next) - H0) / H0;
  const auto ok = s.converged.logical_not() | (dg_gain <= 1e-10);
  EXPECT_TRUE(ok.all().item<bool>());
}

TEST(DiscreteStepTest, NodeRejectsDiscreteGradient) {
  const auto model = DynamicsModel::create(ModelOptions{ModelKind::kNode, ModelSize::kSmall, SystemKind::kHarmonic}, {0});
  const auto x = states(1, 4, 7);
  EXPECT_THROW(dg_inference_step(*model, x, x.narrow(-1, 0, 1), 0.01), std::invalid_argument);
}

}  // namespace
}  // namespace phnn
