// tests/integrators/explicit_midpoint_test.cpp
#include "reference/explicit_midpoint.h"

#include <cmath>

#include <gtest/gtest.h>

#include "test_util.h"

namespace phnn {
namespace {

// One step on x' = a x equals the degree-2 Taylor polynomial exactly:
// x1 = (1 + a h + (a h)^2 / 2) x0 (the corrected eq: rk2-method, with h).
TEST(ExplicitMidpointTest, MatchesSecondOrderTaylorOnLinearScalarField) {
  const double a = -1.7, h = 0.05;
  const Vec2 x0(0.3, -0.2);
  const Vec2 x1 = explicit_midpoint_step([&](const Vec2& x) { return Vec2(a * x); }, x0, h);
  const double factor = 1.0 + a * h + 0.5 * a * a * h * h;
  EXPECT_NEAR(x1(0), factor * x0(0), 1e-16);
  EXPECT_NEAR(x1(1), factor * x0(1), 1e-16);
}

}  // namespace
}  // namespace phnn
