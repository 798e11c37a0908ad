// include/phnn/kernels/flat_adam.h — Adam on one contiguous parameter tensor.
#pragma once

#include <torch/torch.h>

#include "phnn/config/trainer_options.h"

namespace phnn {

/// Adam (Kingma & Ba; the update of torch::optim::Adam 1.13, no weight
/// decay, no AMSGrad) on a single flat leaf tensor, as one plain loop whose
/// every operation is rounded on its own: the same bits on every CPU
/// (docs/METHOD.md "Deterministic kernels"). It agrees with
/// torch::optim::Adam to round-off (tested; LibTorch fuses some
/// multiply-adds depending on ATEN_CPU_CAPABILITY).
///   m = b1 m + (1 - b1) g;  v = b2 v + (1 - b2) g^2
///   p -= lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)
class FlatAdam {
 public:
  /// `values` and `gradients`: contiguous buffers that the parameters and
  /// their .grad() alias (DynamicsModel::flatten_parameters()).
  FlatAdam(torch::Tensor values, torch::Tensor gradients, const TrainerOptions& options);
  void zero_grad();
  void step();
  int64_t steps_taken() const { return t_; }
  /// The moment estimates (shaped like the values), for a saved training
  /// state; restore() puts them and the step count back.
  const torch::Tensor& first_moment() const { return m_; }
  const torch::Tensor& second_moment() const { return v_; }
  void restore(const torch::Tensor& m, const torch::Tensor& v, int64_t steps_taken);

 private:
  torch::Tensor p_, g_, m_, v_;
  double lr_, b1_, b2_, eps_;
  int64_t t_ = 0;
};

}  // namespace phnn
