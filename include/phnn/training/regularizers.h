// include/phnn/training/regularizers.h — Jacobian regularizers (docs/METHOD.md §4).
#pragma once

#include <torch/torch.h>

#include "phnn/training/trainer_options.h"

namespace phnn {

/// Closed-form spectral quantities of 2 x 2 Jacobians J [E, B, 2, 2],
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
JacobianStats jacobian_stats(const torch::Tensor& jacobian, double eps);

/// Per-member penalty [E]: CN lambda_CN mean(kappa^2), SN lambda_SN
/// mean(sigma_max), SR lambda_SR mean((rho - 1)^2); zeros for kNone.
torch::Tensor regularizer_penalty(Regularizer reg, const JacobianStats& stats,
                                  const TrainerOptions& options);

}  // namespace phnn
