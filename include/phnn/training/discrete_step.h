// include/phnn/training/discrete_step.h — discrete models g_theta (Eqs. 28-30).
#pragma once

#include <torch/torch.h>

#include "phnn/models/dynamics_model.h"

namespace phnn {

/// RK2 (eq: rk2-method with the factor h the paper drops; SPEC.md §4):
///   x_hat = x + h f(x + (h/2) f(x, u), u).
torch::Tensor rk2_step(const DynamicsModel& model, const torch::Tensor& x,
                       const torch::Tensor& u, double h);

/// DG in training, inverse-explicit (SPEC.md §4): with the data step
/// dx = x_next - x, x_hat = x + h f_bar(x, dx, u).
torch::Tensor dg_training_step(const DynamicsModel& model, const torch::Tensor& x,
                               const torch::Tensor& x_next, const torch::Tensor& u, double h,
                               double min_dx_norm);

/// Options of the implicit DG inference step.
struct DgInferenceOptions {
  /// Newton stops when max |delta dx| <= tolerance for every row.
  double tolerance = 1e-12;
  int max_iterations = 20;
  double min_dx_norm = 6e-6;
  /// Forward-difference step of the 2 x 2 Newton Jacobian.
  double fd_step = 1e-7;
};

struct DgInferenceStep {
  torch::Tensor x_next;     // [E, B, 2]
  torch::Tensor converged;  // [E, B] bool
  int iterations = 0;
};

/// DG at inference: solves r(dx) = dx - h f_bar(x, dx, u) = 0 by Newton from
/// the RK2 step, with the 2 x 2 Jacobian I - h d f_bar / d dx by forward
/// differences (both columns and the residual in one batched model call).
/// Rows that do not converge within max_iterations are reported, not thrown.
DgInferenceStep dg_inference_step(const DynamicsModel& model, const torch::Tensor& x,
                                  const torch::Tensor& u, double h,
                                  const DgInferenceOptions& options = {});

}  // namespace phnn
