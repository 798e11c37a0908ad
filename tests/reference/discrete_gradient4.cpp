// tests/reference/discrete_gradient4.cpp — reference/discrete_gradient4.h.
#include "reference/discrete_gradient4.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "phnn/common/check.h"
#include "reference/runge_kutta4.h"

namespace phnn {
namespace {

// The pieces of (DG4) at one increment d.
struct Dg4Terms {
  Vec2 effort = Vec2::Zero();  // e = avf(x, d)
  PortFlows flows;             // F(e) = flows.x_dot
  Mat2 F_e = Mat2::Zero();     // dF/de at w
  Mat2 A = Mat2::Zero();       // F_e Q(a)
  Vec2 correction = Vec2::Zero();  // C
};

Dg4Terms dg4_terms(const Oscillator& system, const Vec2& x, const Vec2& dx,
                   double u) {
  const Eigen::Matrix4d& S = system.S();
  Dg4Terms t;
  t.effort = system.average_vector_field_gradient(x, dx);
  t.flows = system.flows(t.effort, u);
  const Vec2 S_xw = S.block<2, 1>(0, 2);
  const Eigen::RowVector2d S_wx = S.block<1, 2>(2, 0);
  t.F_e = S.block<2, 2>(0, 0) +
          system.dissipation_derivative(t.flows.w) * S_xw * S_wx;
  const Mat2 Q = system.hessian(Vec2(x + 0.5 * dx));
  t.A = t.F_e * Q;
  const Vec2& v = t.flows.x_dot;
  const double s = S_wx * (Q * v);
  t.correction = (system.dissipation_second_derivative(t.flows.w) * s * s /
                  24.0) * S_xw -
                 (t.A * (t.A * v)) / 12.0;
  return t;
}

}  // namespace

Vec2 discrete_gradient4_increment(const Oscillator& system, const Vec2& x,
                                  const Vec2& dx, double u, double h,
                                  PortFlows* flows, double* correction_power) {
  const Dg4Terms t = dg4_terms(system, x, dx, u);
  if (flows != nullptr) *flows = t.flows;
  if (correction_power != nullptr) {
    *correction_power = t.effort.dot(t.correction);
  }
  return h * t.flows.x_dot + (h * h * h) * t.correction;
}

namespace {

// d r / d d by central differences of the residual r(d) = d - rhs(d):
// step 1e-6 max(|d|_inf, 1e-12) balances truncation (~1e-12) against
// round-off (~eps / 1e-6 = 1e-10 relative).
Mat2 residual_jacobian_by_differences(const Oscillator& system, const Vec2& x,
                                      const Vec2& dx, double u, double h) {
  const double eta = 1e-6 * std::max(dx.lpNorm<Eigen::Infinity>(), 1e-12);
  Mat2 jac;
  for (int j = 0; j < 2; ++j) {
    Vec2 plus = dx, minus = dx;
    plus(j) += eta;
    minus(j) -= eta;
    const Vec2 r_plus = plus - discrete_gradient4_increment(system, x, plus, u, h);
    const Vec2 r_minus =
        minus - discrete_gradient4_increment(system, x, minus, u, h);
    jac.col(j) = (r_plus - r_minus) / (plus(j) - minus(j));
  }
  return jac;
}

// Newton on r(d) = d - h F(e) - h^3 C from d0: simplified (analytic
// Jacobian less the derivatives of A and z'') while it contracts by 10x per
// iteration, then full (central differences: large h, where those matter).
DiscreteGradient4Step solve_dg4(const Oscillator& system, const Vec2& x,
                                double u, double h, Vec2 dx,
                                const DiscreteGradientOptions& options) {
  DiscreteGradient4Step out;
  bool full_newton = false;
  double previous_residual = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    const Dg4Terms t = dg4_terms(system, x, dx, u);
    const Vec2 r = dx - h * t.flows.x_dot - (h * h * h) * t.correction;
    out.residual = r.lpNorm<Eigen::Infinity>();
    out.newton_iterations = it;
    out.flows = t.flows;
    out.correction_power = t.effort.dot(t.correction);
    if (!std::isfinite(out.residual) || !dx.allFinite()) {
      out.status = StepStatus::kNonFinite;
      break;
    }
    if (out.residual <= options.newton_tolerance) {
      out.status = StepStatus::kConverged;
      break;
    }
    if (it >= options.max_newton_iterations) {
      out.status = StepStatus::kMaxIterations;
      break;
    }
    full_newton = full_newton || out.residual > 0.1 * previous_residual;
    previous_residual = out.residual;
    const Mat2 jac =
        full_newton
            ? residual_jacobian_by_differences(system, x, dx, u, h)
            : Mat2(Mat2::Identity() -
                   h * (Mat2::Identity() - (h * h / 12.0) * t.A * t.A) *
                       t.F_e * system.average_vector_field_jacobian(x, dx));
    dx -= jac.partialPivLu().solve(r);
  }
  out.x_next = x + dx;
  return out;
}

}  // namespace

DiscreteGradient4Step discrete_gradient4_step(
    const Oscillator& system, const Vec2& x, double u, double h,
    const DiscreteGradientOptions& options) {
  PHNN_REQUIRE(std::isfinite(h) && h > 0.0,
               "discrete_gradient4_step: h = "
                   << h << "; violated constraint: h > 0.");
  // RK4 is the closer start where it is stable; on stiff steps (the
  // self-sustained oscillator's damping at |w| ~ 2 reaches h z' k ~ 20 at
  // h = 0.08 s) it explodes, and the A-stable Gonzalez step is the start.
  const Vec2 rk4_start = runge_kutta4_step(system, x, u, h) - x;
  DiscreteGradient4Step out = solve_dg4(system, x, u, h, rk4_start, options);
  if (out.status == StepStatus::kConverged) return out;
  const DiscreteGradientStep dg = discrete_gradient_step(system, x, u, h, options);
  if (dg.status != StepStatus::kConverged) return out;
  const int first_iterations = out.newton_iterations;
  out = solve_dg4(system, x, u, h, Vec2(dg.x_next - x), options);
  out.newton_iterations += first_iterations;
  return out;
}

}  // namespace phnn
