// tests/training/regularizers_test.cpp
#include "phnn/training/regularizers.h"

#include <cmath>
#include <cstring>
#include <limits>

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

// Bitwise equal, NaN matching any NaN: LibTorch's own NaN bits differ
// between its scalar and vector loops (maximum: +qNaN against all ones).
bool same_bits(const torch::Tensor& a, const torch::Tensor& b) {
  const auto ca = a.contiguous(), cb = b.contiguous();
  if (ca.sizes() != cb.sizes()) return false;
  const double *pa = ca.data_ptr<double>(), *pb = cb.data_ptr<double>();
  for (int64_t k = 0; k < ca.numel(); ++k) {
    if (std::isnan(pa[k]) && std::isnan(pb[k])) continue;
    if (std::memcmp(pa + k, pb + k, sizeof(double)) != 0) return false;
  }
  return true;
}

// The hand-written steps' closed-form 2 x 2 penalty and its adjoint against
// autograd's through jacobian_stats + regularizer_penalty, bit for bit: random
// Jacobians (real and complex eigenvalues) and the edge rows, where one
// branch of the formulas switches: a clamped singular-value root (a = d,
// c = -b; J = 0), equal |Re lambda| (complex eigenvalues, and a = -d with a
// real pair), a zero real part, a repeated eigenvalue (disc = 0), and a
// non-finite entry. The transposed view is the field's df/dx layout.
TEST(RegularizersTest, ClosedFormPenaltyIsAutogradsToTheBit) {
  torch::manual_seed(5);
  const int64_t E = 3, B = 40;
  auto J = torch::randn({E, B, 2, 2}, torch::kFloat64) * 3.0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::array<double, 4>> edges = {
      {1.0, 2.0, -2.0, 1.0}, {0.0, 0.0, 0.0, 0.0},  {0.5, 1.0, -4.0, 0.5},  {2.0, 1.0, 3.0, -2.0},
      {0.0, 1.0, -1.0, 0.0}, {1.5, 0.0, 0.0, 1.5},  {1.0, 1.0, 0.0, 1.0},   {-3.0, 0.5, 0.5, 1.0},
      {1.0, 0.0, 0.0, -1.0}, {0.0, 1e-160, 0.0, 0}, {nan, 1.0, 0.0, 1.0},   {1.0, 2.0, 3.0, 4.0}};
  for (std::size_t k = 0; k < edges.size(); ++k) {
    for (int i = 0; i < 4; ++i) J[1][static_cast<int64_t>(k)][i / 2][i % 2] = edges[k][i];
  }
  const auto dfdx = J.transpose(-1, -2);
  TrainerOptions options;
  options.lambda_cn = 1e-3, options.lambda_sn = 0.7, options.lambda_sr = 0.3;
  for (Regularizer reg : {Regularizer::kCn, Regularizer::kSn, Regularizer::kSr}) {
    torch::Tensor bar, reference_bar;
    const auto penalty = jacobian_penalty(reg, options)(dfdx, &bar);
    const auto reference = jacobian_penalty_by_autograd(reg, options)(dfdx, &reference_bar);
    EXPECT_TRUE(same_bits(penalty, reference)) << to_string(reg) << penalty << reference;
    EXPECT_TRUE(same_bits(bar, reference_bar))
        << to_string(reg) << ": largest difference "
        << (bar - reference_bar).abs().nan_to_num(0.0).max().item<double>();
    // The finite members' adjoints are finite and not all zero (the check is not blind).
    EXPECT_GT(bar[0].abs().sum().item<double>(), 0.0) << to_string(reg);
  }
  EXPECT_FALSE(jacobian_penalty(Regularizer::kNone, options));
}

}  // namespace
}  // namespace phnn
