// src/training/regularizers.cpp
#include "phnn/training/regularizers.h"

#include <limits>

#include "models/ordered_sum.h"
#include "training/jacobian_spectrum.h"

namespace phnn {
namespace {
// sqrt with a finite derivative at 0 (the clamped branch has zero slope).
// The floor is a positive normal number of the dtype: 1e-300 would round to 0
// in float32 (float32 training), where sqrt has an infinite slope.
torch::Tensor safe_sqrt(const torch::Tensor& s) {
  const double floor =
      s.scalar_type() == torch::kFloat32 ? std::numeric_limits<float>::min() : 1e-300;
  return torch::sqrt(s.clamp_min(floor));
}
}  // namespace

JacobianStats jacobian_stats_general(const torch::Tensor& jacobian, double eps) {
  const int64_t n = jacobian.size(-1);
  const auto sigma = internal::singular_values(jacobian);  // descending
  JacobianStats out;
  out.sigma_max = sigma.select(-1, 0);
  out.sigma_min = sigma.select(-1, n - 1);
  out.kappa = out.sigma_max / (out.sigma_min + eps);
  const auto re = internal::eigenvalue_real_parts(jacobian).abs();
  out.rho = std::get<0>(re.max(-1)) / (std::get<0>(re.min(-1)) + eps);
  return out;
}

JacobianStats jacobian_stats(const torch::Tensor& jacobian, double eps) {
  if (jacobian.size(-1) != 2) return jacobian_stats_general(jacobian, eps);
  const auto a = jacobian.select(-2, 0).select(-1, 0);
  const auto b = jacobian.select(-2, 0).select(-1, 1);
  const auto c = jacobian.select(-2, 1).select(-1, 0);
  const auto d = jacobian.select(-2, 1).select(-1, 1);
  const auto s1 = safe_sqrt((a + d) * (a + d) + (c - b) * (c - b));
  const auto s2 = safe_sqrt((a - d) * (a - d) + (c + b) * (c + b));
  JacobianStats out;
  out.sigma_max = 0.5 * (s1 + s2);
  out.sigma_min = 0.5 * (s1 - s2).abs();
  out.kappa = out.sigma_max / (out.sigma_min + eps);
  const auto half_trace = 0.5 * (a + d);
  const auto disc = half_trace * half_trace - (a * d - b * c);
  const auto root = torch::where(disc > 0, safe_sqrt(disc), torch::zeros_like(disc));
  const auto re1 = (half_trace + root).abs(), re2 = (half_trace - root).abs();
  out.rho = torch::maximum(re1, re2) / (torch::minimum(re1, re2) + eps);
  return out;
}

torch::Tensor regularizer_penalty(Regularizer reg, const JacobianStats& stats,
                                  const TrainerOptions& options) {
  switch (reg) {
    case Regularizer::kCn: return options.lambda_cn * internal::ordered_mean(stats.kappa * stats.kappa, 1);
    case Regularizer::kSn: return options.lambda_sn * internal::ordered_mean(stats.sigma_max, 1);
    case Regularizer::kSr: {
      const auto r = stats.rho - 1.0;
      return options.lambda_sr * internal::ordered_mean(r * r, 1);
    }
    case Regularizer::kNone: break;
  }
  return torch::zeros({stats.kappa.size(0)}, stats.kappa.options());
}

JacobianPenalty jacobian_penalty(Regularizer reg, const TrainerOptions& options) {
  if (reg == Regularizer::kNone) return {};
  return [reg, options](const torch::Tensor& dfdx, torch::Tensor* dfdx_bar) {
    torch::AutoGradMode enable(true);
    const auto leaf = dfdx.detach().requires_grad_(true);
    const auto penalty =
        regularizer_penalty(reg, jacobian_stats(leaf, options.jacobian_eps), options);
    *dfdx_bar = torch::autograd::grad({penalty.sum()}, {leaf})[0];
    return penalty.detach();
  };
}

}  // namespace phnn
