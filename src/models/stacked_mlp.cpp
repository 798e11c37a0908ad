// src/models/stacked_mlp.cpp — E tanh MLPs as one stack, with their jets
// (phnn/models/stacked_mlp.h).
#include "phnn/models/stacked_mlp.h"

#include <cmath>

#include "models/fused_mlp.h"
#include "kernels/ordered_sum.h"
#include "models/pinned_activations.h"
#include "kernels/stacked_matmul.h"
#include "phnn/common/check.h"
#include "phnn/data/counter_rng.h"

namespace phnn {

Jet Jet::input(const torch::Tensor& x, int directions, int order) {
  Jet j;
  j.v = x;
  if (order >= 1) {
    const auto n = x.size(-1);
    auto eye = torch::zeros({directions, n}, x.options());
    for (int i = 0; i < directions; ++i) eye.index_put_({i, i}, 1.0);
    j.g = eye.expand({x.size(0), x.size(1), directions, n});
  }
  if (order >= 2) {
    j.h = torch::zeros({x.size(0), x.size(1), directions, directions, x.size(-1)}, x.options());
  }
  return j;
}

Jet Jet::constant(const torch::Tensor& v, int directions, int order) {
  Jet j;
  j.v = v;
  if (order >= 1) j.g = torch::zeros({v.size(0), v.size(1), directions, v.size(-1)}, v.options());
  if (order >= 2) {
    j.h = torch::zeros({v.size(0), v.size(1), directions, directions, v.size(-1)}, v.options());
  }
  return j;
}

Jet Jet::cat(const std::vector<Jet>& parts) {
  std::vector<torch::Tensor> vs, gs, hs;
  for (const Jet& p : parts) {
    vs.push_back(p.v);
    if (p.g.defined()) gs.push_back(p.g);
    if (p.h.defined()) hs.push_back(p.h);
  }
  Jet j;
  j.v = torch::cat(vs, -1);
  if (gs.size() == parts.size()) j.g = torch::cat(gs, -1);
  if (hs.size() == parts.size()) j.h = torch::cat(hs, -1);
  return j;
}

namespace {
// Outer product of direction gradients: [E,B,d,n] x [E,B,d,n] -> [E,B,d,d,n].
torch::Tensor direction_outer(const torch::Tensor& a, const torch::Tensor& b) {
  return internal::ordered_broadcast_mul(a.unsqueeze(-2), b.unsqueeze(-3));
}

// phi(a) given phi(v), phi'(v), phi''(v).
Jet apply(const Jet& a, const torch::Tensor& f0, const torch::Tensor& f1,
          const torch::Tensor& f2) {
  Jet out;
  out.v = f0;
  using internal::ordered_broadcast_mul;
  if (a.g.defined()) out.g = ordered_broadcast_mul(f1.unsqueeze(-2), a.g);
  if (a.h.defined()) {
    out.h = ordered_broadcast_mul(f1.unsqueeze(-2).unsqueeze(-2), a.h) +
            ordered_broadcast_mul(f2.unsqueeze(-2).unsqueeze(-2), direction_outer(a.g, a.g));
  }
  return out;
}
}  // namespace

Jet jet_add(const Jet& a, const Jet& b) {
  Jet out;
  out.v = a.v + b.v;
  if (a.g.defined() && b.g.defined()) out.g = a.g + b.g;
  if (a.h.defined() && b.h.defined()) out.h = a.h + b.h;
  return out;
}

Jet jet_sub(const Jet& a, const Jet& b) {
  Jet out;
  out.v = a.v - b.v;
  if (a.g.defined() && b.g.defined()) out.g = a.g - b.g;
  if (a.h.defined() && b.h.defined()) out.h = a.h - b.h;
  return out;
}

Jet jet_mul(const Jet& a, const Jet& b) {
  Jet out;
  using internal::ordered_broadcast_mul;
  out.v = ordered_broadcast_mul(a.v, b.v);
  if (a.g.defined() && b.g.defined()) {
    out.g = ordered_broadcast_mul(a.g, b.v.unsqueeze(-2)) + ordered_broadcast_mul(b.g, a.v.unsqueeze(-2));
  }
  if (a.h.defined() && b.h.defined()) {
    out.h = ordered_broadcast_mul(a.h, b.v.unsqueeze(-2).unsqueeze(-2)) +
            ordered_broadcast_mul(b.h, a.v.unsqueeze(-2).unsqueeze(-2)) +
            direction_outer(a.g, b.g) + direction_outer(b.g, a.g);
  }
  return out;
}

Jet jet_scale(const Jet& a, double s) {
  Jet out;
  out.v = a.v * s;
  if (a.g.defined()) out.g = a.g * s;
  if (a.h.defined()) out.h = a.h * s;
  return out;
}

Jet jet_tanh(const Jet& a) {
  const auto t = internal::pinned_tanh(a.v);
  if (!a.g.defined()) return Jet{t, {}, {}};
  const auto d1 = 1.0 - t * t;
  const auto d2 = a.h.defined() ? -2.0 * t * d1 : torch::Tensor();
  return apply(a, t, d1, d2);
}

Jet jet_softplus(const Jet& a) {
  const auto sp = internal::pinned_softplus(a.v);
  if (!a.g.defined()) return Jet{sp, {}, {}};
  const auto s = internal::pinned_sigmoid(a.v);
  const auto d2 = a.h.defined() ? s * (1.0 - s) : torch::Tensor();
  return apply(a, sp, s, d2);
}

StackedMlp::StackedMlp(StackedMlpOptions options, const std::vector<std::uint64_t>& seeds,
                       std::uint64_t stream)
    : options_(std::move(options)), members_(static_cast<int64_t>(seeds.size())) {
  PHNN_REQUIRE(!seeds.empty(), "StackedMlp: at least one member seed is needed");
  std::vector<int> sizes{options_.input};
  sizes.insert(sizes.end(), options_.hidden.begin(), options_.hidden.end());
  sizes.push_back(options_.output);
  const auto f64 = torch::TensorOptions().dtype(torch::kFloat64);
  for (std::size_t l = 0; l + 1 < sizes.size(); ++l) {
    const int fan_in = sizes[l], fan_out = sizes[l + 1];
    weights_.push_back(torch::empty({members_, fan_in, fan_out}, f64));
    biases_.push_back(torch::empty({members_, 1, fan_out}, f64));
  }
  // Member e: its own counter-based stream keyed by (seed, network stream),
  // filled in a fixed order (layer by layer, W row-major then b).
  for (int64_t e = 0; e < members_; ++e) {
    CounterRng rng(mix64(mix64(seeds[static_cast<std::size_t>(e)] ^ 0x6d6c70ULL) ^ stream));
    for (std::size_t l = 0; l < weights_.size(); ++l) {
      const double bound = 1.0 / std::sqrt(static_cast<double>(sizes[l]));
      auto w = weights_[l].accessor<double, 3>();
      for (int64_t i = 0; i < w.size(1); ++i)
        for (int64_t j = 0; j < w.size(2); ++j) w[e][i][j] = rng.uniform(-bound, bound);
      auto b = biases_[l].accessor<double, 3>();
      for (int64_t j = 0; j < b.size(2); ++j) b[e][0][j] = rng.uniform(-bound, bound);
    }
  }
  // float32: the float64 draws rounded (a no-op for float64).
  PHNN_REQUIRE(options_.dtype == torch::kFloat64 ||
                   (options_.dtype == torch::kFloat32 && !options_.fused),
               "StackedMlp: the fused networks are float64 only; float32 needs fused = false");
  for (auto* params : {&weights_, &biases_}) {
    for (auto& p : *params) {
      p = p.to(options_.dtype);
      p.set_requires_grad(true);
    }
  }
}

torch::Tensor StackedMlp::forward(const torch::Tensor& x) const {
  if (!options_.fused) return reference_forward(x);
  return internal::fused_mlp(weights_, biases_, x, {}, {}, internal::FusedMlpOptions{},
                             gradient_sinks_).v;
}

Jet StackedMlp::forward(const Jet& x) const {
  if (!options_.fused) return reference_forward(x);
  const int order = x.order();
  const int directions = order >= 1 ? static_cast<int>(x.g.size(-2)) : 0;
  const auto out = internal::fused_mlp(weights_, biases_, x.v, x.g, x.h,
                                       internal::FusedMlpOptions{directions, order}, gradient_sinks_);
  return Jet{out.v, out.g, out.h};
}

Jet StackedMlp::forward_input(const torch::Tensor& x, int directions, int order) const {
  if (!options_.fused) return reference_forward_input(x, directions, order);
  const auto out = internal::fused_mlp(weights_, biases_, x, {}, {},
                                       internal::FusedMlpOptions{order >= 1 ? directions : 0, order},
                                       gradient_sinks_);
  return Jet{out.v, out.g, out.h};
}

namespace {
// x W + b; the bias's adjoint is summed over the batch in order
// (ordered_expand), not by autograd's broadcast sum, whose order LibTorch
// sets by the CPU's vector width.
torch::Tensor affine(const torch::Tensor& x, const torch::Tensor& w, const torch::Tensor& b) {
  const auto xw = internal::stacked_matmul(x, w);
  return xw + internal::ordered_expand(b, xw.sizes().vec());
}
}  // namespace

torch::Tensor StackedMlp::reference_forward(const torch::Tensor& x) const {
  torch::Tensor a = x;
  const std::size_t last = weights_.size() - 1;
  for (std::size_t l = 0; l < weights_.size(); ++l) {
    a = affine(a, weights_[l], biases_[l]);
    if (l < last) a = internal::pinned_tanh(a);
  }
  return a;
}

namespace {
// [E, B, ..., n] @ W[E, n, m] for the derivative tensors: flatten the middle.
torch::Tensor batched_linear(const torch::Tensor& t, const torch::Tensor& w) {
  const auto sizes = t.sizes();
  auto flat = t.reshape({sizes[0], -1, sizes.back()});
  auto out = internal::stacked_matmul(flat, w);
  std::vector<int64_t> shape(sizes.begin(), sizes.end());
  shape.back() = w.size(2);
  return out.reshape(shape);
}
}  // namespace

Jet StackedMlp::reference_forward(const Jet& x) const {
  Jet a = x;
  const std::size_t last = weights_.size() - 1;
  for (std::size_t l = 0; l < weights_.size(); ++l) {
    Jet z;
    z.v = affine(a.v, weights_[l], biases_[l]);
    if (a.g.defined()) z.g = batched_linear(a.g, weights_[l]);
    if (a.h.defined()) z.h = batched_linear(a.h, weights_[l]);
    a = l < last ? jet_tanh(z) : z;
  }
  return a;
}

Jet StackedMlp::reference_forward_input(const torch::Tensor& x, int directions,
                                        int order) const {
  if (order == 0) return Jet{reference_forward(x), {}, {}};
  const int64_t E = x.size(0), B = x.size(1);
  // Layer 0: z = x W + b, dz/dx_i = W[i, :], d2z = 0.
  Jet z;
  z.v = affine(x, weights_[0], biases_[0]);
  z.g = internal::ordered_expand(weights_[0].narrow(1, 0, directions).unsqueeze(1),
                                 {E, B, directions, weights_[0].size(2)});
  Jet a;
  if (weights_.size() == 1) return z;
  const auto t = internal::pinned_tanh(z.v);
  const auto d1 = 1.0 - t * t;
  a.v = t;
  a.g = internal::ordered_broadcast_mul(d1.unsqueeze(-2), z.g);
  if (order >= 2) {
    a.h = internal::ordered_broadcast_mul((-2.0 * t * d1).unsqueeze(-2).unsqueeze(-2),
                                          direction_outer(z.g, z.g));
  }
  const std::size_t last = weights_.size() - 1;
  for (std::size_t l = 1; l < weights_.size(); ++l) {
    Jet y;
    y.v = affine(a.v, weights_[l], biases_[l]);
    y.g = batched_linear(a.g, weights_[l]);
    if (a.h.defined()) y.h = batched_linear(a.h, weights_[l]);
    a = l < last ? jet_tanh(y) : y;
  }
  return a;
}

void StackedMlp::bind_to(const torch::Tensor& values, const torch::Tensor& gradients,
                         int64_t* offset) {
  std::vector<torch::Tensor> weight_sinks, bias_sinks;
  for (std::size_t l = 0; l < weights_.size(); ++l) {
    for (torch::Tensor* p : {&weights_[l], &biases_[l]}) {
      const int64_t n = p->numel();
      const auto shape = p->sizes().vec();
      *p = values.narrow(0, *offset, n).view(shape).detach().requires_grad_(true);
      p->mutable_grad() = gradients.narrow(0, *offset, n).view(shape);
      (p == &weights_[l] ? weight_sinks : bias_sinks).push_back(p->mutable_grad());
      *offset += n;
    }
  }
  if (!options_.fused) return;  // the reference path accumulates through autograd
  gradient_sinks_ = weight_sinks;
  gradient_sinks_.insert(gradient_sinks_.end(), bias_sinks.begin(), bias_sinks.end());
}

std::vector<torch::Tensor> StackedMlp::parameters() const {
  std::vector<torch::Tensor> out;
  for (std::size_t l = 0; l < weights_.size(); ++l) {
    out.push_back(weights_[l]);
    out.push_back(biases_[l]);
  }
  return out;
}

long StackedMlp::parameter_count() const {
  long n = 0;
  for (std::size_t l = 0; l < weights_.size(); ++l) {
    n += weights_[l].size(1) * weights_[l].size(2) + biases_[l].size(2);
  }
  return n;
}

}  // namespace phnn
