// src/models/fused_mlp.h — a stack of E tanh MLPs and its forward-mode jets
// as one autograd node with a hand-written backward (docs/DECISIONS.md "Fused
// networks"). Private to src/models: StackedMlp is its only caller.
#pragma once

#include <memory>
#include <vector>

#include <torch/torch.h>

namespace phnn {
namespace internal {

/// What to propagate through the network.
struct FusedMlpOptions {
  /// Input directions d (<= input width): the jet is taken w.r.t. them.
  int directions = 0;
  /// 0: value only; 1: + first derivatives; 2: + second derivatives.
  int order = 0;
};

/// Outputs of fused_mlp (undefined above the requested order):
///   v [E, B, out], g [E, B, d, out] = dv/dx_i, h [E, B, d, d, out] = d2v/dx_i dx_j.
struct FusedMlpJet {
  torch::Tensor v, g, h;
};

/// The jet of a_{l+1} = tanh(a_l W_l + b_l) (l < L), output a_L W_L + b_L,
/// for weights W_l [E, n_l, n_{l+1}] and biases b_l [E, 1, n_{l+1}], from an
/// input jet (x_v [E, B, n_0], x_g [E, B, d, n_0], x_h [E, B, d, d, n_0]).
/// An undefined x_g means x_g = [I_d | 0] (the jet of the input coordinates)
/// and an undefined x_h means 0. x_h must be symmetric in (i, j).
///
/// All E members and the whole batch go through one autograd node: per
/// layer one dgemm per member on the stacked channels (value, d tangents,
/// d(d+1)/2 second derivatives), tanh once on the value channel, and the
/// jet's chain rule elementwise. Its backward is written out in
/// fused_mlp.cpp; it is first-order only (no double backward), which is all
/// training needs since derivatives w.r.t. x are carried forward as jets.
///
/// `gradient_sinks` (optional: empty, or one tensor per weight then one per
/// bias, shaped like them): the backward adds the parameter gradients into
/// these buffers directly (the trainer passes the aliases of its flat
/// gradient buffer) instead of returning them to autograd, which saves an
/// AccumulateGrad node, an allocation and an add per parameter and call.
/// The parameters are then not part of the autograd graph (autograd::grad
/// w.r.t. them is not available); gradients w.r.t. the input still are.
FusedMlpJet fused_mlp(const std::vector<torch::Tensor>& weights,
                      const std::vector<torch::Tensor>& biases, const torch::Tensor& x_v,
                      const torch::Tensor& x_g, const torch::Tensor& x_h,
                      const FusedMlpOptions& options,
                      const std::vector<torch::Tensor>& gradient_sinks = {});

/// The same forward without an autograd node, for a hand-written step
/// (models/manual_step.cpp): the outputs, and in *tape the workspace its
/// backward reads (held until the tape is dropped). The input jet is the
/// input coordinates' (x_g, x_h undefined in fused_mlp's terms), or with x_g
/// an order-1 input jet as fused_mlp's.
struct FusedMlpTape;
FusedMlpJet fused_mlp_taped(const std::vector<torch::Tensor>& weights,
                            const std::vector<torch::Tensor>& biases, const torch::Tensor& x_v,
                            const FusedMlpOptions& options, std::shared_ptr<FusedMlpTape>* tape,
                            const torch::Tensor& x_g = {});

/// The backward of a taped call, the same arithmetic as fused_mlp's node:
/// from the output adjoints `grads` (v~, g~, h~; undefined = 0) the
/// parameter gradients are added into `gradient_sinks` (one per weight, then
/// one per bias); returns x_v~ [E, B, n_0] if `input_adjoint`, else undefined.
torch::Tensor fused_mlp_taped_backward(const FusedMlpTape& tape,
                                       const std::vector<torch::Tensor>& weights,
                                       const std::vector<torch::Tensor>& gradient_sinks,
                                       const std::vector<torch::Tensor>& grads, bool input_adjoint);

/// The backward of an order-0 taped call from v~ with, per layer l > 0,
/// adjoints act_extra[l] [E, B, n_l] added to those of the hidden
/// activations a_l (act_extra[0] unused): the second pass of the
/// reverse-mode gradient (fused_mlp_gradient.h).
torch::Tensor fused_mlp_taped_backward(const FusedMlpTape& tape,
                                       const std::vector<torch::Tensor>& weights,
                                       const std::vector<torch::Tensor>& gradient_sinks,
                                       const torch::Tensor& v_bar,
                                       const std::vector<const double*>& act_extra,
                                       bool input_adjoint);

/// The same backward for a call with an input jet x_g: returns (x_v~, x_g~).
std::pair<torch::Tensor, torch::Tensor> fused_mlp_taped_jet_backward(
    const FusedMlpTape& tape, const std::vector<torch::Tensor>& weights,
    const std::vector<torch::Tensor>& gradient_sinks, const std::vector<torch::Tensor>& grads);

}  // namespace internal
}  // namespace phnn
