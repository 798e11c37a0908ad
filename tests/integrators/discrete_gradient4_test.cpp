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

Vec2 integrate_dg4(const Oscillator& osc, Vec2 x, double u, double h,
                   int steps) {
  for (int n = 0; n < steps; ++n) {
    const DiscreteGradient4Step step = discrete_gradient4_step(osc, x, u, h);
    EXPECT_EQ(step.status, StepStatus::kConverged) << "step " << n;
    x = step.x_next;
  }
  return x;
}

Vec2 integrate_rk4(const Oscillator& osc, Vec2 x, double u, double h,
                   int steps) {
  for (int n = 0; n < steps; ++n) x = runge_kutta4_step(osc, x, u, h);
  return x;
}

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

// Order 4.0 +- 0.15 against the closed-form damped, forced harmonic
// oscillator (linear: DG4 is the Cayley map of the corrected matrix).
TEST(DiscreteGradient4Test, IsFourthOrderOnDampedHarmonicOscillator) {
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kHarmonic));
  const Vec2 x0(0.3, -0.1);
  const double u = 0.2, T = 2.0;
  const Vec2 exact =
      testing_util::damped_harmonic_solution(osc.options(), x0, u, T);
  double previous = 0.0;
  for (int steps : {50, 100, 200}) {
    const double err =
        (integrate_dg4(osc, x0, u, T / steps, steps) - exact).norm();
    if (previous > 0.0) {
      EXPECT_NEAR(std::log2(previous / err), 4.0, 0.15) << steps << " steps";
    }
    previous = err;
  }
}

// Order 4.0 +- 0.15 on the nonlinear systems (Duffing: H''' != 0; the
// self-sustained oscillator: z'' != 0), over 1 s from a data-set initial
// state, against RK4 with 64x smaller steps (its error is ~1e-7 of DG4's).
TEST(DiscreteGradient4Test, IsFourthOrderOnNonlinearSystems) {
  const DatasetOptions data;
  for (SystemKind kind : {SystemKind::kDuffing, SystemKind::kSelfSustained}) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    const testing_util::PaperTrajectory spec = testing_util::paper_trajectory(kind, data, /*index=*/5, 0);
    const double T = 1.0;
    const Vec2 reference =
        integrate_rk4(osc, spec.states[0], spec.u, T / (200 * 64), 200 * 64);
    double previous = 0.0;
    for (int steps : {100, 200, 400}) {
      const double err =
          (integrate_dg4(osc, spec.states[0], spec.u, T / steps, steps) - reference)
              .norm();
      if (previous > 0.0) {
        EXPECT_NEAR(std::log2(previous / err), 4.0, 0.15)
            << to_string(kind) << ", " << steps << " steps";
      }
      previous = err;
    }
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
