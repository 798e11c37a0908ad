// tests/models/manual_step_test.cpp — the hand-written training steps
// (models/manual_step.h, general_manual_step.cpp) on the built-in systems'
// structures (DynamicsModel::create without a ModelStructure) against
// autograd on the same model, for NODE, PHNN-S and PHNN-JR with RK2 and RK4
// and the PH models with DG (R at the midpoint and at the start; rows below
// the Gonzalez threshold included), each built-in structure, two sizes, data
// expanded over the members (the full-batch view) and gathered per member;
// with a Jacobian regularizer (CN, SN, SR) the reference is the trainer's
// regularized loss, L_d + the penalty of df/dx at x with the RK2 step's first
// stage reused. NODE: bitwise; PH models: to 1e-12 (1e-10 with a penalty),
// the tolerances and their reasons of general_manual_step_test.cpp.
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cctype>
#include <cstring>
#include <string>
#include <vector>

#include "models/manual_step_reference.h"
#include "phnn/models/port_hamiltonian.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/regularizers.h"

namespace phnn {
namespace {

using testing_util::autograd_loss_of;

struct Case {
  ModelKind kind;
  IntegratorKind integrator;
  SystemKind structure;
  ModelSize size;
  bool expanded;          // x, x_next, u one [1, B, .] array viewed by every member
  bool at_start = false;  // DG: R at x_n
  Regularizer regularizer = Regularizer::kNone;
};

class ManualStepTest : public ::testing::TestWithParam<Case> {};

TEST_P(ManualStepTest, LossAndGradientsAreAutograds) {
  const Case c = GetParam();
  const std::vector<std::uint64_t> seeds = {3, 4, 5, 6};
  const int64_t E = 4, B = 37;
  ModelOptions options{c.kind, c.size, c.structure};
  if (c.at_start) options.dg_structure_point = DgStructurePoint::kStart;
  auto model = DynamicsModel::create(options, seeds);
  auto flat = model->flatten_parameters();
  testing_util::move_off_initialization(flat.values);
  torch::manual_seed(12);
  const int64_t rows = c.expanded ? 1 : E;
  auto x = 1.5 * torch::randn({rows, B, 2}, torch::kFloat64);
  auto x_next = x + 0.05 * torch::randn({rows, B, 2}, torch::kFloat64);
  x_next.narrow(1, 0, 3).copy_(x.narrow(1, 0, 3) + 1e-12);  // |dx| below DG's threshold
  auto u = torch::randn({rows, B, 1}, torch::kFloat64);
  if (c.expanded) {
    x = x.expand({E, B, 2}), x_next = x_next.expand({E, B, 2}), u = u.expand({E, B, 1});
  }
  const double h = 0.05, min_dx_norm = 1e-10;
  const bool dg = c.integrator == IntegratorKind::kDg;

  const TrainerOptions trainer;
  flat.gradients.zero_();
  const auto loss =
      autograd_loss_of(*model, c.integrator, c.regularizer, x, x_next, u, h, min_dx_norm, trainer);
  loss.sum().backward();
  const auto autograd_loss = loss.detach().clone(), autograd_grad = flat.gradients.clone();
  ASSERT_GT(autograd_grad.abs().sum().item<double>(), 0.0);

  flat.gradients.zero_();
  const JacobianPenalty penalty = jacobian_penalty(c.regularizer, trainer);
  const auto manual = dg ? model->dg_mean_l1_step(x, x_next, u, h, min_dx_norm, penalty)
                         : model->explicit_mean_l1_step(c.integrator, x, x_next, u, h, penalty);
  ASSERT_TRUE(manual.defined());
  testing_util::expect_step_matches(c.kind, c.regularizer, manual, autograd_loss, flat.gradients,
                                    autograd_grad);
}

INSTANTIATE_TEST_SUITE_P(
    Models, ManualStepTest,
    ::testing::Values(
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk2, SystemKind::kHarmonic, ModelSize::kSmall,
             true},
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk2, SystemKind::kDuffing, ModelSize::kSmall,
             false},
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk2, SystemKind::kSelfSustained,
             ModelSize::kSmall, true},
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk2, SystemKind::kSelfSustained,
             ModelSize::kMedium, false},
        Case{ModelKind::kPhnnS, IntegratorKind::kRk2, SystemKind::kHarmonic, ModelSize::kSmall,
             false},
        Case{ModelKind::kPhnnS, IntegratorKind::kRk2, SystemKind::kDuffing, ModelSize::kSmall,
             true},
        Case{ModelKind::kPhnnS, IntegratorKind::kRk2, SystemKind::kSelfSustained,
             ModelSize::kMedium, false},
        Case{ModelKind::kNode, IntegratorKind::kRk2, SystemKind::kDuffing, ModelSize::kSmall, true},
        Case{ModelKind::kNode, IntegratorKind::kRk2, SystemKind::kSelfSustained, ModelSize::kMedium,
             false},
        Case{ModelKind::kPhnnJr, IntegratorKind::kDg, SystemKind::kHarmonic, ModelSize::kSmall,
             true},
        Case{ModelKind::kPhnnJr, IntegratorKind::kDg, SystemKind::kDuffing, ModelSize::kMedium,
             false},
        Case{ModelKind::kPhnnJr, IntegratorKind::kDg, SystemKind::kSelfSustained, ModelSize::kSmall,
             false, true},
        Case{ModelKind::kPhnnS, IntegratorKind::kDg, SystemKind::kDuffing, ModelSize::kSmall, true},
        Case{ModelKind::kPhnnS, IntegratorKind::kDg, SystemKind::kSelfSustained, ModelSize::kMedium,
             false},
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk2, SystemKind::kDuffing, ModelSize::kSmall,
             false, false, Regularizer::kCn},
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk2, SystemKind::kSelfSustained,
             ModelSize::kMedium, true, false, Regularizer::kSr},
        Case{ModelKind::kPhnnJr, IntegratorKind::kDg, SystemKind::kHarmonic, ModelSize::kSmall,
             false, false, Regularizer::kCn},
        Case{ModelKind::kPhnnJr, IntegratorKind::kDg, SystemKind::kDuffing, ModelSize::kSmall, true,
             true, Regularizer::kSn},
        Case{ModelKind::kNode, IntegratorKind::kRk2, SystemKind::kDuffing, ModelSize::kSmall, false,
             false, Regularizer::kCn},
        Case{ModelKind::kNode, IntegratorKind::kRk2, SystemKind::kHarmonic, ModelSize::kMedium,
             true, false, Regularizer::kSn},
        Case{ModelKind::kNode, IntegratorKind::kRk2, SystemKind::kSelfSustained, ModelSize::kSmall,
             false, false, Regularizer::kSr},
        Case{ModelKind::kPhnnS, IntegratorKind::kRk2, SystemKind::kDuffing, ModelSize::kSmall,
             false, false, Regularizer::kCn},
        Case{ModelKind::kPhnnS, IntegratorKind::kRk2, SystemKind::kSelfSustained,
             ModelSize::kMedium, true, false, Regularizer::kSn},
        Case{ModelKind::kPhnnS, IntegratorKind::kDg, SystemKind::kHarmonic, ModelSize::kSmall,
             false, false, Regularizer::kSr},
        Case{ModelKind::kPhnnS, IntegratorKind::kDg, SystemKind::kSelfSustained, ModelSize::kSmall,
             true, false, Regularizer::kCn},
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk4, SystemKind::kDuffing, ModelSize::kSmall,
             false},
        Case{ModelKind::kPhnnS, IntegratorKind::kRk4, SystemKind::kSelfSustained, ModelSize::kSmall,
             true},
        Case{ModelKind::kNode, IntegratorKind::kRk4, SystemKind::kHarmonic, ModelSize::kMedium,
             false},
        Case{ModelKind::kPhnnJr, IntegratorKind::kRk4, SystemKind::kHarmonic, ModelSize::kSmall,
             true, false, Regularizer::kSr},
        Case{ModelKind::kPhnnS, IntegratorKind::kRk4, SystemKind::kDuffing, ModelSize::kSmall,
             false, false, Regularizer::kCn},
        Case{ModelKind::kNode, IntegratorKind::kRk4, SystemKind::kSelfSustained, ModelSize::kSmall,
             true, false, Regularizer::kSn}),
    // A readable, deterministic name (the default prints the struct's bytes, padding included).
    [](const ::testing::TestParamInfo<Case>& case_info) {
      const Case& c = case_info.param;
      std::string name =
          to_string(c.kind) + "_" + to_string(c.integrator) + "_" + to_string(c.structure) + "_" +
          to_string(c.size) + (c.expanded ? "_expanded" : "_gathered") +
          (c.at_start ? "_start" : "") +
          (c.regularizer != Regularizer::kNone ? "_" + to_string(c.regularizer) : "");
      for (char& ch : name) {
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      }
      return name;
    });

// Reference (op-by-op) networks have no hand-written step: the trainer then runs autograd.
TEST(ManualStepTest, ReferenceNetworksHaveNone) {
  const auto x = torch::zeros({2, 3, 2}, torch::kFloat64),
             u = torch::zeros({2, 3, 1}, torch::kFloat64);
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    ModelOptions reference{kind, ModelSize::kSmall, SystemKind::kDuffing};
    reference.fused_networks = false;
    auto model = DynamicsModel::create(reference, {0, 1});
    model->flatten_parameters();
    EXPECT_FALSE(model->explicit_mean_l1_step(IntegratorKind::kRk2, x, x, u, 0.1, {}).defined())
        << to_string(kind);
    EXPECT_FALSE(model->dg_mean_l1_step(x, x, u, 0.1, 1e-10, {}).defined()) << to_string(kind);
  }
}

}  // namespace
}  // namespace phnn
