// include/phnn/integrators/ph_steps.h — RK2, RK4, the Gonzalez discrete
// gradient and the fourth-order DG for any PhSystem (n_x states, n_w ports,
// n_u inputs, u constant over the step), the paper's three oscillators
// included (their shipped files). Owns nothing but the steps; touches no
// file. The tests compare them with closed-form 2-state versions
// (tests/reference/).
#pragma once

#include "phnn/integrators/step_options.h"
#include "phnn/systems/ph_system.h"

namespace phnn {

/// Explicit midpoint rule, paper eq: rk2-method, corrected:
///   x_{n+1} = x_n + h f(x_n + (h/2) f(x_n, u), u).
/// The paper prints x_{n+1} = x_n + f(...) without the outer factor h (a
/// typo: the update would not have the units of a state). Butcher tableau
/// c = (0, 1/2), a21 = 1/2, b = (0, 1). Order 2.
VecX ph_rk2_step(const PhSystem& system, const VecX& x, const VecX& u, double h);
/// Classical RK4 (Kutta 1901), order 4:
///     0  |
///    1/2 | 1/2
///    1/2 |  0   1/2
///     1  |  0    0    1
///   -----+--------------------
///        | 1/6  1/3  1/3  1/6
///   x_{n+1} = x_n + h (k1 + 2 k2 + 2 k3 + k4) / 6.
VecX ph_rk4_step(const PhSystem& system, const VecX& x, const VecX& u, double h);

/// An implicit step and its port variables (at the step's effort).
struct PhImplicitStep {
  VecX x_next;
  PhFlows flows;
  StepStatus status = StepStatus::kNonFinite;
  int newton_iterations = 0;
  double residual = 0.0;          // max-norm of the residual at exit
  double correction_power = 0.0;  // DG4: e^T C (0 for DG)
};

/// Gonzalez DG step of the PH-DAE (docs/METHOD.md §2):
///   dx / h = S_xx dg(x, dx) + S_xw z(w) + S_xu u,  w = S_wx dg + S_wu u,
/// Newton from the RK2 step with the matrix I - h dF/de d dg/d dx. Power
/// balance: H(x_next) - H(x) = -h (z^T w + u^T y) to round-off.
PhImplicitStep ph_discrete_gradient_step(const PhSystem& system, const VecX& x, const VecX& u,
                                         double h, const DiscreteGradientOptions& options = {});

/// Average-vector-field discrete gradient: 3-point Gauss-Legendre mean of
/// gradH on the segment (exact for H of degree <= 6), projected so that
/// avf^T dx = H(x + dx) - H(x) (gradH(x + dx/2)-only below tau).
VecX ph_average_vector_field_gradient(const PhSystem& system, const VecX& x, const VecX& dx);

/// The fourth-order discrete-gradient step ("DG4"; docs/METHOD.md,
/// "Fourth-order schemes"). With d = x_{n+1} - x_n, midpoint a = x_n + d/2,
/// Q = H''(a):
///   e   = avf(x_n, d)   (a discrete gradient),  w = S_wx e + S_wu u,
///   F(e) = S_xx e + S_xw z(w) + S_xu u,  F_e = S_xx + S_xw z'(w) S_wx,
///   A = F_e Q,  v = F(e),  s = S_wx Q v,
///   C = S_xw z''(w)[s, s] / 24 - A A v / 12,
///   d = h F(e) + h^3 C                                              (DG4)
/// Why fourth order: the implicit midpoint rule has local error
/// h^3 [f'f'f / 12 - f''(f, f) / 24]; the AVF effort adds h^3 F_e H'''[f, f]
/// / 24, which cancels the H''' part of f''(f, f), leaving -h^3 C + O(h^5).
/// Every term is evaluated at (a, e, v), which the adjoint map leaves
/// unchanged: the step is symmetric, its h^4 term vanishes (order 4; with
/// linear z and S_xx = J, C = -(J Q)^2 v / 12 is Cohen and Hairer's
/// correction, BIT 51, 2011). Power balance, exact to round-off:
///   H(x_{n+1}) - H(x_n) = -h (z^T w + u^T y) + h^3 e^T C.
/// Simplified Newton from the RK4 step (then from the DG step), switching
/// to central-difference Jacobians when it contracts by less than 10x.
PhImplicitStep ph_discrete_gradient4_step(const PhSystem& system, const VecX& x, const VecX& u,
                                          double h, const DiscreteGradientOptions& options = {});

}  // namespace phnn
