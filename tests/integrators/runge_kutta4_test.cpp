// tests/integrators/runge_kutta4_test.cpp
#include "reference/runge_kutta4.h"

#include <cmath>

#include <gtest/gtest.h>

#include "test_util.h"

namespace phnn {
namespace {

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

}  // namespace
}  // namespace phnn
