// tests/models/fused_mlp_gradient_test.cpp — the reverse-mode input gradient
// of a fused tanh MLP (models/fused_mlp_gradient.h) against two independent
// computations: the forward-mode jet of fused_mlp (s = sum_k c_k dv_k/dx) and
// LibTorch autograd through one op per bmm / tanh (s by autograd::grad with
// create_graph, then the gradients of s . s~ + v . v~ w.r.t. the weights,
// biases, input and cotangent). Tolerance 1e-12 of the largest entry: the
// three differ only in summation order (double's 1.1e-16 times the few
// hundred terms of a sum here).
#include "models/fused_mlp_gradient.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <string>
#include <vector>

namespace phnn {
namespace {

using torch::Tensor;

void expect_close(const Tensor& a, const Tensor& b, const std::string& what) {
  ASSERT_TRUE(a.defined() && b.defined()) << what;
  ASSERT_EQ(a.sizes(), b.sizes()) << what;
  const double scale = std::max(1.0, b.abs().max().item<double>());
  EXPECT_LE((a - b).abs().max().item<double>(), 1e-12 * scale) << what;
}

struct Net {
  std::vector<Tensor> weights, biases;
};

// E members of a tanh MLP with the given widths, random entries of order 1.
Net random_net(int64_t E, const std::vector<int64_t>& widths) {
  Net net;
  for (std::size_t l = 0; l + 1 < widths.size(); ++l) {
    const double scale = 1.5 / std::sqrt(static_cast<double>(widths[l]));
    net.weights.push_back(scale * torch::randn({E, widths[l], widths[l + 1]}, torch::kFloat64));
    net.biases.push_back(0.3 * torch::randn({E, 1, widths[l + 1]}, torch::kFloat64));
  }
  return net;
}

// The op-by-op network: one bmm and one tanh per layer.
Tensor reference_forward(const Net& net, const Tensor& x) {
  Tensor a = x;
  for (std::size_t l = 0; l < net.weights.size(); ++l) {
    a = torch::baddbmm(net.biases[l], a, net.weights[l]);
    if (l + 1 < net.weights.size()) a = torch::tanh(a);
  }
  return a;
}

TEST(FusedMlpGradientTest, ProductAndItsBackwardMatchAutogradAndTheJet) {
  for (const auto& widths : std::vector<std::vector<int64_t>>{{2, 16, 16, 3}, {6, 9, 5, 7, 21}}) {
    torch::manual_seed(static_cast<int64_t>(widths.size()));
    const int64_t E = 3, B = 11, n = widths.front(), K = widths.back();
    const Net net = random_net(E, widths);
    const Tensor x = torch::randn({E, B, n}, torch::kFloat64);
    const Tensor c = torch::randn({E, B, K}, torch::kFloat64);
    const Tensor s_bar = torch::randn({E, B, n}, torch::kFloat64);
    const Tensor v_bar = torch::randn({E, B, K}, torch::kFloat64);
    const std::string tag = "widths " + std::to_string(widths.size()) + ": ";

    std::shared_ptr<internal::FusedMlpTape> tape;
    const Tensor v = internal::fused_mlp_taped(net.weights, net.biases, x, {0, 0}, &tape).v;
    std::shared_ptr<internal::FusedMlpVjpTape> vjp;
    const Tensor s = internal::fused_mlp_taped_vjp(*tape, net.weights, c, &vjp);
    std::vector<Tensor> sinks;
    for (const auto* group : {&net.weights, &net.biases})
      for (const Tensor& p : *group) sinks.push_back(torch::zeros_like(p));
    const Tensor c_bar =
        internal::fused_mlp_taped_vjp_backward(*vjp, *tape, net.weights, sinks, s_bar);
    const Tensor x_bar =
        internal::fused_mlp_vjp_value_backward(*vjp, *tape, net.weights, sinks, v_bar, true);

    // The forward-mode jet of the same network: s_i = sum_k c_k dv_k/dx_i.
    std::shared_ptr<internal::FusedMlpTape> jet_tape;
    const auto jet =
        internal::fused_mlp_taped(net.weights, net.biases, x, {static_cast<int>(n), 1}, &jet_tape);
    expect_close(s, (jet.g * c.unsqueeze(2)).sum(-1), tag + "s against the jet");

    // Autograd through the op-by-op network.
    Net ref;
    for (const Tensor& w : net.weights) ref.weights.push_back(w.clone().requires_grad_(true));
    for (const Tensor& b : net.biases) ref.biases.push_back(b.clone().requires_grad_(true));
    const Tensor xr = x.clone().requires_grad_(true), cr = c.clone().requires_grad_(true);
    const Tensor vr = reference_forward(ref, xr);
    const Tensor sr = torch::autograd::grad({vr}, {xr}, {cr}, /*retain_graph=*/true,
                                            /*create_graph=*/true)[0];
    expect_close(v, vr.detach(), tag + "v");
    expect_close(s, sr.detach(), tag + "s against autograd");
    std::vector<Tensor> wrt = ref.weights;
    wrt.insert(wrt.end(), ref.biases.begin(), ref.biases.end());
    wrt.push_back(xr);
    wrt.push_back(cr);
    const auto grads = torch::autograd::grad({(sr * s_bar).sum() + (vr * v_bar).sum()}, wrt);
    for (std::size_t k = 0; k < sinks.size(); ++k)
      expect_close(sinks[k], grads[k], tag + "parameter " + std::to_string(k));
    expect_close(x_bar, grads[sinks.size()], tag + "x~");
    expect_close(c_bar, grads[sinks.size() + 1], tag + "c~");
  }
}

}  // namespace
}  // namespace phnn
