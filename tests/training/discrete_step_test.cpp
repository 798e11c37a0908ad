// tests/training/discrete_step_test.cpp
#include "phnn/training/discrete_step.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/integrators/integrator.h"
#include "phnn/models/general_ph.h"
#include "phnn/models/port_hamiltonian.h"
#include "phnn/training/trainer.h"
#include "reference/oscillator.h"
#include "training/small_data.h"

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

// The analytic d f_bar / d dx used by Newton equals central differences of
// discrete_gradient_field (an independent computation: no jets). Step 1e-6
// on |dx| ~ 0.1: truncation ~1e-12 |f'''|, round-off ~1e-16 / 1e-6 = 1e-10.
TEST(DiscreteStepTest, DgFieldJacobianMatchesCentralDifferences) {
  for (ModelKind kind : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (SystemKind sys : all_systems()) {
      const auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, sys}, {0, 1});
      torch::NoGradGuard no_grad;
      const auto x = 2.0 * states(2, 32, 3);
      const auto dx = 0.2 * states(2, 32, 4);
      const auto u = states(2, 32, 5).narrow(-1, 0, 1);
      const FieldEval fj = model->discrete_gradient_field_with_jacobian(x, dx, u, 6e-6);
      EXPECT_LE((fj.f - model->discrete_gradient_field(x, dx, u, 6e-6)).abs().max().item<double>(),
                1e-12);
      const double eps = 1e-6;
      for (int i = 0; i < 2; ++i) {
        auto e = torch::zeros({2}, torch::kFloat64);
        e[i] = eps;
        const auto column = (model->discrete_gradient_field(x, dx + e, u, 6e-6) -
                             model->discrete_gradient_field(x, dx - e, u, 6e-6)) / (2 * eps);
        const auto analytic = fj.dfdx.select(-1, i);
        const double scale = std::max(1.0, column.abs().max().item<double>());
        EXPECT_LE((analytic - column).abs().max().item<double>(), 1e-7 * scale)
            << model_label(kind, IntegratorKind::kDg) << " " << to_string(sys) << " column " << i;
      }
    }
  }
}

// Newton stops on the residual: every converged row satisfies
// max |dx - h f_bar(x, dx, u)| <= 1e-12, recomputed here without jets.
TEST(DiscreteStepTest, DgInferenceMeetsResidualTolerance) {
  for (ModelKind kind : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    const auto model = DynamicsModel::create(
        ModelOptions{kind, ModelSize::kSmall, SystemKind::kDuffing}, {0, 1, 2});
    torch::NoGradGuard no_grad;
    const auto x = 2.0 * states(3, 100, 6);
    const auto u = states(3, 100, 7).narrow(-1, 0, 1);
    const auto s = dg_inference_step(*model, x, u, 0.01);
    ASSERT_TRUE(s.converged.all().item<bool>());
    EXPECT_GE(s.iterations, 1);
    const auto dx = s.x_next - x;
    const auto r = dx - 0.01 * model->discrete_gradient_field(x, dx, u, 6e-6);
    EXPECT_LE(r.abs().max().item<double>(), 1e-12);
  }
}

// PHNN-JR's DG step with R_theta at the midpoint (default) or at the start
// x_n: with e = (dg, u), dg the Gonzalez gradient along the Newton solution
// dx and R = R_theta at that point, skew J gives the discrete power balance
//   H(x_{n+1}) - H(x_n) = dg^T dx = h dg^T f_bar = -h (e^T R e + u [(J - R) e]_3)
// for any PSD R wherever it is evaluated (up to dg^T r, |r| <= 1e-12). Both
// points satisfy it; they give different steps; each point's training step
// reproduces its own inference step; its Newton Jacobian is exact.
TEST(DiscreteStepTest, DgStructurePointKeepsThePowerBalanceAndChangesTheStep) {
  const double h = 0.01;
  std::vector<torch::Tensor> next;
  for (DgStructurePoint point : all_dg_structure_points()) {
    const auto model = DynamicsModel::create(
        ModelOptions{ModelKind::kPhnnJr, ModelSize::kSmall, SystemKind::kDuffing, true, point},
        {0, 1});
    const auto& jr = dynamic_cast<const PhnnJr&>(*model);
    torch::NoGradGuard no_grad;
    const auto x = 2.0 * states(2, 64, 11);
    const auto u = states(2, 64, 12).narrow(-1, 0, 1);
    const auto s = dg_inference_step(*model, x, u, h);
    ASSERT_TRUE(s.converged.all().item<bool>()) << to_string(point);
    const auto dx = s.x_next - x;
    const auto e = torch::cat({jr.discrete_gradient(x, dx, 6e-6), u}, -1).unsqueeze(-1);
    const auto R = jr.dissipation_matrix(point == DgStructurePoint::kStart ? x : x + 0.5 * dx, u);
    const Eigen::Matrix3d Jm = Oscillator(OscillatorOptions::defaults(SystemKind::kDuffing)).J();
    auto J = torch::empty({3, 3}, torch::kFloat64);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) J[r][c] = Jm(r, c);
    const auto ere = torch::matmul(e.transpose(-1, -2), torch::matmul(R, e)).squeeze(-1).squeeze(-1);
    const auto y = torch::matmul(J - R, e).squeeze(-1).select(-1, 2);
    const auto supplied = -h * (ere + u.squeeze(-1) * y);
    const auto stored = jr.hamiltonian(s.x_next) - jr.hamiltonian(x);
    EXPECT_LE((stored - supplied).abs().max().item<double>(), 1e-12) << to_string(point);
    EXPECT_GT(ere.min().item<double>(), -1e-15) << "R is PSD";
    const auto x_hat = dg_training_step(*model, x, s.x_next, u, h, 6e-6);
    EXPECT_LE((x_hat - s.x_next).abs().max().item<double>(), 1e-10) << to_string(point);
    const FieldEval fj = model->discrete_gradient_field_with_jacobian(x, dx, u, 6e-6);
    const double eps = 1e-6;
    for (int i = 0; i < 2; ++i) {
      auto step = torch::zeros({2}, torch::kFloat64);
      step[i] = eps;
      const auto column = (model->discrete_gradient_field(x, dx + step, u, 6e-6) -
                           model->discrete_gradient_field(x, dx - step, u, 6e-6)) / (2 * eps);
      EXPECT_LE((fj.dfdx.select(-1, i) - column).abs().max().item<double>(), 1e-7)
          << to_string(point) << " column " << i;
    }
    next.push_back(s.x_next);
  }
  EXPECT_GT((next[0] - next[1]).abs().max().item<double>(), 1e-8);
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


// A given first stage k1 = f(x, u) is used as is: the step with k1 passed is
// bitwise the step that computes it; with k1 from the Jacobian (jet) path, as
// the regularized training step passes it, the steps agree to round-off
// (the jet path's f equals the order-0 path's to 1e-14, ForwardModeTest).
TEST(DiscreteStepTest, ExplicitStepsReuseAGivenFirstStage) {
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    const auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, SystemKind::kDuffing}, {0, 1});
    torch::NoGradGuard no_grad;
    const auto x = states(2, 16, 7);
    const auto u = states(2, 16, 8).narrow(-1, 0, 1);
    const double h = 0.05;
    const auto k1 = model->field(x, u, false).f;
    const auto k1_jet = model->field(x, u, true).f;
    for (IntegratorKind integrator : {IntegratorKind::kRk2, IntegratorKind::kRk4}) {
      const auto plain = explicit_step(*model, integrator, x, u, h);
      EXPECT_TRUE(torch::equal(explicit_step(*model, integrator, x, u, h, k1), plain))
          << to_string(kind) << " " << to_string(integrator);
      const auto from_jet = explicit_step(*model, integrator, x, u, h, k1_jet);
      EXPECT_LE((from_jet - plain).abs().max().item<double>(), 1e-14)
          << to_string(kind) << " " << to_string(integrator);
      // A wrong k1 would show: the step is not the one of k1 = 0.
      EXPECT_GT((explicit_step(*model, integrator, x, u, h, torch::zeros_like(k1)) - plain)
                    .abs().max().item<double>(), 1e-6);
    }
  }
}

// The regularized training step backpropagates through the jet path's f (the
// first stage) and df/dx (the penalty) of one evaluation: its parameter
// gradients equal those of two separate evaluations (order-0 f for the step,
// the jet for df/dx) to round-off, so the jet node's backward takes the
// gradient of its value output, not only of its derivatives.
TEST(DiscreteStepTest, SharedFirstStageKeepsTheParameterGradients) {
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, SystemKind::kDuffing}, {0, 1});
    const auto x = states(2, 16, 9);
    const auto u = states(2, 16, 10).narrow(-1, 0, 1);
    const auto target = states(2, 16, 11);
    const double h = 0.05;
    auto gradients = [&](bool shared) {
      for (auto& p : model->parameters()) p.mutable_grad() = torch::Tensor();
      const FieldEval at_x = model->field(x, u, true);
      const auto k1 = shared ? at_x.f : torch::Tensor();
      const auto step = explicit_step(*model, IntegratorKind::kRk2, x, u, h, k1);
      const auto loss = discrete_loss(target, step, h, LossNorm::kMeanL1) +
                        (at_x.dfdx * at_x.dfdx).sum({1, 2, 3});
      loss.sum().backward();
      std::vector<torch::Tensor> g;
      for (const auto& p : model->parameters()) g.push_back(p.grad().clone());
      return g;
    };
    const auto separate = gradients(false), shared = gradients(true);
    ASSERT_EQ(separate.size(), shared.size());
    for (std::size_t k = 0; k < shared.size(); ++k) {
      const double scale = 1.0 + separate[k].abs().max().item<double>();
      EXPECT_LE((shared[k] - separate[k]).abs().max().item<double>(), 1e-12 * scale)
          << to_string(kind) << " parameter " << k;
    }
  }
}
// DG4's training (inverse-explicit) and inference (Newton) forms agree: the
// Newton solution fed back as the data step reproduces itself.
TEST(DiscreteStepTest, Dg4TrainingStepEqualsInferenceStepAtNewtonSolution) {
  for (ModelKind kind : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (SystemKind sys : all_systems()) {
      const auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, sys}, {0, 1});
      torch::NoGradGuard no_grad;
      const auto x = states(2, 64, 1);
      const auto u = states(2, 64, 2).narrow(-1, 0, 1);
      const auto s = dg4_inference_step(*model, x, u, 0.01);
      ASSERT_TRUE(s.converged.all().item<bool>()) << model_label(kind, IntegratorKind::kDg4);
      const auto x_hat = dg4_training_step(*model, x, s.x_next, u, 0.01, 6e-6);
      EXPECT_LE((x_hat - s.x_next).abs().max().item<double>(), 1e-10);
    }
  }
}

// The learned AVF discrete gradient: chain rule H(x+dx) - H(x) = avf^T dx to
// round-off of H on both sides of tau, and avf -> gradH(x) as dx -> 0.
TEST(DiscreteStepTest, LearnedAverageVectorFieldIsADiscreteGradient) {
  const auto model = DynamicsModel::create(ModelOptions{ModelKind::kPhnnJr, ModelSize::kSmall,
                                                        SystemKind::kDuffing}, {0, 1});
  const auto& ph = dynamic_cast<const PortHamiltonianModel&>(*model);
  torch::NoGradGuard no_grad;
  const auto x = states(2, 32, 7);
  for (double scale : {0.3, 1e-3, 1e-6, 1e-9, 0.0}) {
    const auto dx = scale * states(2, 32, 8);
    const auto avf = ph.average_vector_field_gradient(x, dx, 6e-6);
    const auto dH = model->hamiltonian(x + dx) - model->hamiltonian(x);
    const auto tol = 1e-13 * (1.0 + model->hamiltonian(x).abs());
    EXPECT_TRUE(((avf * dx).sum(-1) - dH).abs().le(tol).all().item<bool>()) << "scale " << scale;
    const auto g = model->grad_hamiltonian(x);
    EXPECT_LE((avf - g).abs().max().item<double>(), 1e-12 + 50.0 * scale) << "scale " << scale;
  }
}

// One inference step of every integrator of all_integrators() against 64
// RK4 substeps of the same learned continuous field: the local error falls
// as h^(p+1) (p its table's order), so halving h from 0.1 to 0.05 to 0.025
// gives log2 ratios p + 1 (+-0.3). Every model the integrator allows (NODE:
// no discrete gradient) on Duffing and the self-sustained oscillator; for
// DG4 this checks the correction term with state-dependent R (PHNN-JR) and
// nonlinear z (PHNN-S), where the closed-form tests cannot reach.
TEST(DiscreteStepTest, EveryIntegratorHasItsOrderOnLearnedFields) {
  DgInferenceOptions tight;
  tight.tolerance = 1e-15;
  tight.max_iterations = 50;
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (SystemKind sys : {SystemKind::kDuffing, SystemKind::kSelfSustained}) {
      const auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, sys}, {0});
      torch::NoGradGuard no_grad;
      const auto x = states(1, 16, 9);
      const auto u = states(1, 16, 10).narrow(-1, 0, 1);
      for (const Integrator& in : all_integrators()) {
        if (kind == ModelKind::kNode && in.discrete_gradient) continue;
        double previous = 0.0;
        for (double h : {0.1, 0.05, 0.025}) {
          auto reference = x;
          for (int i = 0; i < 64; ++i) reference = rk4_step(*model, reference, u, h / 64);
          const DgInferenceStep s = inference_step(*model, in.kind, x, u, h, tight);
          if (s.converged.defined()) {
            EXPECT_TRUE(s.converged.all().item<bool>());
          }
          const double err = (s.x_next - reference).norm().item<double>();
          if (previous > 0.0) {
            EXPECT_NEAR(std::log2(previous / err), in.order + 1, 0.3)
                << model_label(kind, in.kind) << " " << to_string(sys) << " h = " << h;
          }
          previous = err;
        }
      }
    }
  }
}

// A PHNN trained for 1 000 steps on the harmonic oscillator (N_train = 100).
std::unique_ptr<DynamicsModel> learned_model(ModelKind kind) {
  DatasetOptions options;
  options.num_validation = 100;
  options.num_inference = 2;
  static const testing_util::SystemAndData data =
      testing_util::builtin_data(OscillatorOptions::defaults(SystemKind::kHarmonic), options, 100);
  CellSpec cell;
  cell.model = kind;
  cell.integrator = IntegratorKind::kDg;
  cell.n_train = 100;
  cell.seeds = {0};
  cell.training.steps = 1000;
  std::unique_ptr<DynamicsModel> model;
  const auto results = testing_util::train_cell(cell, data, {}, &model);
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

// L_d in its three norms on a fixed error e = x_next - x_hat = h E with
// E = [[1, -2], [3, -4], [0, 5]] (one member): mean-l1 = 15 / 6,
// sum-l1 = 15 / 3 = 2 mean-l1, mse = (1 + 4 + 9 + 16 + 0 + 25) / 6.
TEST(DiscreteStepTest, DiscreteLossNormsFollowTheirDefinitions) {
  const double h = 0.01;
  const auto E = torch::tensor({1.0, -2.0, 3.0, -4.0, 0.0, 5.0}, torch::kFloat64).view({1, 3, 2});
  const auto x_next = states(1, 3, 6);
  const auto x_hat = x_next - h * E;
  constexpr double kRoundOff = 1e-13;  // e / h recovers E to a few ulps
  EXPECT_NEAR(discrete_loss(x_next, x_hat, h, LossNorm::kMeanL1).item<double>(), 2.5, kRoundOff);
  EXPECT_NEAR(discrete_loss(x_next, x_hat, h, LossNorm::kSumL1).item<double>(), 5.0, kRoundOff);
  EXPECT_NEAR(discrete_loss(x_next, x_hat, h, LossNorm::kMse).item<double>(), 55.0 / 6.0,
              kRoundOff);
  // Per member, and the default is today's formula bit for bit.
  const auto a = states(3, 7, 7), b = states(3, 7, 8);
  const auto mean_l1 = discrete_loss(a, b, h, LossNorm::kMeanL1);
  EXPECT_EQ(mean_l1.sizes(), (std::vector<int64_t>{3}));
  EXPECT_TRUE(torch::equal(mean_l1, ((a - b).abs() / h).mean({1, 2})));
  EXPECT_TRUE(torch::allclose(discrete_loss(a, b, h, LossNorm::kSumL1), 2.0 * mean_l1,
                              /*rtol=*/1e-15, /*atol=*/0.0));
}

TEST(DiscreteStepTest, NodeRejectsDiscreteGradient) {
  const auto model = DynamicsModel::create(ModelOptions{ModelKind::kNode, ModelSize::kSmall, SystemKind::kHarmonic}, {0});
  const auto x = states(1, 4, 7);
  EXPECT_THROW(dg_inference_step(*model, x, x.narrow(-1, 0, 1), 0.01), std::invalid_argument);
}

}  // namespace
}  // namespace phnn
