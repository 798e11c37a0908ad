// tests/models/fused_mlp_test.cpp — the fused networks and heads against the
// op-by-op reference path (independent: LibTorch autograd through one op per
// matmul / tanh / jet product), and the vectorized tanh against std::tanh.
#include "models/fused_mlp.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "models/fused_heads_common.h"
#include "kernels/kernel_isa.h"
#include "kernels/vector_math.h"
#include "phnn/integrators/integrator.h"
#include "phnn/models/port_hamiltonian.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/regularizers.h"

namespace phnn {
namespace {

// Relative agreement of two tensors: max |a - b| <= tol * max(1, max |b|).
// 1e-12 leaves ~4 orders of magnitude for summation-order differences
// (BLAS blocking, fused vs separate sums) over double's 1.1e-16.
void expect_close(const torch::Tensor& a, const torch::Tensor& b, double tol, const std::string& what) {
  ASSERT_TRUE(a.defined() && b.defined()) << what;
  ASSERT_EQ(a.sizes(), b.sizes()) << what;
  const double scale = std::max(1.0, b.abs().max().item<double>());
  EXPECT_LE((a - b).abs().max().item<double>(), tol * scale) << what;
}

std::vector<std::uint64_t> seeds() { return {3, 4, 5}; }

// Sum of random projections of every jet component: a scalar whose gradient
// exercises every output adjoint.
torch::Tensor project(const Jet& j, uint64_t seed) {
  torch::manual_seed(seed);
  auto loss = (j.v * torch::randn_like(j.v)).sum();
  if (j.g.defined()) loss = loss + (j.g * torch::randn_like(j.g)).sum();
  if (j.h.defined()) {
    auto w = torch::randn_like(j.h);
    w = w + w.transpose(2, 3);  // the symmetric part is what a jet defines
    loss = loss + (j.h * w).sum();
  }
  return loss;
}

// The same member weights through both paths: values, jets and the
// gradients of a projection w.r.t. the weights and the input, orders 0-2.
TEST(FusedMlpTest, JetsAndGradientsMatchReferencePath) {
  for (int order = 0; order <= 2; ++order) {
    for (bool general_input : {false, true}) {
      StackedMlpOptions opt{3, {7, 5}, 4};
      StackedMlp fused(opt, seeds(), 9);
      opt.fused = false;
      StackedMlp reference(opt, seeds(), 9);
      torch::manual_seed(11);
      const auto xv = torch::randn({3, 6, 3}, torch::kFloat64).requires_grad_(true);
      Jet in_f, in_r;
      if (general_input && order >= 1) {
        // A jet with 2 directions whose tangents and curvature are not the identity.
        const auto xg = torch::randn({3, 6, 2, 3}, torch::kFloat64).requires_grad_(true);
        auto xh = torch::randn({3, 6, 2, 2, 3}, torch::kFloat64);
        xh = (xh + xh.transpose(2, 3)).detach().requires_grad_(true);
        in_f = Jet{xv, xg, order >= 2 ? xh : torch::Tensor()};
      } else {
        in_f = Jet::input(xv, 2, order);
      }
      in_r = in_f;
      const Jet out_f = fused.forward(in_f), out_r = reference.forward(in_r);
      const std::string tag = "order " + std::to_string(order) + (general_input ? " general" : " input");
      expect_close(out_f.v, out_r.v, 1e-12, tag + " v");
      if (order >= 1) expect_close(out_f.g, out_r.g, 1e-12, tag + " g");
      if (order >= 2) expect_close(out_f.h, out_r.h, 1e-12, tag + " h");
      std::vector<torch::Tensor> wrt = fused.parameters();
      wrt.push_back(xv);
      if (general_input && order >= 1) wrt.push_back(in_f.g);
      if (general_input && order >= 2) wrt.push_back(in_f.h);
      std::vector<torch::Tensor> wrt_r = reference.parameters();
      for (std::size_t k = fused.parameters().size(); k < wrt.size(); ++k) wrt_r.push_back(wrt[k]);
      const auto g_f = torch::autograd::grad({project(out_f, 5)}, wrt);
      const auto g_r = torch::autograd::grad({project(out_r, 5)}, wrt_r);
      for (std::size_t k = 0; k < wrt.size(); ++k) {
        expect_close(g_f[k], g_r[k], 1e-12, tag + " gradient " + std::to_string(k));
      }
    }
  }
}

// Jet::input's convenience path (forward_input) equals the general one.
TEST(FusedMlpTest, InputJetShortcutEqualsGeneralJet) {
  StackedMlp net(StackedMlpOptions{2, {6, 6}, 3}, seeds(), 1);
  torch::manual_seed(2);
  const auto x = torch::randn({3, 5, 2}, torch::kFloat64);
  const Jet a = net.forward_input(x, 2, 2), b = net.forward(Jet::input(x, 2, 2));
  EXPECT_TRUE(torch::equal(a.v, b.v));
  EXPECT_TRUE(torch::equal(a.g, b.g));
  EXPECT_TRUE(torch::equal(a.h, b.h));
}

// One training step of every model x integrator x regularizer: the loss and
// every parameter gradient of the fused model equal the reference model's.
TEST(FusedMlpTest, TrainingLossAndGradientsMatchReferenceForEveryModel) {
  const double h = 0.01;
  torch::manual_seed(4);
  const auto x = 0.8 * torch::randn({3, 16, 2}, torch::kFloat64);
  const auto x_next = x + 0.01 * torch::randn({3, 16, 2}, torch::kFloat64);
  const auto u = 0.3 * torch::randn({3, 16, 1}, torch::kFloat64);
  TrainerOptions options;
  options.lambda_cn = options.lambda_sn = options.lambda_sr = 1.0;  // make the penalty count
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (const Integrator& in : all_integrators()) {
      const IntegratorKind integrator = in.kind;
      if (kind == ModelKind::kNode && in.discrete_gradient) continue;
      for (Regularizer reg : {Regularizer::kNone, Regularizer::kCn, Regularizer::kSn, Regularizer::kSr}) {
        std::vector<torch::Tensor> losses, grads[2];
        for (bool fused : {true, false}) {
          const auto model = DynamicsModel::create(
              ModelOptions{kind, ModelSize::kSmall, SystemKind::kDuffing, fused}, seeds());
          const auto x_hat = training_step(*model, integrator, x, x_next, u, h, 6e-6);
          auto loss = ((x_next - x_hat).abs() / h).mean({1, 2});
          if (reg != Regularizer::kNone) {
            loss = loss + regularizer_penalty(
                              reg, jacobian_stats(model->field(x, u, true).dfdx, 1e-6), options);
          }
          losses.push_back(loss);
          grads[fused ? 0 : 1] = torch::autograd::grad({loss.sum()}, model->parameters());
        }
        const std::string tag = model_label(kind, integrator) + " " + to_string(reg);
        expect_close(losses[0], losses[1], 1e-12, tag + " loss");
        for (std::size_t k = 0; k < grads[0].size(); ++k) {
          expect_close(grads[0][k], grads[1][k], 1e-12, tag + " parameter " + std::to_string(k));
        }
      }
    }
  }
}

// Learned H, gradH, the discrete gradient and the Jacobians through the
// fused heads equal the reference formulas, including rows below the DG
// fallback threshold.
TEST(FusedMlpTest, HamiltonianAndDiscreteGradientMatchReference) {
  const auto fused = DynamicsModel::create(
      ModelOptions{ModelKind::kPhnnJr, ModelSize::kSmall, SystemKind::kDuffing, true}, seeds());
  const auto reference = DynamicsModel::create(
      ModelOptions{ModelKind::kPhnnJr, ModelSize::kSmall, SystemKind::kDuffing, false}, seeds());
  torch::manual_seed(6);
  const auto x = 2.0 * torch::randn({3, 40, 2}, torch::kFloat64);
  auto dx = 0.05 * torch::randn({3, 40, 2}, torch::kFloat64);
  dx.narrow(1, 0, 5).mul_(1e-7);  // |dx| < tau = 6e-6: gradH(x + dx/2) alone
  expect_close(fused->hamiltonian(x), reference->hamiltonian(x), 1e-12, "H");
  expect_close(fused->grad_hamiltonian(x), reference->grad_hamiltonian(x), 1e-12, "gradH");
  const auto& f = dynamic_cast<const PortHamiltonianModel&>(*fused);
  const auto& r = dynamic_cast<const PortHamiltonianModel&>(*reference);
  expect_close(f.discrete_gradient(x, dx, 6e-6), r.discrete_gradient(x, dx, 6e-6), 1e-12, "DG");
  // df/dx through the closed-form Hessian head (the regularizers' Jacobian).
  const auto u = 0.5 * torch::randn({3, 40, 1}, torch::kFloat64);
  expect_close(fused->field(x, u, true).dfdx, reference->field(x, u, true).dfdx, 1e-12, "df/dx");
  // d f_bar / d dx divides an O(|dx|^2) difference of gradients by |dx|^2,
  // so round-off differences grow like eps |gradH| / |dx|^2: compare at
  // |dx| in [0.05, 0.1] against that bound with a factor 8 for the few
  // roundings of each path (|gradH| up to ~40 here, so ~3e-11; measured
  // differences 1e-13 to 1.6e-12 depending on the CPU's BLAS kernels), and
  // below tau, where the Hessian head is used.
  const auto angle = 6.283185307179586 * torch::rand({3, 40}, torch::kFloat64);
  auto dx_mid = (0.05 + 0.05 * torch::rand({3, 40, 1}, torch::kFloat64)) *
                torch::stack({torch::cos(angle), torch::sin(angle)}, -1);
  dx_mid.narrow(1, 0, 5).mul_(1e-7);
  const double grad_scale =
      std::max(1.0, reference->grad_hamiltonian(x).abs().max().item<double>());
  const double round_off_bound = 8.0 * 2.220446049250313e-16 * grad_scale / (0.05 * 0.05);
  const auto fused_jacobian = fused->discrete_gradient_field_with_jacobian(x, dx_mid, u, 6e-6).dfdx;
  const auto reference_jacobian =
      reference->discrete_gradient_field_with_jacobian(x, dx_mid, u, 6e-6).dfdx;
  ASSERT_EQ(fused_jacobian.sizes(), reference_jacobian.sizes());
  EXPECT_LE((fused_jacobian - reference_jacobian).abs().max().item<double>(), round_off_bound)
      << "d f_bar / d dx";
}

// Within 1.6 ulp of the exact tanh (long double: 11 more bits than the
// result) on a log grid of |x| in [1e-20, 31.6] (both signs) and random
// points around the branch switch at 0.625, where the one-division form is
// least accurate (1.59 ulp measured there over 4e7 points); the clamp at 22
// included; exact at 0, +-inf and NaN.
TEST(VectorTanhTest, WithinOnePointSixUlpOfTheExactTanh) {
  std::vector<double> x;
  for (double e = -20.0; e <= 1.5; e += 1e-4) {
    x.push_back(std::pow(10.0, e));
    x.push_back(-std::pow(10.0, e));
  }
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> near_switch(0.55, 0.8);
  for (int i = 0; i < 400000; ++i) x.push_back(near_switch(rng));
  for (double v : {0.625, std::nextafter(0.625, 0.0), 22.0, 0.0, -0.0}) x.push_back(v);
  std::vector<double> y(x.size());
  internal::tanh_array(x.data(), y.data(), static_cast<int64_t>(x.size()));
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const long double exact = tanhl(static_cast<long double>(x[i]));
    const double rounded = static_cast<double>(exact);
    const double ulp = std::nextafter(std::fabs(rounded), 2.0) - std::fabs(rounded);
    worst = std::max(worst, static_cast<double>(std::fabs(y[i] - exact) / ulp));
  }
  EXPECT_LE(worst, 1.6);
  const double special[] = {std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::quiet_NaN(), 0.0, -0.0};
  double out[5];
  internal::tanh_array(special, out, 5);
  EXPECT_EQ(out[0], 1.0);
  EXPECT_EQ(out[1], -1.0);
  EXPECT_TRUE(std::isnan(out[2]));
  EXPECT_TRUE(out[3] == 0.0 && !std::signbit(out[3]));
  EXPECT_TRUE(out[4] == 0.0 && std::signbit(out[4])) << "tanh(-0) = -0, as std::tanh";
}

// The softplus/sigmoid pieces: exp on (-750, 0] (subnormal results
// included) within 2 ulp of the C library, log1p on [0, 1] within 3 (the
// rounding of s = z / (2 + z) carries into 2 atanh s).
TEST(VectorTanhTest, ExpAndLog1pWithinTwoUlpOfStd) {
  const auto ulps = [](double got, double ref) {
    const double ulp = std::nextafter(std::fabs(ref), 2.0 * std::fabs(ref) + 1.0) - std::fabs(ref);
    return std::fabs(got - ref) / ulp;
  };
  double worst_exp = 0.0, worst_log = 0.0;
  for (double x = -750.0; x <= 0.0; x += 1.37e-3) {
    worst_exp = std::max(worst_exp, ulps(internal::exp_nonpositive(x), std::exp(x)));
  }
  for (double e = -20.0; e <= 0.0; e += 1e-4) {
    const double z = std::pow(10.0, e);
    worst_log = std::max(worst_log, ulps(internal::log1p_unit(z), std::log1p(z)));
  }
  EXPECT_LE(worst_exp, 2.0);
  EXPECT_LE(worst_log, 3.0);
  EXPECT_EQ(internal::exp_nonpositive(0.0), 1.0);
  EXPECT_EQ(internal::exp_nonpositive(-800.0), 0.0);
  EXPECT_EQ(internal::log1p_unit(0.0), 0.0);
  EXPECT_TRUE(std::isnan(internal::exp_nonpositive(std::numeric_limits<double>::quiet_NaN())));
}

// The vectorized softplus/sigmoid is the scalar SoftplusSigmoid bit for bit
// (NaN for NaN), on every instruction set this CPU has: across the exp
// reduction's range, both sides of 0 and of the softplus threshold 20, the
// exp underflow at |x| = 745.2, subnormal inputs, +-inf and NaN.
TEST(VectorTanhTest, SoftplusSigmoidArrayIsTheScalarFormBitForBit) {
  std::vector<double> x;
  for (double e = -320.0; e <= 3.0; e += 0.0137) {
    x.push_back(std::pow(10.0, e));
    x.push_back(-std::pow(10.0, e));
  }
  for (double v = -800.0; v <= 40.0; v += 0.0731) x.push_back(v);
  const double inf = std::numeric_limits<double>::infinity();
  for (double v : {0.0, -0.0, 20.0, std::nextafter(20.0, 21.0), -745.2, std::nextafter(-745.2, 0.0),
                   745.2, 4.9e-324, -4.9e-324, inf, -inf, std::numeric_limits<double>::quiet_NaN()})
    x.push_back(v);
  const auto n = static_cast<int64_t>(x.size());
  const auto same = [](double a, double b) {
    return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0;
  };
  for (const auto isa : {internal::KernelIsa::kBaseline, internal::KernelIsa::kAvx2,
                         internal::KernelIsa::kAvx512}) {
    const internal::ScopedKernelIsa scope(isa);
    std::vector<double> sp(x.size()), sg(x.size()), sl(x.size());
    internal::softplus_sigmoid_array(x.data(), n, sp.data(), sg.data(), sl.data());
    int differ = 0;
    for (int64_t i = 0; i < n; ++i) {
      const internal::heads::SoftplusSigmoid f(x[i]);
      const bool ok = same(sp[i], f.softplus) && same(sg[i], f.sigmoid) && same(sl[i], f.slope);
      if (!ok && ++differ <= 3)
        ADD_FAILURE() << internal::kernel_isa_name(internal::kernel_isa()) << " x = " << x[i]
                      << ": " << sp[i] << " " << sg[i] << " " << sl[i] << " against "
                      << f.softplus << " " << f.sigmoid << " " << f.slope;
    }
    EXPECT_EQ(differ, 0);
  }
}

}  // namespace
}  // namespace phnn
