// tests/models/manual_step_reference.h — what the hand-written training steps
// are compared with (manual_step_test.cpp, general_manual_step_test.cpp,
// dg4_manual_step_test.cpp): the trainer's loss taken by autograd, a bitwise
// comparison of tensors, and the comparison rule of a step with autograd.
#pragma once

#include <gtest/gtest.h>

#include <cstring>

#include <torch/torch.h>

#include "phnn/models/dynamics_model.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/regularizers.h"

namespace phnn {
namespace testing_util {

/// Moves a model's flat weights away from their initialization (seeded
/// noise of 0.3), so no term of a step is special.
inline void move_off_initialization(torch::Tensor values) {
  torch::NoGradGuard no_grad;
  torch::manual_seed(11);
  values.add_(0.3 * torch::randn_like(values));
}

inline bool same_bits(const torch::Tensor& a, const torch::Tensor& b) {
  const auto ca = a.contiguous(), cb = b.contiguous();
  return ca.sizes() == cb.sizes() && std::memcmp(ca.data_ptr<double>(), cb.data_ptr<double>(),
                                                 sizeof(double) * ca.numel()) == 0;
}

/// The trainer's loss without a hand-written step (CellTrainer::loss_and_gradients):
/// the DG, DG4 or explicit step's mean-L1 loss, + the penalty of df/dx at x (the
/// explicit step's first stage reused) when `regularizer` is set.
inline torch::Tensor autograd_loss_of(const DynamicsModel& model, IntegratorKind integrator,
                                      Regularizer regularizer, const torch::Tensor& x,
                                      const torch::Tensor& x_next, const torch::Tensor& u,
                                      double h, double min_dx_norm,
                                      const TrainerOptions& options) {
  const bool regularized = regularizer != Regularizer::kNone;
  const FieldEval at_x = regularized ? model.field(x, u, true) : FieldEval{};
  const auto x_hat = training_step(model, integrator, x, x_next, u, h, min_dx_norm, at_x.f);
  const auto loss = discrete_loss(x_next, x_hat, h, LossNorm::kMeanL1);
  if (!regularized) return loss;
  return loss + regularizer_penalty(regularizer, jacobian_stats(at_x.dfdx, options.jacobian_eps),
                                    options);
}

/// A hand-written step's loss per member and parameter gradients against
/// autograd's: NODE bitwise (the same operations in the same order); the
/// PH models to 1e-12 relative (loss) and of the largest gradient (gradH in
/// reverse mode where autograd's graph carries L_H's forward jet), 1e-10
/// with a regularizer (the jet heads' round-off, amplified by the penalty's
/// condition numbers).
inline void expect_step_matches(ModelKind kind, Regularizer regularizer, const torch::Tensor& loss,
                                const torch::Tensor& autograd_loss, const torch::Tensor& grads,
                                const torch::Tensor& autograd_grads) {
  const double largest = (grads - autograd_grads).abs().max().item<double>();
  const double scale = autograd_grads.abs().max().item<double>();
  if (kind == ModelKind::kNode) {
    EXPECT_TRUE(same_bits(loss, autograd_loss)) << loss << autograd_loss;
    EXPECT_TRUE(same_bits(grads, autograd_grads))
        << "largest difference " << largest << " of " << scale;
    return;
  }
  const double tolerance = regularizer == Regularizer::kNone ? 1e-12 : 1e-10;
  EXPECT_LT(((loss - autograd_loss).abs() / autograd_loss.abs()).max().item<double>(), tolerance)
      << loss << autograd_loss;
  EXPECT_LT(largest, tolerance * scale) << "largest difference " << largest << " of " << scale;
}

}  // namespace testing_util
}  // namespace phnn
