// tests/reference/discrete_gradient4.h — the 2-state closed-form step of the paper's
// oscillators (test code: the reference the n-dimensional steps of
// ph_steps.h are compared with).
// A fourth-order, energy-consistent discrete-gradient step for the
// oscillators' PH-DAE: the implicit solve on the true systems (work-precision
// study, stress suite). The same formula, with both end points known, is the
// inverse-explicit `dg4` training step (docs/METHOD.md, "Fourth-order
// schemes", derives it).
#pragma once

#include "reference/discrete_gradient.h"
#include "reference/oscillator.h"

namespace phnn {

/// The fourth-order discrete-gradient step ("DG4"). With d = x_{n+1} - x_n,
/// midpoint a = x_n + d/2 and Q = H''(a):
///
///   e   = avf(x_n, d) = int_0^1 gradH(x_n + s d) ds   (a discrete gradient)
///   w   = S_wx e + S_wu u,   F(e) = S_xx e + S_xw z(w) + S_xu u
///   F_e = S_xx + z'(w) S_xw S_wx,   A = F_e Q,   v = F(e)
///   C   = z''(w) (S_wx Q v)^2 S_xw / 24 - A A v / 12
///   d   = h F(e) + h^3 C                                            (DG4)
///
/// Why fourth order: the implicit midpoint rule d = h f(a) has local error
/// h^3 [f'f'f / 12 - f''(f, f) / 24]; the AVF effort adds h^3 F_e H'''[f, f]/24,
/// which cancels the H''' part of f''(f, f), leaving
/// h^3 [f'f'f / 12 - F_ee[Qf, Qf] / 24] = -h^3 C + O(h^5). Every term is
/// evaluated at (a, e, v), which the adjoint map (x_n, x_{n+1}, h) ->
/// (x_{n+1}, x_n, -h) leaves unchanged, so the step is symmetric and its
/// h^4 error term vanishes: order 4 (tested: 4.0 +- 0.15). With linear z
/// and S_xx = J, C = -(1/12) (J Q)^2 v is the correction of Cohen and
/// Hairer (BIT 51, 2011) for linear energy-preserving integrators; the form
/// x_{n+1} = x_n + h S_bar(x_n, x_{n+1}, h) grad_bar H is the class whose
/// order conditions S. Eidnes gives (BIT Numer. Math. 62, 2022).
///
/// Power balance, exact to round-off (e^T d = H(x_{n+1}) - H(x_n) because
/// e is a discrete gradient; e^T F(e) = -(z w + u y) because S = -S^T):
///
///   H(x_{n+1}) - H(x_n) = -h (z(w) w + u y) + h^3 e^T C.
///
/// The last term is the scheme's O(h^2) correction to the port power; it
/// is identically 0 without ports (z = 0, u = 0: e^T (J Q)^2 J e = 0),
/// where DG4 conserves H exactly.
struct DiscreteGradient4Step {
  Vec2 x_next = Vec2::Zero();
  PortFlows flows;               // at the effort e
  double correction_power = 0;   // e^T C (the h^3 term above, divided by h^3)
  StepStatus status = StepStatus::kNonFinite;
  int newton_iterations = 0;
  double residual = 0.0;         // ||d - h F(e) - h^3 C||_inf at exit
};

/// The DG4 increment's right-hand side h F(e) + h^3 C for a given d
/// (explicit in d: the training form, both end points known).
Vec2 discrete_gradient4_increment(const Oscillator& system, const Vec2& x,
                                  const Vec2& dx, double u, double h,
                                  PortFlows* flows = nullptr,
                                  double* correction_power = nullptr);

/// Solves (DG4) for d by simplified Newton from the RK4 step, Jacobian
/// I - h (I - h^2 A A / 12) F_e d(avf)/dd (the exact one less the
/// derivatives of A and z''). Stops when the residual's max-norm is
/// <= options.newton_tolerance; the same options as the Gonzalez step.
DiscreteGradient4Step discrete_gradient4_step(
    const Oscillator& system, const Vec2& x, double u, double h,
    const DiscreteGradientOptions& options = {});

}  // namespace phnn
