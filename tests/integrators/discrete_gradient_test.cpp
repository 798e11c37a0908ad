// tests/integrators/discrete_gradient_test.cpp
#include "reference/discrete_gradient.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <random>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/data/dataset.h"
#include "reference/explicit_midpoint.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Generic Gonzalez DG on the Duffing Hamiltonian, with the fallback.
Vec2 generic_dg(const Oscillator& osc, const Vec2& x, const Vec2& dx) {
  return gonzalez_gradient([&](const Vec2& s) { return osc.hamiltonian(s); },
                           [&](const Vec2& s) { return osc.grad_hamiltonian(s); },
                           x, dx, DiscreteGradientOptions{}.min_dx_norm);
}

// DG property 1 (discrete chain rule) for Duffing, ||dx|| log-uniform in
// [1e-9, 1e-1]: both sides of tau = 6e-6. Tolerance 1e-12 |H(x)| (issue 2).
TEST(DiscreteGradientTest, SatisfiesDiscreteChainRuleOnBothSidesOfFallback) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  std::mt19937_64 gen(42);
  std::uniform_real_distribution<double> coord(-0.5, 0.5), angle(0, 2 * M_PI),
      log_norm(-9.0, -1.0);
  int below = 0, above = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec2 x(coord(gen), coord(gen));
    const double r = std::pow(10.0, log_norm(gen)), a = angle(gen);
    const Vec2 dx(r * std::cos(a), r * std::sin(a));
    (r < 6e-6 ? below : above)++;
    const double dH = osc.hamiltonian(x + dx) - osc.hamiltonian(x);
    const double tol = 1e-12 * std::abs(osc.hamiltonian(x));
    EXPECT_LE(std::abs(generic_dg(osc, x, dx).dot(dx) - dH), tol)
        << "generic, |dx| = " << r;
    EXPECT_LE(std::abs(osc.discrete_gradient(x, dx).dot(dx) - dH), tol)
        << "closed form, |dx| = " << r;
  }
  EXPECT_GT(below, 500);
  EXPECT_GT(above, 500);
}

// The closed form and the generic quotient agree where the quotient is
// accurate (|dx| >= 1e-3: cancellation error eps |H| / |dx| <= 1e-12).
TEST(DiscreteGradientTest, ClosedFormMatchesGenericQuotient) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  std::mt19937_64 gen(7);
  std::uniform_real_distribution<double> coord(-0.5, 0.5), d(-0.1, 0.1);
  for (int i = 0; i < 500; ++i) {
    const Vec2 x(coord(gen), coord(gen));
    Vec2 dx(d(gen), d(gen));
    if (dx.norm() < 1e-3) continue;
    const Vec2 a = osc.discrete_gradient(x, dx), b = generic_dg(osc, x, dx);
    EXPECT_LE((a - b).lpNorm<Eigen::Infinity>(), 1e-11 * (1.0 + a.norm()));
  }
}

// DG property 2: dg(x, dx) -> gradH(x), finite, for |dx| = 1e-9, 1e-300, 0.
TEST(DiscreteGradientTest, ReducesToGradientAsStepVanishes) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  const Vec2 x(0.31, -0.17);
  const Vec2 g = osc.grad_hamiltonian(x);
  for (double r : {1e-9, 1e-300, 0.0}) {
    const Vec2 dx = r * Vec2(0.6, 0.8);
    for (const Vec2& dg : {generic_dg(osc, x, dx), osc.discrete_gradient(x, dx)}) {
      ASSERT_TRUE(dg.allFinite()) << "|dx| = " << r;
      // |dg - gradH(x)| <= |H''| |dx| / 2 + round-off.
      EXPECT_LE((dg - g).norm(), 1e-14 * g.norm() + 1e3 * r) << "|dx| = " << r;
    }
  }
  EXPECT_EQ(osc.discrete_gradient(x, Vec2::Zero()), g);
  EXPECT_EQ(generic_dg(osc, x, Vec2::Zero()), g);
}

// Newton's Jacobian of the closed-form DG against central differences.
TEST(DiscreteGradientTest, JacobianMatchesFiniteDifferences) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  const Vec2 x(0.2, 0.1), dx(0.01, -0.02);
  const Mat2 jac = osc.discrete_gradient_jacobian(x, dx);
  const double eps = 1e-7;
  for (int j = 0; j < 2; ++j) {
    Vec2 e = Vec2::Zero();
    e(j) = eps;
    const Vec2 col = (osc.discrete_gradient(x, dx + e) - osc.discrete_gradient(x, dx - e)) /
                     (2 * eps);
    EXPECT_LE((jac.col(j) - col).norm(), 1e-6 * (1.0 + col.norm()));
  }
}

// Discrete power balance of generated trajectories, all three systems:
//   H(x_{n+1}) - H(x_n) = -h (z w + u y), to 1e-12 of the step's power scale.
TEST(DiscreteGradientTest, GeneratedTrajectoriesSatisfyDiscretePowerBalance) {
  DatasetOptions data;
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    double worst = 0.0;
    for (std::int64_t index : {0, 17, 401, 2950}) {
      const testing_util::PaperTrajectory traj = testing_util::paper_trajectory(kind, data, index, 2000);
      for (std::size_t n = 0; n + 1 < traj.states.size(); ++n) {
        const Vec2& x = traj.states[n];
        const DiscreteGradientStep step =
            discrete_gradient_step(osc, x, traj.u, data.generation_step);
        ASSERT_EQ(step.status, StepStatus::kConverged);
        ASSERT_EQ(step.x_next, traj.states[n + 1]);  // the generator's own step
        const double h = data.generation_step;
        const double h0 = osc.hamiltonian(x), h1 = osc.hamiltonian(step.x_next);
        const double zw = step.flows.z * step.flows.w, uy = traj.u * step.flows.y;
        const double scale = std::abs(h0) + std::abs(h1) + h * std::abs(zw) + h * std::abs(uy);
        worst = std::max(worst, std::abs(h1 - h0 + h * (zw + uy)) / scale);
      }
    }
    EXPECT_LE(worst, 1e-12) << to_string(kind);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", worst);
    RecordProperty("power_balance_" + to_string(kind), buf);
  }
}

std::vector<Vec2> integrate(const Oscillator& osc, Vec2 x, double u, double h, int steps) {
  std::vector<Vec2> out{x};
  for (int n = 0; n < steps; ++n) {
    const auto step = discrete_gradient_step(osc, x, u, h);
    EXPECT_EQ(step.status, StepStatus::kConverged);
    x = step.x_next;
    out.push_back(x);
  }
  return out;
}

// u = -1: w* = 1 in I_w, the equilibrium is unstable and a limit cycle forms.
TEST(DiscreteGradientTest, SelfSustainedOscillatorSettlesOnLimitCycle) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kSelfSustained));
  const double h = 1.0 / 400.0, u = -1.0;
  const Vec2 x_star = osc.equilibrium(u);
  const auto xs = integrate(osc, x_star + Vec2(0.01, 0.0), u, h, 12000);  // 30 s
  // Upward crossings of q through 0 give the period.
  std::vector<double> crossings;
  for (std::size_t n = 1; n < xs.size(); ++n) {
    if (xs[n - 1](0) < 0.0 && xs[n](0) >= 0.0) {
      const double frac = xs[n - 1](0) / (xs[n - 1](0) - xs[n](0));
      crossings.push_back((static_cast<double>(n) - 1.0 + frac) * h);
    }
  }
  ASSERT_GE(crossings.size(), 4u);
  const std::size_t c = crossings.size();
  auto peak_to_peak = [&](double t0, double t1) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t n = 0; n < xs.size(); ++n) {
      const double t = static_cast<double>(n) * h;
      if (t >= t0 && t < t1) {
        lo = std::min(lo, xs[n](0));
        hi = std::max(hi, xs[n](0));
      }
    }
    return hi - lo;
  };
  const double a1 = peak_to_peak(crossings[c - 3], crossings[c - 2]);
  const double a2 = peak_to_peak(crossings[c - 2], crossings[c - 1]);
  EXPECT_GT(a1, 0.05);  // not small: the equilibrium is at q = 0
  EXPECT_NEAR(a1 / a2, 1.0, 0.01);
}

// u = -2: w* = 2 outside I_w, z'(2) = 2.6 > 0: the equilibrium
// (0, m z(w*)) is stable (eigenvalues -2.9 and -13.3 /s).
TEST(DiscreteGradientTest, SelfSustainedOscillatorOutsideIntervalConverges) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kSelfSustained));
  const double u = -2.0;
  const auto xs = integrate(osc, Vec2(0.2, -0.1), u, 1.0 / 400.0, 12000);
  const Vec2 expected(0.0, 0.16 * osc.dissipation(2.0));
  EXPECT_NEAR(expected(1), 0.064, 1e-15);
  EXPECT_LT((xs.back() - expected).norm(), 1e-10);
}

TEST(DiscreteGradientOptionsTest, RejectsNonPositiveStepAndTolerance) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kHarmonic));
  EXPECT_THAT([&] { discrete_gradient_step(osc, Vec2(0.1, 0.1), 0.0, -0.01); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("h = -0.01")));
  EXPECT_THAT([&] { discrete_gradient_step(osc, Vec2(0.1, 0.1), 0.0, 0.0); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("h = 0")));
  DiscreteGradientOptions options;
  options.newton_tolerance = 0.0;
  EXPECT_THAT([&] { options.validate(); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("newton_tolerance = 0")));
}

// A Newton cap that cannot be met is data in the step, not an exception.
TEST(DiscreteGradientTest, ReportsNonConvergenceInStatus) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  DiscreteGradientOptions options;
  options.max_newton_iterations = 1;
  options.newton_tolerance = 1e-300;
  const auto step = discrete_gradient_step(osc, Vec2(0.3, 0.2), 0.5, 0.01, options);
  EXPECT_EQ(step.status, StepStatus::kMaxIterations);
  EXPECT_EQ(step.newton_iterations, 1);
}

}  // namespace
}  // namespace phnn
