// tests/integrators/discrete_gradient4_test.cpp
#include "reference/discrete_gradient4.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "phnn/data/dataset.h"
#include "reference/runge_kutta4.h"
#include "test_util.h"

namespace phnn {
namespace {

// The AVF gradient is a discrete gradient (chain rule to 1e-13 |H|) that
// tends to gradH(x) as dx -> 0.
TEST(DiscreteGradient4Test, AverageVectorFieldIsADiscreteGradient) {
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> c(-0.5, 0.5), d(-0.2, 0.2);
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    for (int i = 0; i < 300; ++i) {
      const Vec2 x(c(gen), c(gen)), dx(d(gen), d(gen));
      const double dH = osc.hamiltonian(x + dx) - osc.hamiltonian(x);
      EXPECT_NEAR(osc.average_vector_field_gradient(x, dx).dot(dx), dH,
                  1e-13 * (1.0 + std::abs(osc.hamiltonian(x))));
    }
    const Vec2 x(0.2, -0.1);
    EXPECT_EQ(osc.average_vector_field_gradient(x, Vec2::Zero()),
              osc.grad_hamiltonian(x));
  }
}

// The analytic d(avf)/d(dx) against central differences (step 1e-6,
// truncation error ~1e-12 times the third derivative).
TEST(DiscreteGradient4Test, AverageVectorFieldJacobianMatchesDifferences) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  const Vec2 x(0.21, -0.05), dx(0.03, -0.02);
  const Mat2 jac = osc.average_vector_field_jacobian(x, dx);
  const double eta = 1e-6;
  for (int j = 0; j < 2; ++j) {
    Vec2 e = Vec2::Zero();
    e(j) = eta;
    const Vec2 column = (osc.average_vector_field_gradient(x, dx + e) -
                         osc.average_vector_field_gradient(x, dx - e)) /
                        (2 * eta);
    EXPECT_LE((column - jac.col(j)).norm(), 1e-7 * (1.0 + jac.norm()));
  }
}

// Power balance of every step, to 1e-12 of the step's power scale
// h (|z w| + |u y| + h^2 |e^T C|) + |H|:
//   H(x_{n+1}) - H(x_n) = -h (z w + u y) + h^3 e^T C.
TEST(DiscreteGradient4Test, SatisfiesDiscretePowerBalance) {
  const DatasetOptions data;
  const double h = 0.01;
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    for (int index : {0, 1, 2}) {
      const testing_util::PaperTrajectory spec = testing_util::paper_trajectory(kind, data, index, 0);
      Vec2 x = spec.states[0];
      for (int n = 0; n < 300; ++n) {
        const DiscreteGradient4Step s =
            discrete_gradient4_step(osc, x, spec.u, h);
        ASSERT_EQ(s.status, StepStatus::kConverged);
        const double port = s.flows.z * s.flows.w + spec.u * s.flows.y;
        const double dH = osc.hamiltonian(s.x_next) - osc.hamiltonian(x);
        const double rhs = -h * port + h * h * h * s.correction_power;
        const double scale = h * (std::abs(port) +
                                  h * h * std::abs(s.correction_power)) +
                             std::abs(osc.hamiltonian(x));
        EXPECT_LE(std::abs(dH - rhs), 1e-12 * scale)
            << to_string(kind) << " trajectory " << index << " step " << n;
        x = s.x_next;
      }
    }
  }
}

// Without ports (z = 0, u = 0) the correction carries no power and DG4
// conserves H to round-off over 10^4 steps, even for the Duffing H.
TEST(DiscreteGradient4Test, ConservesEnergyWithoutPorts) {
  OscillatorOptions options = OscillatorOptions::defaults(SystemKind::kDuffing);
  options.damping = 0.0;
  const Oscillator osc(options);
  Vec2 x(0.2, 0.05);
  const double H0 = osc.hamiltonian(x);
  double worst_power = 0.0;
  for (int n = 0; n < 10000; ++n) {
    const DiscreteGradient4Step s = discrete_gradient4_step(osc, x, 0.0, 0.01);
    ASSERT_EQ(s.status, StepStatus::kConverged);
    worst_power = std::max(worst_power, std::abs(s.correction_power));
    x = s.x_next;
  }
  EXPECT_LE(worst_power, 1e-9 * H0);
  // Random-walk round-off: ~eps sqrt(n) per unit of H.
  EXPECT_LE(std::abs(osc.hamiltonian(x) - H0), 1e-12 * H0);
}

}  // namespace
}  // namespace phnn
