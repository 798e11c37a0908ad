// tests/models/general_manual_step_test.cpp — the hand-written training steps
// of the n-dimensional models (models/general_manual_step.cpp) against
// autograd on the same model, for NODE, PHNN-S and PHNN-JR with RK2 and RK4
// and the PH models with DG (R at the midpoint and at the start; rows below
// the Gonzalez threshold included), on structures of 2, 4, 6 and 10 states
// (10: the heads' loops sized at run time, above head_sizes.h's fixed sizes)
// with 0-3 ports and 1-3 inputs, data expanded over the members (the
// full-batch view) and gathered per member, with and without a Jacobian
// regularizer (CN, SN, SR; the reference is then the trainer's regularized
// loss). NODE: the loss and every parameter gradient bitwise equal (the same
// operations in the same order). PH models: to 1e-12 (loss relative, and of
// the largest gradient): the step takes gradH in reverse mode (a
// vector-Jacobian product of L_H, fused_mlp_gradient.h) where autograd's
// graph propagates L_H's forward-mode jet. With a regularizer the field jet
// at x runs through the jet heads of general_jet_heads.h instead of the
// op-by-op jets (those agree to 1e-12 of their largest entry,
// JetHeadsMatchTheOpByOpJets); the penalty's kappa and rho amplify that
// round-off by the Jacobian's condition (gradients up to 1e8 here), so those
// steps are compared to 1e-10.
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "models/general_jet_heads.h"
#include "models/manual_step_reference.h"
#include "phnn/models/general_ph.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/regularizers.h"

namespace phnn {
namespace {

using testing_util::autograd_loss_of;

// A port-Hamiltonian structure with random entries: S skew of size
// n_x + n_w + n_u with S_ww = 0, J = S without its port rows and columns.
ModelStructure random_structure(int n_x, int n_w, int n_u, unsigned seed) {
  const int W = n_x + n_w + n_u;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  ModelStructure s{n_x, n_w, n_u, std::vector<double>(W * W, 0.0), {}};
  for (int r = 0; r < W; ++r) {
    for (int c = r + 1; c < W; ++c) {
      const bool both_ports = r >= n_x && r < n_x + n_w && c >= n_x && c < n_x + n_w;
      const double v = both_ports ? 0.0 : entry(rng);
      s.S[r * W + c] = v, s.S[c * W + r] = -v;
    }
  }
  for (int r = 0; r < W; ++r) {
    if (r >= n_x && r < n_x + n_w) continue;
    for (int c = 0; c < W; ++c) {
      if (c < n_x || c >= n_x + n_w) s.J.push_back(s.S[r * W + c]);
    }
  }
  return s;
}

struct Case {
  ModelKind kind;
  IntegratorKind integrator;
  int n_x, n_w, n_u;
  bool expanded;          // x, x_next, u one [1, B, .] array viewed by every member
  bool at_start = false;  // DG: R at x_n
  Regularizer regularizer = Regularizer::kNone;
};

std::string name_of(const ::testing::TestParamInfo<Case>& info) {
  const Case& c = info.param;
  std::string name = to_string(c.kind) + "_" + to_string(c.integrator) + "_x" +
                     std::to_string(c.n_x) + "w" + std::to_string(c.n_w) + "u" +
                     std::to_string(c.n_u) + (c.expanded ? "_expanded" : "_gathered") +
                     (c.at_start ? "_start" : "") +
                     (c.regularizer == Regularizer::kNone ? "" : "_" + to_string(c.regularizer));
  for (char& ch : name) {
    if (ch == '-') ch = '_';
  }
  return name;
}

class GeneralManualStepTest : public ::testing::TestWithParam<Case> {};

TEST_P(GeneralManualStepTest, LossAndGradientsAreAutograds) {
  const Case c = GetParam();
  const std::vector<std::uint64_t> seeds = {3, 4, 5};
  const int64_t E = 3, B = 29;
  ModelOptions options{c.kind, ModelSize::kSmall, SystemKind::kHarmonic};
  options.general = std::make_shared<ModelStructure>(
      random_structure(c.n_x, c.n_w, c.n_u, static_cast<unsigned>(7 * c.n_x + c.n_w)));
  if (c.at_start) options.dg_structure_point = DgStructurePoint::kStart;
  auto model = DynamicsModel::create(options, seeds);
  auto flat = model->flatten_parameters();
  testing_util::move_off_initialization(flat.values);
  torch::manual_seed(12);
  const int64_t rows = c.expanded ? 1 : E;
  auto x = torch::randn({rows, B, c.n_x}, torch::kFloat64);
  auto x_next = x + 0.05 * torch::randn({rows, B, c.n_x}, torch::kFloat64);
  x_next.narrow(1, 0, 3).copy_(x.narrow(1, 0, 3) + 1e-12);  // |dx| below DG's threshold
  auto u = torch::randn({rows, B, c.n_u}, torch::kFloat64);
  if (c.expanded) {
    x = x.expand({E, B, c.n_x}), x_next = x_next.expand({E, B, c.n_x});
    u = u.expand({E, B, c.n_u});
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

using M = ModelKind;
using I = IntegratorKind;
INSTANTIATE_TEST_SUITE_P(
    Models, GeneralManualStepTest,
    ::testing::Values(
        Case{M::kPhnnJr, I::kRk2, 2, 1, 1, true}, Case{M::kPhnnJr, I::kRk2, 4, 2, 1, false},
        Case{M::kPhnnJr, I::kRk2, 6, 3, 2, true}, Case{M::kPhnnJr, I::kDg, 2, 1, 1, false},
        Case{M::kPhnnJr, I::kDg, 4, 2, 1, true}, Case{M::kPhnnJr, I::kDg, 6, 3, 1, false},
        Case{M::kPhnnJr, I::kDg, 4, 2, 2, false, true}, Case{M::kPhnnS, I::kRk2, 2, 1, 1, false},
        Case{M::kPhnnS, I::kRk2, 4, 2, 1, true}, Case{M::kPhnnS, I::kRk2, 6, 3, 2, false},
        Case{M::kPhnnS, I::kRk2, 4, 0, 1, false}, Case{M::kPhnnS, I::kDg, 2, 1, 1, true},
        Case{M::kPhnnS, I::kDg, 4, 2, 2, false}, Case{M::kPhnnS, I::kDg, 6, 3, 1, true},
        Case{M::kPhnnS, I::kDg, 6, 0, 1, false}, Case{M::kNode, I::kRk2, 2, 1, 1, true},
        Case{M::kNode, I::kRk2, 4, 2, 2, false}, Case{M::kNode, I::kRk2, 6, 3, 1, true},
        Case{M::kPhnnJr, I::kRk2, 10, 1, 3, false}, Case{M::kPhnnS, I::kDg, 10, 3, 3, true},
        Case{M::kNode, I::kRk2, 2, 1, 1, false, false, Regularizer::kCn},
        Case{M::kNode, I::kRk2, 4, 2, 1, true, false, Regularizer::kSn},
        Case{M::kNode, I::kRk2, 6, 3, 1, false, false, Regularizer::kSr},
        Case{M::kPhnnJr, I::kRk2, 2, 1, 1, false, false, Regularizer::kCn},
        Case{M::kPhnnJr, I::kRk2, 4, 2, 1, true, false, Regularizer::kSn},
        Case{M::kPhnnJr, I::kDg, 4, 2, 2, false, false, Regularizer::kSr},
        Case{M::kPhnnJr, I::kDg, 6, 3, 1, false, true, Regularizer::kCn},
        Case{M::kPhnnS, I::kRk2, 2, 1, 1, true, false, Regularizer::kCn},
        Case{M::kPhnnS, I::kRk2, 4, 2, 1, false, false, Regularizer::kSr},
        Case{M::kPhnnS, I::kDg, 6, 3, 2, false, false, Regularizer::kSn},
        Case{M::kPhnnS, I::kDg, 4, 0, 1, true, false, Regularizer::kCn},
        Case{M::kPhnnS, I::kRk2, 10, 3, 3, false, false, Regularizer::kCn},
        Case{M::kPhnnJr, I::kRk4, 4, 2, 1, false}, Case{M::kPhnnS, I::kRk4, 6, 3, 2, true},
        Case{M::kNode, I::kRk4, 4, 2, 1, true},
        Case{M::kNode, I::kRk4, 6, 3, 1, false, false, Regularizer::kCn},
        Case{M::kPhnnJr, I::kRk4, 4, 2, 1, true, false, Regularizer::kSn},
        Case{M::kPhnnS, I::kRk4, 4, 0, 1, false, false, Regularizer::kCn},
        Case{M::kPhnnS, I::kRk4, 4, 2, 1, true, false, Regularizer::kSr}),
    name_of);

double max_rel(const torch::Tensor& a, const torch::Tensor& b) {
  return ((a - b).abs().max() / b.abs().max()).item<double>();
}

// The field and df/dx at x from the jet heads against the op-by-op jets of
// the model (field(x, u, true)), PHNN-JR and PHNN-S, 2-10 states.
TEST(GeneralJetHeadsTest, JetHeadsMatchTheOpByOpJets) {
  struct Dims {
    int n_x, n_w, n_u;
  };
  for (const Dims dims : {Dims{2, 1, 1}, Dims{4, 2, 1}, Dims{6, 3, 2}, Dims{10, 3, 3}}) {
    const ModelStructure st = random_structure(dims.n_x, dims.n_w, dims.n_u, 5);
    for (ModelKind kind : {ModelKind::kPhnnJr, ModelKind::kPhnnS}) {
      ModelOptions options{kind, ModelSize::kSmall, SystemKind::kHarmonic};
      options.general = std::make_shared<ModelStructure>(st);
      const auto model = DynamicsModel::create(options, {1, 2});
      torch::NoGradGuard no_grad;
      torch::manual_seed(3);
      const auto x = torch::randn({2, 7, dims.n_x}, torch::kFloat64);
      const auto u = torch::randn({2, 7, dims.n_u}, torch::kFloat64);
      const FieldEval ref = model->field(x, u, true);
      const auto nets = model->networks();
      const Jet o_h = nets[0]->forward_input(x, dims.n_x, 2);
      internal::CurvatureTape tape;
      const auto e = internal::general_curvature_forward(o_h.v, o_h.g, o_h.h, x, &tape);
      internal::JrFieldJet jet;
      if (kind == ModelKind::kPhnnJr) {
        const Jet o = nets[1]->forward_input(torch::cat({x, u}, -1), dims.n_x, 1);
        jet = internal::general_jr_field_jet_forward(e.grad, e.hessian, o.v, o.g, u, st.J);
      } else {
        std::vector<double> m;  // [S_wx S_wu]
        const int W = dims.n_x + dims.n_w + dims.n_u;
        for (int r = dims.n_x; r < dims.n_x + dims.n_w; ++r)
          for (int c = 0; c < W; ++c)
            if (c < dims.n_x || c >= dims.n_x + dims.n_w) m.push_back(st.S[r * W + c]);
        const auto w = internal::general_port_jet(e.grad, e.hessian, u, m, dims.n_w);
        Jet in;
        in.v = w.w, in.g = w.w_g;
        const Jet o = nets[1]->forward(in);
        jet = internal::general_s_field_jet_forward(e.grad, e.hessian, u, o.v, o.g, w, st.S,
                                                    dims.n_w);
      }
      EXPECT_LT(max_rel(jet.f, ref.f), 1e-12) << to_string(kind) << " n_x " << dims.n_x;
      EXPECT_LT(max_rel(jet.g.transpose(-1, -2), ref.dfdx), 1e-12)
          << to_string(kind) << " n_x " << dims.n_x;
    }
  }
}

}  // namespace
}  // namespace phnn
