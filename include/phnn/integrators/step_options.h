// include/phnn/integrators/step_options.h — what every implicit step of the
// integrators (ph_steps.h) and the data generator share: the Newton options of
// the discrete-gradient step and how a step ended. No state, no files.
#pragma once

#include <string>

#include "phnn/common/enum_names.h"

namespace phnn {

/// Options of the implicit discrete-gradient step. Defaults are docs/METHOD.md §2.
struct DiscreteGradientOptions {
  /// Newton stops when ||dx - h f_bar(dx)||_inf <= newton_tolerance. The
  /// power-balance error of a step equals gradbar^T (residual), so this
  /// tolerance shows up directly in the balance (docs/METHOD.md §2).
  double newton_tolerance = 1e-14;
  /// Reaching the cap is reported in the step's status.
  int max_newton_iterations = 50;
  /// Below this ||dx|| the generic Gonzalez quotient is 0/0-prone: use
  /// gradH(x + dx/2) alone (docs/METHOD.md §4: tau = 6e-6, about cbrt(eps)).
  double min_dx_norm = 6e-6;

  /// Throws std::invalid_argument naming the field, value and constraint.
  void validate() const;
};

enum class StepStatus { kConverged, kMaxIterations, kNonFinite };
inline constexpr EnumNames<StepStatus, 3> kStepStatusNames{
    "step status", {{{StepStatus::kConverged, "converged"}, {StepStatus::kMaxIterations, "max-iterations"},
                     {StepStatus::kNonFinite, "non-finite"}}}};
inline std::string to_string(StepStatus status) { return kStepStatusNames.name(status); }

}  // namespace phnn
