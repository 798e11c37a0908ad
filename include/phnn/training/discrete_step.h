// include/phnn/training/discrete_step.h — discrete models g_theta (Eqs. 28-30).
#pragma once

#include <torch/torch.h>

#include "phnn/config/trainer_options.h"
#include "phnn/models/dynamics_model.h"

namespace phnn {

/// RK2 (eq: rk2-method with the factor h the paper drops; docs/METHOD.md §4):
///   x_hat = x + h f(x + (h/2) f(x, u), u).
/// `k1`, when defined, is f(x, u) already computed (e.g. with the Jacobian a
/// regularizer needs): the step then evaluates the field once more, not twice.
torch::Tensor rk2_step(const DynamicsModel& model, const torch::Tensor& x,
                       const torch::Tensor& u, double h, const torch::Tensor& k1 = {});

/// Classical RK4 (include/phnn/integrators/ph_steps.h has the tableau):
///   x_hat = x + h (k1 + 2 k2 + 2 k3 + k4) / 6, four evaluations of f.
torch::Tensor rk4_step(const DynamicsModel& model, const torch::Tensor& x,
                       const torch::Tensor& u, double h, const torch::Tensor& k1 = {});

/// The explicit discrete model of `integrator` (rk2 or rk4; throws for dg,
/// which needs x_next in training and Newton at inference); `k1` as in rk2_step.
torch::Tensor explicit_step(const DynamicsModel& model, IntegratorKind integrator,
                            const torch::Tensor& x, const torch::Tensor& u, double h,
                            const torch::Tensor& k1 = {});

/// DG in training, inverse-explicit (docs/METHOD.md §4): with the data step
/// dx = x_next - x, x_hat = x + h f_bar(x, dx, u).
torch::Tensor dg_training_step(const DynamicsModel& model, const torch::Tensor& x,
                               const torch::Tensor& x_next, const torch::Tensor& u, double h,
                               double min_dx_norm);

/// DG4 in training, inverse-explicit like DG: with the data step dx,
/// x_hat = x + h f4(x, dx, u) (DynamicsModel::discrete_gradient4_field).
torch::Tensor dg4_training_step(const DynamicsModel& model, const torch::Tensor& x,
                                const torch::Tensor& x_next, const torch::Tensor& u, double h,
                                double min_dx_norm);

/// The training step of `integrator`, x_hat from the data pair (x, x_next):
/// explicit_step for RK2/RK4 (x_next unused; `k1` as there), the inverse-
/// explicit dg_training_step / dg4_training_step for DG/DG4.
torch::Tensor training_step(const DynamicsModel& model, IntegratorKind integrator,
                            const torch::Tensor& x, const torch::Tensor& x_next,
                            const torch::Tensor& u, double h, double min_dx_norm,
                            const torch::Tensor& k1 = {});

/// The discrete loss L_d per member [E] of predictions x_hat for data x_next
/// ([E, B, 2] both) at step h, in `norm` (docs/METHOD.md §4, "Loss"); with
/// e = x_next - x_hat:
///   mean-l1: mean_{b, i} |e_bi| / h          (the default)
///   sum-l1:  mean_b (|e_b0| + |e_b1|) / h   (= 2 mean-l1 for 2 components)
///   mse:     mean_{b, i} e_bi^2 / h^2
torch::Tensor discrete_loss(const torch::Tensor& x_next, const torch::Tensor& x_hat, double h,
                            LossNorm norm);

/// Options of the implicit DG inference step.
struct DgInferenceOptions {
  /// A row has converged when its residual max |dx - h f_bar| <= tolerance.
  double tolerance = 1e-12;
  /// Newton updates at most; a row still above tolerance then is reported.
  int max_iterations = 20;
  double min_dx_norm = 6e-6;
};

/// The Newton Jacobian d f_bar / d dx [E, B, 2, 2] carried from one step of
/// a rollout to the next (the state moves by O(h) per step, so it stays a
/// good simplified-Newton matrix; rows where it is not get a fresh one).
struct DgNewtonJacobian {
  torch::Tensor dfddx;
};

struct DgInferenceStep {
  torch::Tensor x_next;          // [E, B, n_x]
  torch::Tensor converged;       // [E, B] bool (undefined for an explicit step)
  int iterations = 0;            // Newton updates of the slowest row
  int jacobian_evaluations = 0;  // batched Jacobian evaluations
};

/// DG at inference: solves r(dx) = dx - h f_bar(x, dx, u) = 0 by Newton from
/// the RK2 step, all members and rows at once, with the analytic 2 x 2
/// Jacobian I - h d f_bar / d dx (DynamicsModel::
/// discrete_gradient_field_with_jacobian, forward-mode jets), kept per row
/// while that row's residual shrinks at least 10x per iteration and
/// re-evaluated otherwise (simplified Newton; docs/DECISIONS.md "DG inference"). With `cache`,
/// a rollout reuses the previous step's Jacobians as the start. A row stops
/// (is frozen) once its residual is within tolerance; rows still above it
/// after max_iterations are reported in `converged`, not thrown.
DgInferenceStep dg_inference_step(const DynamicsModel& model, const torch::Tensor& x,
                                  const torch::Tensor& u, double h,
                                  const DgInferenceOptions& options = {},
                                  DgNewtonJacobian* cache = nullptr);

/// DG4 at inference: solves r(dx) = dx - h f4(x, dx, u) = 0 from the RK4
/// step by simplified Newton with the matrix I - (h/2) A, A = dF/dx at the
/// current iterate (returned by the same field evaluation: no extra cost);
/// a row whose residual shrinks less than 10x in one iteration switches to
/// the Jacobian of r by forward differences (two more evaluations). Rows
/// converge, freeze and are reported exactly as in dg_inference_step.
DgInferenceStep dg4_inference_step(const DynamicsModel& model, const torch::Tensor& x,
                                   const torch::Tensor& u, double h,
                                   const DgInferenceOptions& options = {});

/// One inference (rollout) step of `integrator`: explicit_step for RK2/RK4
/// (`converged` left undefined: no Newton), dg_inference_step (with `cache`)
/// or dg4_inference_step for DG/DG4.
DgInferenceStep inference_step(const DynamicsModel& model, IntegratorKind integrator,
                               const torch::Tensor& x, const torch::Tensor& u, double h,
                               const DgInferenceOptions& options = {},
                               DgNewtonJacobian* cache = nullptr);

}  // namespace phnn
