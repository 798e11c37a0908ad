// tests/reference/discrete_gradient.cpp — reference/discrete_gradient.h.
#include "reference/discrete_gradient.h"

#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "phnn/common/check.h"
#include "reference/explicit_midpoint.h"

namespace phnn {

Vec2 gonzalez_gradient(const std::function<double(const Vec2&)>& H,
                       const std::function<Vec2(const Vec2&)>& grad_H,
                       const Vec2& x, const Vec2& dx, double min_dx_norm) {
  const Vec2 grad_mid = grad_H(Vec2(x + 0.5 * dx));
  const double n2 = dx.squaredNorm();
  if (!(std::sqrt(n2) >= min_dx_norm) || n2 == 0.0) return grad_mid;
  const double defect = H(Vec2(x + dx)) - H(x) - grad_mid.dot(dx);
  return grad_mid + (defect / n2) * dx;
}

DiscreteGradientStep discrete_gradient_step(
    const Oscillator& system, const Vec2& x, double u, double h,
    const DiscreteGradientOptions& options) {
  PHNN_REQUIRE(std::isfinite(h) && h > 0.0,
               "discrete_gradient_step: h = " << h
                                              << "; violated constraint: h > 0.");
  const Eigen::Matrix4d& S = system.S();
  // dF/de = S_xx + S_xw z'(w) S_wx, e = effort (2), F = x_dot.
  auto residual_of = [&](const Vec2& dx, PortFlows* flows_out) {
    const Vec2 effort = system.discrete_gradient(x, dx);
    *flows_out = system.flows(effort, u);
    return Vec2(dx - h * flows_out->x_dot);
  };

  DiscreteGradientStep out;
  Vec2 dx = explicit_midpoint_step(system, x, u, h) - x;
  PortFlows flows;
  Vec2 r = residual_of(dx, &flows);
  for (int it = 0;; ++it) {
    out.residual = r.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(out.residual) || !dx.allFinite()) {
      out.status = StepStatus::kNonFinite;
      out.newton_iterations = it;
      break;
    }
    if (out.residual <= options.newton_tolerance) {
      out.status = StepStatus::kConverged;
      out.newton_iterations = it;
      break;
    }
    if (it >= options.max_newton_iterations) {
      out.status = StepStatus::kMaxIterations;
      out.newton_iterations = it;
      break;
    }
    // Newton: (I - h dF/de d dg/d dx) delta = -r.
    Mat2 dF_de = S.block<2, 2>(0, 0);
    const double dz_dw = system.dissipation_derivative(flows.w);
    dF_de += dz_dw * S.block<2, 1>(0, 2) * S.block<1, 2>(2, 0);
    const Mat2 jac = Mat2::Identity() -
                     h * dF_de * system.discrete_gradient_jacobian(x, dx);
    dx -= jac.partialPivLu().solve(r);
    r = residual_of(dx, &flows);
  }
  out.x_next = x + dx;
  out.flows = flows;
  return out;
}

}  // namespace phnn
