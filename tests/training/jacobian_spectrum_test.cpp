// tests/training/jacobian_spectrum_test.cpp — the n-dimensional
// regularizers' singular values and eigenvalue real parts
// (src/training/jacobian_spectrum.h) against LAPACK (torch::linalg, an
// independent implementation) in value and in gradient, and against central
// differences; batch shape and float32 pass through.
#include "training/jacobian_spectrum.h"

#include <cmath>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/training/regularizers.h"

namespace phnn {
namespace {

// [2, 3, n, n] random matrices: distinct singular values and eigenvalues
// almost surely, complex pairs among them (a random real matrix has some).
torch::Tensor random_jacobians(int64_t n, int seed) {
  torch::manual_seed(seed);
  return torch::randn({2, 3, n, n}, torch::kFloat64);
}

// Values: LAPACK and Eigen agree to 1e-12 of the largest singular value
// (both backward stable: errors ~ n eps ||J||).
TEST(JacobianSpectrumTest, ValuesMatchLapack) {
  for (int64_t n : {3, 4, 6, 8}) {
    const torch::Tensor j = random_jacobians(n, static_cast<int>(n));
    const torch::Tensor sigma = internal::singular_values(j);
    const torch::Tensor scale = torch::linalg_svdvals(j).select(-1, 0).unsqueeze(-1);
    EXPECT_LE(((sigma - torch::linalg_svdvals(j)).abs() / scale).max().item<double>(), 1e-12);
    // Eigenvalue order differs between the two: compare the sorted real parts.
    const torch::Tensor re = std::get<0>(internal::eigenvalue_real_parts(j).sort(-1));
    const torch::Tensor lapack = std::get<0>(torch::real(torch::linalg_eigvals(j)).sort(-1));
    EXPECT_LE(((re - lapack).abs() / scale).max().item<double>(), 1e-12) << "n = " << n;
  }
}

// Gradients of a scalar that weighs every output differently equal the
// gradients autograd takes through LAPACK's factorizations, to 1e-9
// relative (first-order formulas, distinct values).
TEST(JacobianSpectrumTest, GradientsMatchLapackAutograd) {
  for (int64_t n : {3, 5}) {
    const torch::Tensor j0 = random_jacobians(n, 40 + static_cast<int>(n));
    const torch::Tensor w = torch::linspace(0.5, 1.5, n, torch::kFloat64);
    auto grad_of = [&](auto&& f) {
      const torch::Tensor j = j0.clone().set_requires_grad(true);
      (f(j) * w).sum().backward();
      return j.grad();
    };
    const torch::Tensor gs = grad_of([](const torch::Tensor& j) { return internal::singular_values(j); });
    const torch::Tensor gs_ref = grad_of([](const torch::Tensor& j) { return torch::linalg_svdvals(j); });
    EXPECT_LE((gs - gs_ref).abs().max().item<double>(), 1e-9 * gs_ref.abs().max().item<double>());
    // Real parts in sorted order on both sides, so each weight meets the same eigenvalue.
    const torch::Tensor ge = grad_of([](const torch::Tensor& j) {
      return std::get<0>(internal::eigenvalue_real_parts(j).sort(-1));
    });
    const torch::Tensor ge_ref = grad_of([](const torch::Tensor& j) {
      return std::get<0>(torch::real(torch::linalg_eigvals(j)).sort(-1));
    });
    EXPECT_LE((ge - ge_ref).abs().max().item<double>(), 1e-9 * ge_ref.abs().max().item<double>())
        << "n = " << n;
  }
}

// kappa, sigma_max and rho of jacobian_stats_general against central
// differences (step 1e-6: truncation ~1e-12 relative, round-off ~1e-10).
TEST(JacobianSpectrumTest, StatsGradientsMatchCentralDifferences) {
  const torch::Tensor j0 = random_jacobians(4, 7);
  auto total = [](const torch::Tensor& j) {
    const JacobianStats s = jacobian_stats_general(j, 1e-6);
    return (s.kappa + s.sigma_max + s.rho).sum();
  };
  const torch::Tensor j = j0.clone().set_requires_grad(true);
  total(j).backward();
  const torch::Tensor grad = j.grad().reshape({-1});
  torch::NoGradGuard no_grad;
  for (int64_t i : {0, 5, 17, 40, 63, 95}) {
    torch::Tensor plus = j0.clone(), minus = j0.clone();
    const double h = 1e-6;
    plus.view({-1})[i] += h;
    minus.view({-1})[i] -= h;
    const double fd = (total(plus).item<double>() - total(minus).item<double>()) / (2 * h);
    EXPECT_NEAR(grad[i].item<double>(), fd, 1e-6 * (1.0 + std::abs(fd))) << "entry " << i;
  }
}

TEST(JacobianSpectrumTest, KeepsTheBatchShapeAndTheDtype) {
  const torch::Tensor j = random_jacobians(3, 1).to(torch::kFloat32);
  const torch::Tensor sigma = internal::singular_values(j);
  EXPECT_EQ(sigma.sizes(), (std::vector<int64_t>{2, 3, 3}));
  EXPECT_EQ(sigma.scalar_type(), torch::kFloat32);
  // diag(3, -1, 2): sigma (3, 2, 1), Re(lambda) {3, -1, 2} in some order.
  const torch::Tensor d = torch::diag(torch::tensor({3.0, -1.0, 2.0}, torch::kFloat64)).reshape({1, 3, 3});
  EXPECT_TRUE(torch::equal(internal::singular_values(d), torch::tensor({{3.0, 2.0, 1.0}}, torch::kFloat64)));
  EXPECT_TRUE(torch::equal(std::get<0>(internal::eigenvalue_real_parts(d).sort(-1)),
                           torch::tensor({{-1.0, 2.0, 3.0}}, torch::kFloat64)));
}

}  // namespace
}  // namespace phnn
