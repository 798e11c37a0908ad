// src/integrators/discrete_gradient4.cpp
#include "phnn/integrators/discrete_gradient4.h"

#include <cmath>

#include <Eigen/LU>

#include "phnn/common/check.h"
#include "phnn/integrators/runge_kutta4.h"

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

DiscreteGradient4Step discrete_gradient4_step(
    const Oscillator& system, const Vec2& x, double u, double h,
    const DiscreteGradientOptions& options) {
  PHNN_REQUIRE(std::isfinite(h) && h > 0.0,
               "discrete_gradient4_step: h = "
                   << h << "; violated constraint: h > 0.");
  DiscreteGradient4Step out;
  Vec2 dx = runge_kutta4_step(system, x, u, h) - x;
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
    const Mat2 jac =
        Mat2::Identity() -
        h * (Mat2::Identity() - (h * h / 12.0) * t.A * t.A) * t.F_e *
            system.average_vector_field_jacobian(x, dx);
    dx -= jac.partialPivLu().solve(r);
  }
  out.x_next = x + dx;
  return out;
}

}  // namespace phnn
