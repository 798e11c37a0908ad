// include/phnn/training/regularizers.h — Jacobian regularizers (docs/METHOD.md §4).
#pragma once

#include <torch/torch.h>

#include "phnn/config/trainer_options.h"
#include "phnn/models/dynamics_model.h"

namespace phnn {

/// Spectral quantities of the Jacobians J [E, B, n, n]; for n = 2 in closed form,
/// differentiable. With J = [[a, b], [c, d]]:
///   s1 = |(a + d, c - b)|, s2 = |(a - d, c + b)|,
///   sigma_max = (s1 + s2) / 2, sigma_min = |s1 - s2| / 2,
///   kappa = sigma_max / (sigma_min + eps)      (eq:condition-number-loss)
///   lambda = tr/2 +- sqrt(tr^2/4 - det): Re(lambda) = tr/2 +- sqrt(disc) if
///   disc >= 0, else tr/2 for both;
///   rho = max|Re lambda| / (min|Re lambda| + eps)  (eq:stiffness-ratio-loss)
struct JacobianStats {
  torch::Tensor sigma_max, sigma_min, kappa, rho;  // [E, B]
};
///
/// For n x n Jacobians with n != 2 (file-defined systems) the same
/// quantities come from the singular values and the real parts of the
/// eigenvalues (src/training/jacobian_spectrum.h: Eigen's Jacobi SVD and
/// real Schur form, compiled code, so the same bits on every CPU, unlike
/// LAPACK's), differentiable; jacobian_stats_general is that path for any n
/// (tests compare it with the closed form at n = 2 and with LAPACK).
JacobianStats jacobian_stats(const torch::Tensor& jacobian, double eps);
JacobianStats jacobian_stats_general(const torch::Tensor& jacobian, double eps);

/// Per-member penalty [E]: CN lambda_CN mean(kappa^2), SN lambda_SN
/// mean(sigma_max), SR lambda_SR mean((rho - 1)^2); zeros for kNone.
torch::Tensor regularizer_penalty(Regularizer reg, const JacobianStats& stats,
                                  const TrainerOptions& options);

/// The penalty of `reg` for a model's hand-written training step:
/// regularizer_penalty(jacobian_stats(df/dx)) per member and its adjoint,
/// the same bits as autograd's through the whole graph. For 2 x 2 float64
/// Jacobians in closed form, row by row (no graph); otherwise by autograd
/// on the small graph from df/dx alone (jacobian_penalty_by_autograd, also
/// the tests' reference). Empty for kNone.
JacobianPenalty jacobian_penalty(Regularizer reg, const TrainerOptions& options);
JacobianPenalty jacobian_penalty_by_autograd(Regularizer reg, const TrainerOptions& options);

}  // namespace phnn
