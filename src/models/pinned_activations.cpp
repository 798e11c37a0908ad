// src/models/pinned_activations.cpp — see pinned_activations.h. Each is an
// autograd node whose backward is written with differentiable tensor ops
// (and the pinned functions themselves), so second derivatives work.
#include "models/pinned_activations.h"

#include "models/fused_heads_common.h"
#include "kernels/vector_math.h"

namespace phnn {
namespace internal {
namespace {

using torch::autograd::AutogradContext;
using torch::autograd::tensor_list;

// f on every element; float32 elements are widened, mapped by the float64
// function and rounded back (float32 training: one rounding of a pinned
// double, the same bits on every CPU, where LibTorch's float kernels differ
// between its vectorized and scalar builds).
template <typename F>
torch::Tensor map_elements(const torch::Tensor& x, F f) {
  const torch::Tensor in = x.contiguous();
  torch::Tensor out = torch::empty_like(in);
  if (in.scalar_type() == torch::kFloat32) {
    const float* p = in.data_ptr<float>();
    float* q = out.data_ptr<float>();
    for (int64_t k = 0; k < in.numel(); ++k) q[k] = static_cast<float>(f(static_cast<double>(p[k])));
    return out;
  }
  const double* p = in.data_ptr<double>();
  double* q = out.data_ptr<double>();
  for (int64_t k = 0; k < in.numel(); ++k) q[k] = f(p[k]);
  return out;
}

// tanh_array on the elements; float32 as in map_elements (widened, rounded back).
torch::Tensor tanh_values(const torch::Tensor& x) {
  if (x.scalar_type() == torch::kFloat32) return tanh_values(x.to(torch::kFloat64)).to(torch::kFloat32);
  const torch::Tensor in = x.contiguous();
  torch::Tensor t = torch::empty_like(in);
  tanh_array(in.data_ptr<double>(), t.data_ptr<double>(), in.numel());
  return t;
}

torch::Tensor sigmoid_values(const torch::Tensor& x) {
  return map_elements(x, [](double v) { return heads::sigmoid_of(v); });
}

class SigmoidFn : public torch::autograd::Function<SigmoidFn> {
 public:
  static torch::Tensor forward(AutogradContext* ctx, const torch::Tensor& x) {
    const auto s = sigmoid_values(x);
    ctx->save_for_backward({s});
    return s;
  }
  static tensor_list backward(AutogradContext* ctx, tensor_list g) {
    const auto s = ctx->get_saved_variables()[0];
    return {g[0] * s * (1.0 - s)};
  }
};

class SoftplusFn : public torch::autograd::Function<SoftplusFn> {
 public:
  static torch::Tensor forward(AutogradContext* ctx, const torch::Tensor& x) {
    ctx->save_for_backward({x});
    return map_elements(x, [](double v) { return heads::SoftplusSigmoid(v).softplus; });
  }
  static tensor_list backward(AutogradContext* ctx, tensor_list g) {
    const auto x = ctx->get_saved_variables()[0];
    const auto slope = torch::where(x > 20.0, torch::ones_like(x), pinned_sigmoid(x));
    return {g[0] * slope};
  }
};

class TanhFn : public torch::autograd::Function<TanhFn> {
 public:
  static torch::Tensor forward(AutogradContext* ctx, const torch::Tensor& x) {
    const torch::Tensor t = tanh_values(x);
    ctx->save_for_backward({t});
    return t;
  }
  static tensor_list backward(AutogradContext* ctx, tensor_list g) {
    const auto t = ctx->get_saved_variables()[0];
    return {g[0] * (1.0 - t * t)};
  }
};

bool pinned(const torch::Tensor& x) {
  return x.scalar_type() == torch::kFloat64 || x.scalar_type() == torch::kFloat32;
}

}  // namespace

torch::Tensor pinned_tanh(const torch::Tensor& x) {
  return pinned(x) ? TanhFn::apply(x) : torch::tanh(x);
}

torch::Tensor pinned_softplus(const torch::Tensor& x) {
  return pinned(x) ? SoftplusFn::apply(x) : torch::softplus(x);
}

torch::Tensor pinned_sigmoid(const torch::Tensor& x) {
  return pinned(x) ? SigmoidFn::apply(x) : torch::sigmoid(x);
}

}  // namespace internal
}  // namespace phnn
