// tests/models/manual_step_reference.h — what the hand-written training steps
// are compared with (manual_step_test.cpp, general_manual_step_test.cpp): the
// trainer's loss taken by autograd, and a bitwise comparison of tensors.
#pragma once

#include <cstring>

#include <torch/torch.h>

#include "phnn/models/dynamics_model.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/regularizers.h"

namespace phnn {
namespace testing_util {

inline bool same_bits(const torch::Tensor& a, const torch::Tensor& b) {
  const auto ca = a.contiguous(), cb = b.contiguous();
  return ca.sizes() == cb.sizes() && std::memcmp(ca.data_ptr<double>(), cb.data_ptr<double>(),
                                                 sizeof(double) * ca.numel()) == 0;
}

/// The trainer's loss without a hand-written step (CellTrainer::loss_and_gradients):
/// the DG or explicit step's mean-L1 loss, + the penalty of df/dx at x (the
/// explicit step's first stage reused) when `regularizer` is set.
inline torch::Tensor autograd_loss_of(const DynamicsModel& model, IntegratorKind integrator,
                                      Regularizer regularizer, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, double min_dx_norm,
                                      const TrainerOptions& options) {
  const bool regularized = regularizer != Regularizer::kNone;
  const FieldEval at_x = regularized ? model.field(x, u, true) : FieldEval{};
  const auto x_hat = integrator == IntegratorKind::kDg
                         ? dg_training_step(model, x, x_next, u, h, min_dx_norm)
                         : explicit_step(model, integrator, x, u, h, at_x.f);
  const auto loss = discrete_loss(x_next, x_hat, h, LossNorm::kMeanL1);
  if (!regularized) return loss;
  return loss + regularizer_penalty(regularizer, jacobian_stats(at_x.dfdx, options.jacobian_eps),
                                    options);
}

}  // namespace testing_util
}  // namespace phnn
