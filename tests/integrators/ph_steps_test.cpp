// tests/integrators/ph_steps_test.cpp — the n-dimensional steps on system
// files: DG4's power identity, exact conservation without ports, and the
// 2-state steps reproduced on the built-in oscillators. Convergence orders:
// integrator_orders_test.cpp.
#include "phnn/integrators/ph_steps.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "reference/discrete_gradient4.h"
#include "reference/explicit_midpoint.h"
#include "reference/runge_kutta4.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace {

std::string shipped(const std::string& name) {
  return std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml";
}

// H(x_{n+1}) - H(x_n) = -h (z^T w + u^T y) + h^3 e^T C for DG4 (an identity).
TEST(PhStepsTest, Dg4SatisfiesItsDiscretePowerIdentity) {
  for (const std::string name : {"pendulum", "coupled-duffing", "mass-chain"}) {
    const auto sys = load_system_file(shipped(name));
    VecX x = VecX::Constant(sys->n_x(), 0.1);
    const VecX u = VecX::Constant(1, -0.2);
    const double h = 0.02;
    for (int n = 0; n < 50; ++n) {
      const PhImplicitStep s = ph_discrete_gradient4_step(*sys, x, u, h);
      ASSERT_EQ(s.status, StepStatus::kConverged) << name;
      const double dH = sys->hamiltonian(s.x_next) - sys->hamiltonian(x);
      const double power = -h * (s.flows.z.dot(s.flows.w) + u.dot(s.flows.y)) + h * h * h * s.correction_power;
      EXPECT_NEAR(dH, power, 1e-12 * (std::abs(sys->hamiltonian(x)) + std::abs(power))) << name;
      x = s.x_next;
    }
  }
}

// Without ports and inputs DG conserves H to round-off (n_w = n_u = 0).
TEST(PhStepsTest, DiscreteGradientConservesEnergyWithoutPorts) {
  const std::string text = R"(name = "free-pendulum-chain"
states = ["q1", "q2", "p1", "p2"]
H = "(p1^2 + p2^2)/2 + (1 - cos(q1)) + (1 - cos(q2 - q1)) + q1^4/8"
S = [[0, 0, 1, 0], [0, 0, 0, 1], [-1, 0, 0, 0], [0, -1, 0, 0]]
[initial]
method = "box"
box = [[-1, 1], [-1, 1], [-1, 1], [-1, 1]]
)";
  const auto sys = compile_system(text, "free.toml");
  VecX x(4);
  x << 0.9, -0.4, 0.3, 0.8;
  const double H0 = sys->hamiltonian(x);
  for (int n = 0; n < 500; ++n) x = ph_discrete_gradient_step(*sys, x, VecX(0), 0.05).x_next;
  EXPECT_NEAR(sys->hamiltonian(x), H0, 1e-13);
}

// On a built-in oscillator the n-dimensional steps (RK2, RK4, DG, DG4) are
// the 2-state closed forms of tests/reference/; integrator_orders_test.cpp
// checks the orders of the former, so these follow.
TEST(PhStepsTest, StepsMatchTheTwoStateSteps) {
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    const auto sys = make_system(to_string(kind));
    const Vec2 x(0.2, -0.3);
    const VecX u = VecX::Constant(1, 0.4);
    EXPECT_LE((ph_rk2_step(*sys, x, u, 0.01) - VecX(explicit_midpoint_step(osc, x, 0.4, 0.01))).norm(), 1e-15);
    EXPECT_LE((ph_rk4_step(*sys, x, u, 0.01) - VecX(runge_kutta4_step(osc, x, 0.4, 0.01))).norm(), 1e-15);
    const VecX dg = ph_discrete_gradient_step(*sys, x, u, 0.01).x_next;
    EXPECT_LE((dg - VecX(discrete_gradient_step(osc, x, 0.4, 0.01).x_next)).norm(), 1e-14);
    const VecX dg4 = ph_discrete_gradient4_step(*sys, x, u, 0.01).x_next;
    EXPECT_LE((dg4 - VecX(discrete_gradient4_step(osc, x, 0.4, 0.01).x_next)).norm(), 1e-13);
  }
}

}  // namespace
}  // namespace phnn
