// include/phnn/models/stacked_mlp.h — E independent tanh MLPs evaluated as one
// stack, with forward-mode derivatives (jets) w.r.t. a few input directions.
#pragma once

#include <cstdint>
#include <vector>

#include <torch/torch.h>

namespace phnn {

/// A batch of vector values with their first and (optionally) second
/// derivatives w.r.t. d input directions ("jet", truncated Taylor series):
///   v [E, B, n],  g [E, B, d, n] = dv/dx_i,  h [E, B, d, d, n] = d2v/dx_i dx_j.
/// Undefined g / h mean "not propagated" (order 0 / 1). Forward-mode
/// propagation needs only a first-order backward to train through gradH and
/// df/dx (issue 3: half the ops of a create_graph double backward).
struct Jet {
  torch::Tensor v, g, h;

  int order() const { return h.defined() ? 2 : g.defined() ? 1 : 0; }
  /// Jet of the input coordinates: x [E, B, n]; directions are the first d
  /// coordinates (d <= n), g = [I_d | 0], h = 0 (omitted when order < 2).
  static Jet input(const torch::Tensor& x, int directions, int order);
  /// Jet of a value that does not depend on the directions.
  static Jet constant(const torch::Tensor& v, int directions, int order);
  /// Concatenation along the value dimension.
  static Jet cat(const std::vector<Jet>& parts);
};

/// Elementwise and arithmetic jet operations (chain and product rules). The
/// broadcasting products (jet_mul, the chain rule of tanh and softplus, the
/// order-2 outer products) sum their adjoints in one fixed order
/// (ordered_broadcast_mul), so their gradients do not depend on the CPU.
Jet jet_add(const Jet& a, const Jet& b);
Jet jet_sub(const Jet& a, const Jet& b);
Jet jet_mul(const Jet& a, const Jet& b);
Jet jet_scale(const Jet& a, double s);
Jet jet_tanh(const Jet& a);
Jet jet_softplus(const Jet& a);

/// Options of a stack of MLPs with identical shapes.
struct StackedMlpOptions {
  int input = 2;
  std::vector<int> hidden = {16, 16};
  int output = 3;
  /// Evaluate through the fused autograd node (src/models/fused_mlp.h): one
  /// node per call with a hand-written backward. false: the reference path,
  /// one LibTorch op per matmul / tanh / jet product (for tests and
  /// benchmarks; same values to round-off).
  bool fused = true;
  /// Type of the weights (ModelOptions::dtype): kFloat32 needs fused = false.
  torch::ScalarType dtype = torch::kFloat64;
};

/// E tanh MLPs as weights [E, in, out] and biases [E, 1, out]:
///   a_{k+1} = tanh(a_k W_k + b_k),  output = a_L W_L + b_L (linear last layer).
/// Member e is initialized from its own seed with PyTorch's Linear default,
/// W, b ~ U(-1/sqrt(fan_in), 1/sqrt(fan_in)), so a member's weights do not
/// depend on which other members share the stack; drawn in float64, then
/// rounded to options.dtype.
class StackedMlp {
 public:
  StackedMlp(StackedMlpOptions options, const std::vector<std::uint64_t>& seeds,
             std::uint64_t stream);

  /// Plain forward: x [E, B, in] -> [E, B, out].
  torch::Tensor forward(const torch::Tensor& x) const;
  /// Forward with derivatives: the input jet's directions are propagated.
  Jet forward(const Jet& x) const;
  /// Same as forward(Jet::input(x, directions, order)) but the first layer
  /// uses that the input jet is [I | 0] with zero Hessian: its tangent is the
  /// first `directions` rows of W_0 (no matmul) and its Hessian comes from
  /// the tanh curvature alone. Bitwise equal, fewer ops.
  Jet forward_input(const torch::Tensor& x, int directions, int order) const;

  std::vector<torch::Tensor> parameters() const;
  /// Rebinds weights and biases to leaves aliasing `values` from *offset (the
  /// caller copied them there), with gradients aliasing `gradients`;
  /// advances *offset. From then on the fused backward adds the parameter
  /// gradients into `gradients` directly (no AccumulateGrad nodes), so
  /// backward() fills them but autograd::grad w.r.t. the parameters does not.
  void bind_to(const torch::Tensor& values, const torch::Tensor& gradients, int64_t* offset);
  int64_t members() const { return members_; }
  /// Trainable parameters of one member.
  long parameter_count() const;
  const StackedMlpOptions& options() const { return options_; }
  /// For hand-written steps (fused networks after bind_to): W_l [E, n_l,
  /// n_{l+1}], b_l [E, 1, n_{l+1}], and the buffers their gradients are
  /// added into (weights', then biases'; empty before bind_to).
  const std::vector<torch::Tensor>& weights() const { return weights_; }
  const std::vector<torch::Tensor>& biases() const { return biases_; }
  const std::vector<torch::Tensor>& gradient_sinks() const { return gradient_sinks_; }

 private:
  Jet reference_forward(const Jet& x) const;
  Jet reference_forward_input(const torch::Tensor& x, int directions, int order) const;
  torch::Tensor reference_forward(const torch::Tensor& x) const;

  StackedMlpOptions options_;
  int64_t members_;
  std::vector<torch::Tensor> weights_, biases_;
  // Set by bind_to: the weights' then the biases' gradient buffers, which
  // the fused backward writes into directly (fused_mlp's gradient_sinks).
  std::vector<torch::Tensor> gradient_sinks_;
};

}  // namespace phnn
