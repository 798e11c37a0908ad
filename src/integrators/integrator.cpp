// src/integrators/integrator.cpp — the table of include/phnn/integrators/
// integrator.h: one row per integrator, its physics step from ph_steps.h.
#include "phnn/integrators/integrator.h"

#include <cmath>

namespace phnn {

namespace {

// An explicit step as the contract returns it: converged unless non-finite
// (no Newton, no port variables).
template <VecX (*Step)(const PhSystem&, const VecX&, const VecX&, double)>
PhImplicitStep explicit_step(const PhSystem& system, const VecX& x, const VecX& u, double h,
                             const DiscreteGradientOptions& /*options*/) {
  PhImplicitStep s;
  s.x_next = Step(system, x, u, h);
  s.status = s.x_next.allFinite() ? StepStatus::kConverged : StepStatus::kNonFinite;
  return s;
}

}  // namespace

const std::vector<Integrator>& all_integrators() {
  static const std::vector<Integrator> table = {
      {IntegratorKind::kRk2, /*order=*/2, /*discrete_gradient=*/false, explicit_step<ph_rk2_step>},
      {IntegratorKind::kDg, /*order=*/2, /*discrete_gradient=*/true, ph_discrete_gradient_step},
      {IntegratorKind::kRk4, /*order=*/4, /*discrete_gradient=*/false, explicit_step<ph_rk4_step>},
      {IntegratorKind::kDg4, /*order=*/4, /*discrete_gradient=*/true, ph_discrete_gradient4_step},
  };
  return table;
}

const Integrator& integrator(IntegratorKind kind) {
  return all_integrators().at(static_cast<std::size_t>(kind));
}

}  // namespace phnn
