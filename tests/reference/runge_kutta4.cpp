// tests/reference/runge_kutta4.cpp — reference/runge_kutta4.h.
#include "reference/runge_kutta4.h"

namespace phnn {

Vec2 runge_kutta4_step(const Oscillator& system, const Vec2& x, double u,
                       double h) {
  return runge_kutta4_step(
      [&](const Vec2& s) { return system.vector_field(s, u); }, x, h);
}

}  // namespace phnn
