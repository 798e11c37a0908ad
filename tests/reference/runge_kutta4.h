// tests/reference/runge_kutta4.h — the 2-state closed-form step of the paper's
// oscillators (test code: the reference the n-dimensional steps of
// ph_steps.h are compared with).
// The classical fourth-order Runge-Kutta step: the explicit fourth-order
// scheme of the integrator work-precision study and of the `rk4` discrete
// models. Owns nothing but the step; touches no file.
#pragma once

#include "reference/oscillator.h"

namespace phnn {

/// Classical RK4 (Kutta 1901). Butcher tableau:
///
///     0  |
///    1/2 | 1/2
///    1/2 |  0   1/2
///     1  |  0    0    1
///   -----+--------------------
///        | 1/6  1/3  1/3  1/6
///
///   x_{n+1} = x_n + h (k1 + 2 k2 + 2 k3 + k4) / 6,  order 4.
template <class VectorField>
Vec2 runge_kutta4_step(const VectorField& f, const Vec2& x, double h) {
  const Vec2 k1 = f(x);
  const Vec2 k2 = f(Vec2(x + 0.5 * h * k1));
  const Vec2 k3 = f(Vec2(x + 0.5 * h * k2));
  const Vec2 k4 = f(Vec2(x + h * k3));
  return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

/// RK4 step of the true oscillator under constant input u.
Vec2 runge_kutta4_step(const Oscillator& system, const Vec2& x, double u,
                       double h);

}  // namespace phnn
