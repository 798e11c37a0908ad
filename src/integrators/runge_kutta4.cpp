// src/integrators/runge_kutta4.cpp
#include "phnn/integrators/runge_kutta4.h"

namespace phnn {

Vec2 runge_kutta4_step(const Oscillator& system, const Vec2& x, double u,
                       double h) {
  return runge_kutta4_step(
      [&](const Vec2& s) { return system.vector_field(s, u); }, x, h);
}

}  // namespace phnn
