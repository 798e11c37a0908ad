// tests/reference/explicit_midpoint.cpp — reference/explicit_midpoint.h.
#include "reference/explicit_midpoint.h"

namespace phnn {

Vec2 explicit_midpoint_step(const Oscillator& system, const Vec2& x, double u,
                            double h) {
  return explicit_midpoint_step(
      [&](const Vec2& state) { return system.vector_field(state, u); }, x, h);
}

}  // namespace phnn
