// include/phnn/integrators/ph_steps.h — RK2, RK4, the Gonzalez discrete
// gradient and the fourth-order DG for any PhSystem (n_x states, n_w ports,
// n_u inputs, u constant over the step). The same schemes as the 2-state
// steps of explicit_midpoint.h, runge_kutta4.h, discrete_gradient.h and
// discrete_gradient4.h (whose comments derive them), in Eigen's dynamic
// sizes. Owns nothing but the steps; touches no file.
#pragma once

#include "phnn/integrators/discrete_gradient.h"
#include "phnn/systems/ph_system.h"

namespace phnn {

/// x + h f(x + (h/2) f(x, u), u)  (eq: rk2-method with the factor h).
VecX ph_rk2_step(const PhSystem& system, const VecX& x, const VecX& u, double h);
/// Classical RK4: x + h (k1 + 2 k2 + 2 k3 + k4) / 6.
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

/// DG4 (discrete_gradient4.h), with z''(w)[s, s] for n_w ports:
///   d = h F(e) + h^3 C,  C = S_xw z''(w)[s, s] / 24 - A A v / 12,
///   e = avf(x, d), v = F(e), A = F_e H''(a), s = S_wx H''(a) v.
/// Simplified Newton from the RK4 step (then from the DG step), switching
/// to central-difference Jacobians when it contracts by less than 10x.
PhImplicitStep ph_discrete_gradient4_step(const PhSystem& system, const VecX& x, const VecX& u,
                                          double h, const DiscreteGradientOptions& options = {});

}  // namespace phnn
