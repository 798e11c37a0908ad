// include/phnn/integrators/integrator.h — the integrators, one row each
// (MFEM's ODESolver in spirit): kind and name, order, whether it is a
// discrete gradient, and its physics step on any PhSystem. The models'
// steps (training and rollout) dispatch on the same kind in
// training/discrete_step.h; adding an integrator: docs/METHOD.md, "Adding
// an integrator". No state, no files.
#pragma once

#include <vector>

#include "phnn/integrators/integrator_kind.h"
#include "phnn/integrators/ph_steps.h"

namespace phnn {

/// One integrator's contract.
struct Integrator {
  IntegratorKind kind;
  /// Global order p: the error after a fixed time falls as h^p (one step's
  /// as h^(p+1)); the order tests read it.
  int order;
  /// A discrete gradient: needs a Hamiltonian (not NODE), is inverse-
  /// explicit in training and implicit (Newton) at inference, and keeps the
  /// power balance to round-off.
  bool discrete_gradient;
  /// x_{n+1} from x_n under u constant over the step (ph_steps.h); an
  /// explicit step reports kConverged, or kNonFinite.
  PhImplicitStep (*step)(const PhSystem& system, const VecX& x, const VecX& u, double h,
                         const DiscreteGradientOptions& options);
};

/// Every integrator, in the order of IntegratorKind.
const std::vector<Integrator>& all_integrators();
const Integrator& integrator(IntegratorKind kind);

/// DG and DG4.
inline bool is_discrete_gradient(IntegratorKind kind) { return integrator(kind).discrete_gradient; }

/// The physics step of `kind`.
inline PhImplicitStep ph_step(IntegratorKind kind, const PhSystem& system, const VecX& x,
                              const VecX& u, double h,
                              const DiscreteGradientOptions& options = {}) {
  return integrator(kind).step(system, x, u, h, options);
}

}  // namespace phnn
