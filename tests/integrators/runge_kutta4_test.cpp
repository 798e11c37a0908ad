// tests/integrators/runge_kutta4_test.cpp
#include "reference/runge_kutta4.h"

#include <cmath>

#include <gtest/gtest.h>

#include "test_util.h"

namespace phnn {
namespace {

Vec2 integrate_rk4(const Oscillator& osc, Vec2 x, double u, double h,
                   int steps) {
  for (int n = 0; n < steps; ++n) x = runge_kutta4_step(osc, x, u, h);
  return x;
}

// One step on x' = lambda x reproduces the degree-4 Taylor polynomial of
// exp(h lambda) exactly (the defining property of a 4-stage order-4 RK).
TEST(RungeKutta4Test, MatchesFourthOrderTaylorOnLinearField) {
  const double lambda = -0.7, h = 0.3;
  const Vec2 x(1.0, -2.0);
  const Vec2 next = runge_kutta4_step(
      [&](const Vec2& s) { return Vec2(lambda * s); }, x, h);
  const double z = h * lambda;
  const double taylor = 1 + z + z * z / 2 + z * z * z / 6 + z * z * z * z / 24;
  EXPECT_NEAR(next(0), taylor * x(0), 1e-15);
  EXPECT_NEAR(next(1), taylor * x(1), 1e-15);
}

// Order 4.0 +- 0.15 against the closed-form damped, forced harmonic
// oscillator over 2 s (errors 1e-6..1e-9, far above round-off).
TEST(RungeKutta4Test, IsFourthOrderOnDampedHarmonicOscillator) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kHarmonic));
  const Vec2 x0(0.3, -0.1);
  const double u = 0.2, T = 2.0;
  const Vec2 exact =
      testing_util::damped_harmonic_solution(osc.options(), x0, u, T);
  double previous = 0.0;
  for (int steps : {50, 100, 200}) {
    const double err =
        (integrate_rk4(osc, x0, u, T / steps, steps) - exact).norm();
    if (previous > 0.0) {
      const double order = std::log2(previous / err);
      EXPECT_NEAR(order, 4.0, 0.15) << steps << " steps";
    }
    previous = err;
  }
}

}  // namespace
}  // namespace phnn
