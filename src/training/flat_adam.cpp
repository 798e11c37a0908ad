// src/training/flat_adam.cpp
#include "phnn/training/flat_adam.h"

#include <cmath>

#include "phnn/common/check.h"

namespace phnn {

FlatAdam::FlatAdam(torch::Tensor values, torch::Tensor gradients, const TrainerOptions& options)
    : p_(std::move(values)),
      g_(std::move(gradients)),
      lr_(options.learning_rate),
      b1_(options.adam_beta1),
      b2_(options.adam_beta2),
      eps_(options.adam_eps) {
  PHNN_CHECK(p_.is_contiguous() && g_.is_contiguous() && p_.sizes() == g_.sizes(),
             "FlatAdam needs contiguous value and gradient buffers of one shape");
  m_ = torch::zeros_like(p_, torch::MemoryFormat::Preserve);
  v_ = torch::zeros_like(p_, torch::MemoryFormat::Preserve);
}

void FlatAdam::restore(const torch::Tensor& m, const torch::Tensor& v, int64_t steps_taken) {
  torch::NoGradGuard no_grad;
  m_.copy_(m);
  v_.copy_(v);
  t_ = steps_taken;
}

void FlatAdam::zero_grad() { g_.zero_(); }

void FlatAdam::step() {
  torch::NoGradGuard no_grad;
  ++t_;
  const auto& g = g_;
  const double bias_correction1 = 1 - std::pow(b1_, static_cast<double>(t_));
  const double bias_correction2 = 1 - std::pow(b2_, static_cast<double>(t_));
  m_.mul_(b1_).add_(g, 1 - b1_);
  v_.mul_(b2_).addcmul_(g, g, 1 - b2_);
  const auto denom = (v_.sqrt() / std::sqrt(bias_correction2)).add_(eps_);
  p_.addcdiv_(m_, denom, -lr_ / bias_correction1);
}

}  // namespace phnn
