// tests/integrators/integrator_orders_test.cpp — the convergence order of
// every integrator of all_integrators() (mfem test_ode.cpp style: log2 of
// the error ratio when h halves equals the order), read from its table
// row: against the closed-form damped, forced harmonic oscillator and
// against a fine RK4 on nonlinear systems. A new integrator is tested here
// by its registration. The 2-state closed forms of tests/reference/ equal
// these steps (ph_steps_test.cpp), so their orders follow.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "phnn/integrators/integrator.h"
#include "phnn/systems/ph_system.h"
#include "test_util.h"

namespace phnn {
namespace {

// Step counts (halving h) and tolerance on log2 per order: errors well
// above round-off (>= 1e-10) and inside the asymptotic range.
struct Levels {
  std::vector<int> steps;
  double tolerance;
};
Levels levels_for(int order) {
  if (order == 2) return {{200, 400, 800}, 0.1};
  if (order == 4) return {{200, 400, 800}, 0.15};
  return {{}, 0.0};
}

// The states after every `every` steps of `steps` (x0 not included).
std::vector<VecX> samples(IntegratorKind kind, const PhSystem& sys, VecX x, const VecX& u, double h,
                          int steps, int every) {
  std::vector<VecX> out;
  for (int n = 1; n <= steps; ++n) {
    const PhImplicitStep s = ph_step(kind, sys, x, u, h);
    EXPECT_EQ(s.status, StepStatus::kConverged) << to_string(kind) << " step " << n;
    x = s.x_next;
    if (n % every == 0) out.push_back(x);
  }
  return out;
}

// Max-norm global error over the coarsest level's times t_k = k T / coarse
// (a single end time can sit near a zero of the error's leading term).
double global_error(IntegratorKind kind, const PhSystem& sys, const VecX& x0, const VecX& u,
                    double T, int steps, int coarse, const std::vector<VecX>& reference) {
  const std::vector<VecX> x = samples(kind, sys, x0, u, T / steps, steps, steps / coarse);
  double worst = 0.0;
  for (std::size_t k = 0; k < reference.size(); ++k) {
    worst = std::max(worst, (x[k] - reference[k]).norm());
  }
  return worst;
}

// log2(e(h) / e(h/2)) at each halving of `levels`, `error` of a step count.
template <class Error>
void expect_order(const Integrator& in, const Levels& levels, Error error,
                  const std::string& what) {
  double previous = 0.0;
  for (int steps : levels.steps) {
    const double err = error(steps);
    if (previous > 0.0) {
      EXPECT_NEAR(std::log2(previous / err), in.order, levels.tolerance)
          << to_string(in.kind) << " on " << what << ", " << steps << " steps: " << err;
    }
    previous = err;
  }
}

// The shipped harmonic system (the paper's, to 1e-12) over 2 s from
// (0.2, -0.1) under u = 0.4 against its closed form.
TEST(IntegratorOrderTest, EveryIntegratorHasItsOrderOnTheDampedHarmonicOscillator) {
  const auto sys = make_system("harmonic");
  const OscillatorOptions o = OscillatorOptions::defaults(SystemKind::kHarmonic);
  const Vec2 x0(0.2, -0.1);
  const double u = 0.4, T = 2.0;
  for (const Integrator& in : all_integrators()) {
    const Levels levels = levels_for(in.order);
    ASSERT_FALSE(levels.steps.empty())
        << to_string(in.kind) << ": no levels for order " << in.order;
    const int coarse = levels.steps.front();
    std::vector<VecX> exact;
    for (int k = 1; k <= coarse; ++k) {
      exact.push_back(testing_util::damped_harmonic_solution(o, x0, u, k * T / coarse));
    }
    expect_order(
        in, levels,
        [&](int steps) {
          return global_error(in.kind, *sys, x0, VecX::Constant(1, u), T, steps, coarse, exact);
        },
        "harmonic");
  }
}

// Nonlinear systems (Duffing: H''' != 0; the self-sustained oscillator:
// z'' != 0; the coupled Duffing chain: n_x = 4, n_w = 2) over 1 s against
// RK4 with 64x smaller steps than the finest level.
TEST(IntegratorOrderTest, EveryIntegratorHasItsOrderOnNonlinearSystems) {
  const DatasetOptions data;
  for (const std::string name : {"duffing", "self-sustained", "coupled-duffing"}) {
    const auto sys = make_system(name);
    VecX x0 = (VecX(4) << 0.12, -0.2, -0.05, 0.25).finished();
    VecX u = VecX::Constant(1, 0.3);
    if (name != "coupled-duffing") {  // data-set trajectory 5: its x0 and u
      const testing_util::PaperTrajectory t =
          testing_util::paper_trajectory(parse_system(name), data, /*index=*/5, 0);
      x0 = t.states[0];
      u = VecX::Constant(1, t.u);
    }
    const double T = 1.0;
    for (const Integrator& in : all_integrators()) {
      const Levels levels = levels_for(in.order);
      ASSERT_FALSE(levels.steps.empty()) << to_string(in.kind);
      const int coarse = levels.steps.front(), fine = levels.steps.back() * 64;
      const std::vector<VecX> reference =
          samples(IntegratorKind::kRk4, *sys, x0, u, T / fine, fine, fine / coarse);
      expect_order(
          in, levels,
          [&](int steps) {
            return global_error(in.kind, *sys, x0, u, T, steps, coarse, reference);
          },
          name);
    }
  }
}

// The table: one row per IntegratorKind, in its order, named as the enum.
TEST(IntegratorOrderTest, TheTableHasOneRowPerKind) {
  const std::vector<IntegratorKind> kinds = kIntegratorNames.all();
  ASSERT_EQ(all_integrators().size(), kinds.size());
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    EXPECT_EQ(all_integrators()[k].kind, kinds[k]);
    EXPECT_EQ(&integrator(kinds[k]), &all_integrators()[k]);
  }
  EXPECT_FALSE(is_discrete_gradient(IntegratorKind::kRk2));
  EXPECT_TRUE(is_discrete_gradient(IntegratorKind::kDg4));
}

}  // namespace
}  // namespace phnn
