// tests/models/jr_rk2_step_test.cpp — the hand-written PHNN-JR RK2 step
// (models/jr_rk2_step.cpp) against autograd on the same model: the loss and
// every parameter gradient bitwise equal (it claims the same operations in
// the same order), for each built-in structure, two sizes, data expanded
// over the members (the full-batch view) and gathered per member.
#include <cstring>
#include <vector>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/models/port_hamiltonian.h"
#include "phnn/training/discrete_step.h"

namespace phnn {
namespace {

bool same_bits(const torch::Tensor& a, const torch::Tensor& b) {
  const auto ca = a.contiguous(), cb = b.contiguous();
  return ca.sizes() == cb.sizes() &&
         std::memcmp(ca.data_ptr<double>(), cb.data_ptr<double>(), sizeof(double) * ca.numel()) == 0;
}

struct Case {
  SystemKind structure;
  ModelSize size;
  bool expanded;  // x, x_next, u one [1, B, .] array viewed by every member
};

class JrRk2StepTest : public ::testing::TestWithParam<Case> {};

TEST_P(JrRk2StepTest, LossAndGradientsAreAutogradsToTheBit) {
  const Case c = GetParam();
  const std::vector<std::uint64_t> seeds = {3, 4, 5, 6};
  const int64_t E = 4, B = 37;
  auto model = DynamicsModel::create(ModelOptions{ModelKind::kPhnnJr, c.size, c.structure}, seeds);
  auto flat = model->flatten_parameters();
  {  // weights away from their initialization, so no term is special
    torch::NoGradGuard no_grad;
    torch::manual_seed(11);
    flat.values.add_(0.3 * torch::randn_like(flat.values));
  }
  torch::manual_seed(12);
  const int64_t rows = c.expanded ? 1 : E;
  auto x = 1.5 * torch::randn({rows, B, 2}, torch::kFloat64);
  auto x_next = x + 0.05 * torch::randn({rows, B, 2}, torch::kFloat64);
  auto u = torch::randn({rows, B, 1}, torch::kFloat64);
  if (c.expanded) {
    x = x.expand({E, B, 2}), x_next = x_next.expand({E, B, 2}), u = u.expand({E, B, 1});
  }
  const double h = 0.05;

  flat.gradients.zero_();
  const auto loss = discrete_loss(x_next, rk2_step(*model, x, u, h), h, LossNorm::kMeanL1);
  loss.sum().backward();
  const auto autograd_loss = loss.detach().clone(), autograd_grad = flat.gradients.clone();
  ASSERT_GT(autograd_grad.abs().sum().item<double>(), 0.0);

  flat.gradients.zero_();
  const auto manual = model->rk2_mean_l1_step(x, x_next, u, h);
  ASSERT_TRUE(manual.defined());
  EXPECT_TRUE(same_bits(manual, autograd_loss)) << manual << autograd_loss;
  EXPECT_TRUE(same_bits(flat.gradients, autograd_grad))
      << "largest difference " << (flat.gradients - autograd_grad).abs().max().item<double>()
      << " of " << autograd_grad.abs().max().item<double>();
}

INSTANTIATE_TEST_SUITE_P(
    Structures, JrRk2StepTest,
    ::testing::Values(Case{SystemKind::kHarmonic, ModelSize::kSmall, true},
                      Case{SystemKind::kDuffing, ModelSize::kSmall, false},
                      Case{SystemKind::kSelfSustained, ModelSize::kSmall, true},
                      Case{SystemKind::kSelfSustained, ModelSize::kMedium, false}));

// The models without a hand-written step say so (the trainer then runs autograd).
TEST(JrRk2StepTest, OtherModelsHaveNone) {
  const auto x = torch::zeros({2, 3, 2}, torch::kFloat64), u = torch::zeros({2, 3, 1}, torch::kFloat64);
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS}) {
    auto model = DynamicsModel::create(ModelOptions{kind, ModelSize::kSmall, SystemKind::kDuffing}, {0, 1});
    model->flatten_parameters();
    EXPECT_FALSE(model->rk2_mean_l1_step(x, x, u, 0.1).defined()) << to_string(kind);
  }
  ModelOptions reference{ModelKind::kPhnnJr, ModelSize::kSmall, SystemKind::kDuffing};
  reference.fused_networks = false;
  auto jr = DynamicsModel::create(reference, {0, 1});
  jr->flatten_parameters();
  EXPECT_FALSE(jr->rk2_mean_l1_step(x, x, u, 0.1).defined()) << "reference networks";
}

}  // namespace
}  // namespace phnn
