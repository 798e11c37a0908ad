// tests/training/regularizers_test.cpp
#include "phnn/training/regularizers.h"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/models/dynamics_model.h"

namespace phnn {
namespace {

// Independent reference: Eigen's SVD and eigen solver on the autograd
// Jacobian of f_theta.
TEST(RegularizersTest, MatchEigenOnAutogradJacobian) {
  const double eps = 1e-6;
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    const auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, SystemKind::kDuffing}, {3});
    torch::manual_seed(11);
    auto x = (torch::rand({1, 50, 2}, torch::kFloat64) - 0.5).set_requires_grad(true);
    const auto u = torch::rand({1, 50, 1}, torch::kFloat64) - 0.5;
    const auto f = model->field(x, u, false).f;
    std::vector<torch::Tensor> rows;
    for (int i = 0; i < 2; ++i)
      rows.push_back(torch::autograd::grad({f.select(-1, i).sum()}, {x}, {}, true)[0]);
    const auto J = torch::stack(rows, -2).detach();
    const auto stats = jacobian_stats(J, eps);
    auto Ja = J.accessor<double, 4>();
    for (int b = 0; b < 50; ++b) {
      Eigen::Matrix2d m;
      m << Ja[0][b][0][0], Ja[0][b][0][1], Ja[0][b][1][0], Ja[0][b][1][1];
      const Eigen::Vector2d sv = Eigen::JacobiSVD<Eigen::Matrix2d>(m).singularValues();
      const Eigen::Vector2cd ev = Eigen::EigenSolver<Eigen::Matrix2d>(m).eigenvalues();
      const double re1 = std::abs(ev(0).real()), re2 = std::abs(ev(1).real());
      const double kappa = sv(0) / (sv(1) + eps);
      const double rho = std::max(re1, re2) / (std::min(re1, re2) + eps);
      EXPECT_NEAR(stats.sigma_max[0][b].item<double>(), sv(0), 1e-10 * (1 + sv(0)));
      EXPECT_NEAR(stats.sigma_min[0][b].item<double>(), sv(1), 1e-10 * (1 + sv(0)));
      EXPECT_NEAR(stats.kappa[0][b].item<double>(), kappa, 1e-10 * (1 + kappa));
      EXPECT_NEAR(stats.rho[0][b].item<double>(), rho, 1e-10 * (1 + rho));
    }
  }
}

TEST(RegularizersTest, KnownMatrices) {
  // diag(3, -1): sigma = (3, 1), eigenvalues real 3, -1: rho = 3.
  auto J = torch::tensor({3.0, 0.0, 0.0, -1.0}, torch::kFloat64).reshape({1, 1, 2, 2});
  auto s = jacobian_stats(J, 0.0);
  EXPECT_DOUBLE_EQ(s.sigma_max.item<double>(), 3.0);
  EXPECT_DOUBLE_EQ(s.sigma_min.item<double>(), 1.0);
  EXPECT_DOUBLE_EQ(s.rho.item<double>(), 3.0);
  // Rotation-like [[-0.1, 1], [-1, -0.1]]: complex pair, Re = -0.1 twice: rho = 1.
  J = torch::tensor({-0.1, 1.0, -1.0, -0.1}, torch::kFloat64).reshape({1, 1, 2, 2});
  s = jacobian_stats(J, 0.0);
  EXPECT_NEAR(s.rho.item<double>(), 1.0, 1e-15);
  EXPECT_NEAR(s.kappa.item<double>(), 1.0, 1e-15);
}

// d penalty / d theta by autograd against central differences on weights.
TEST(RegularizersTest, PenaltyGradientsMatchFiniteDifferences) {
  TrainerOptions options;
  options.lambda_cn = options.lambda_sn = options.lambda_sr = 1.0;  // scale-free check
  for (Regularizer reg : {Regularizer::kCn, Regularizer::kSn, Regularizer::kSr}) {
    const auto model = DynamicsModel::create(
        ModelOptions{ModelKind::kPhnnJr, ModelSize::kSmall, SystemKind::kHarmonic}, {5});
    torch::manual_seed(3);
    const auto x = torch::rand({1, 16, 2}, torch::kFloat64) - 0.5;
    const auto u = torch::rand({1, 16, 1}, torch::kFloat64) - 0.5;
    auto penalty = [&] {
      return regularizer_penalty(reg, jacobian_stats(model->field(x, u, true).dfdx, 1e-6), options)
          .sum();
    };
    auto params = model->parameters();
    for (auto& p : params) p.mutable_grad() = torch::Tensor();
    penalty().backward();
    for (std::size_t k : {std::size_t{0}, std::size_t{4}, std::size_t{6}}) {
      auto& p = params[k];
      const auto flat_grad = p.grad().reshape({-1});
      for (int64_t i : {int64_t{0}, int64_t{5}}) {
        const double h = 1e-6;
        torch::NoGradGuard no_grad;
        auto flat = p.view({-1});
        const double orig = flat[i].item<double>();
        flat[i].fill_(orig + h);
        const double plus = penalty().item<double>();
        flat[i].fill_(orig - h);
        const double minus = penalty().item<double>();
        flat[i].fill_(orig);
        const double fd = (plus - minus) / (2 * h);
        const double ad = flat_grad[i].item<double>();
        EXPECT_NEAR(ad, fd, 1e-5 * (1.0 + std::abs(fd))) << to_string(reg) << " param " << k << "[" << i << "]";
      }
    }
  }
}

}  // namespace
}  // namespace phnn
