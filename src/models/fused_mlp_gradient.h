// src/models/fused_mlp_gradient.h — reverse mode through a taped fused tanh
// MLP (fused_mlp.h): the input gradient J(x)^T c of its outputs against a
// cotangent c, and that product's own backward, for the hand-written
// training steps (manual_step.cpp) where gradH is a vector-Jacobian product
// of L_H. Two passes through the network whatever the number of states,
// where the forward-mode jet takes n_x + 1 channels. Private to src/models.
#pragma once

#include <memory>
#include <vector>

#include <torch/torch.h>

#include "models/fused_mlp.h"

namespace phnn {
namespace internal {

/// What the product's backward reads: the cotangent, the adjoints S_l of
/// the activations and U_l of the pre-activations of the reverse pass, and
/// after the backward the activation adjoints it leaves for the value pass.
struct FusedMlpVjpTape;

/// s = (d v / d x)^T c [E, B, n_0] for the order-0 taped call `tape`
/// (v = the network's output at x), c [E, B, n_L]; what the backward reads
/// goes into *vjp, which belongs to `tape` (the backwards check it). c is
/// kept, not copied: leave it unchanged until the product's backward.
torch::Tensor fused_mlp_taped_vjp(const FusedMlpTape& tape, const std::vector<torch::Tensor>& weights,
                                  const torch::Tensor& c, std::shared_ptr<FusedMlpVjpTape>* vjp);

/// The backward of s from s~ [E, B, n_0]: the weights' part of the gradient
/// is added into `gradient_sinks` (weights then biases, as fused_mlp's);
/// returns c~. The adjoints it leaves on the value pass's activations are
/// kept in `vjp`, for fused_mlp_vjp_value_backward.
torch::Tensor fused_mlp_taped_vjp_backward(FusedMlpVjpTape& vjp, const FusedMlpTape& tape,
                                           const std::vector<torch::Tensor>& weights,
                                           const std::vector<torch::Tensor>& gradient_sinks,
                                           const torch::Tensor& s_bar);

/// The value pass's backward from v~ with the activation adjoints of the
/// product's backward (call that first): parameter gradients into the
/// sinks; returns x~ if `input_adjoint`.
torch::Tensor fused_mlp_vjp_value_backward(const FusedMlpVjpTape& vjp, const FusedMlpTape& tape,
                                           const std::vector<torch::Tensor>& weights,
                                           const std::vector<torch::Tensor>& gradient_sinks,
                                           const torch::Tensor& v_bar, bool input_adjoint);

}  // namespace internal
}  // namespace phnn
