// src/integrators/step_options.cpp — include/phnn/integrators/step_options.h.
#include "phnn/integrators/step_options.h"

#include <cmath>

#include "phnn/common/check.h"

namespace phnn {

void DiscreteGradientOptions::validate() const {
  PHNN_REQUIRE(std::isfinite(newton_tolerance) && newton_tolerance > 0.0,
               "Invalid DiscreteGradientOptions: newton_tolerance = "
                   << newton_tolerance
                   << "; violated constraint: newton_tolerance > 0.");
  PHNN_REQUIRE(max_newton_iterations >= 1,
               "Invalid DiscreteGradientOptions: max_newton_iterations = "
                   << max_newton_iterations
                   << "; violated constraint: max_newton_iterations >= 1.");
  PHNN_REQUIRE(std::isfinite(min_dx_norm) && min_dx_norm >= 0.0,
               "Invalid DiscreteGradientOptions: min_dx_norm = "
                   << min_dx_norm
                   << "; violated constraint: min_dx_norm >= 0.");
}

}  // namespace phnn
