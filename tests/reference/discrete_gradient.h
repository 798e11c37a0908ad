// tests/reference/discrete_gradient.h — the closed-form 2-state discrete
// gradient step of the paper's oscillators (reference/oscillator.h): an
// implementation independent of the system files' (ph_steps.h), which the
// tests compare them with. Test code only.
#pragma once

#include <functional>
#include <string>

#include "phnn/integrators/step_options.h"
#include "reference/oscillator.h"

namespace phnn {

/// Generic Gonzalez discrete gradient (eq: gonzalez-discrete-gradient;
/// O. Gonzalez, J. Nonlinear Sci. 6:449-467, 1996):
///
///   dg(x, dx) = gradH(x + dx/2)
///             + (H(x + dx) - H(x) - gradH(x + dx/2)^T dx) / (dx^T dx) dx
///
/// with the fallback dg = gradH(x + dx/2) when ||dx|| < min_dx_norm (the
/// dropped term is O(||dx||^3 H''')). Property 1: dg^T dx = H(x+dx) - H(x);
/// property 2: dg(x, 0) = gradH(x).
Vec2 gonzalez_gradient(const std::function<double(const Vec2&)>& H,
                       const std::function<Vec2(const Vec2&)>& grad_H,
                       const Vec2& x, const Vec2& dx,
                       double min_dx_norm = 6e-6);

/// One implicit DG step of a PH-DAE and its port variables, evaluated at the
/// discrete gradient: the power balance of the step reads
///   H(x_next) - H(x) = -h (z w + u y)   (to round-off).
struct DiscreteGradientStep {
  Vec2 x_next = Vec2::Zero();
  PortFlows flows;  // at effort dg(x, x_next - x)
  StepStatus status = StepStatus::kNonFinite;
  int newton_iterations = 0;
  double residual = 0.0;  // ||dx - h f_bar||_inf at exit
};

/// Implicit DG step of the oscillator's PH-DAE (docs/METHOD.md §2):
///   dx / h = S_xx dg(x, dx) + S_xw z(w) + S_xu u,  w = S_wx dg + S_wu u,
/// solved for dx by Newton from the explicit-midpoint step, with the
/// oscillator's cancellation-free closed-form discrete gradient.
DiscreteGradientStep discrete_gradient_step(
    const Oscillator& system, const Vec2& x, double u, double h,
    const DiscreteGradientOptions& options = {});

}  // namespace phnn
