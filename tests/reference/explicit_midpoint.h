// tests/reference/explicit_midpoint.h — the 2-state closed-form step of the paper's
// oscillators (test code: the reference the n-dimensional steps of
// ph_steps.h are compared with).
#pragma once

#include "reference/oscillator.h"

namespace phnn {

/// Explicit midpoint rule (RK2), paper eq: rk2-method, corrected:
///
///   x_{n+1} = x_n + h f(x_n + (h/2) f(x_n, u), u)
///
/// The paper prints x_{n+1} = x_n + f(...) without the outer factor h; that
/// is a typo (the update would not even have the units of a state).
/// Butcher tableau: c = (0, 1/2), a21 = 1/2, b = (0, 1). Order 2.
template <class VectorField>
Vec2 explicit_midpoint_step(const VectorField& f, const Vec2& x, double h) {
  const Vec2 k1 = f(x);
  return x + h * f(Vec2(x + 0.5 * h * k1));
}

/// RK2 step of the true oscillator under constant input u.
Vec2 explicit_midpoint_step(const Oscillator& system, const Vec2& x, double u,
                            double h);

}  // namespace phnn
