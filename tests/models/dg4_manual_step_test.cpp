// tests/models/dg4_manual_step_test.cpp — the hand-written DG4 training step
// (manual_step.cpp's ph_dg4_mean_l1 with the order-2 field jets of
// models/dg4_jet_heads.cpp) against autograd through
// PortHamiltonianModel::discrete_gradient4_field (the trainer's loss without
// a hand-written step, manual_step_reference.h), for PHNN-S and PHNN-JR on
// the shipped duffing (n_x = 2), coupled-duffing (4) and mass-chain (6)
// files (with ports) and on random structures of 2, 4 and 6 states without
// ports (PHNN-S's linear field; two inputs at 4 states), each without a
// regularizer and with CN, SN and SR (not SR on PHNN-S without ports:
// all_cases); data expanded over the members and
// gathered per member alternately; three rows below the projection's
// threshold.
//
// Tolerance, without a regularizer: 1e-12 of the loss per member
// (relative), of the largest parameter gradient, and of every parameter
// tensor's gradient against its own largest entry. Both sides compute the
// same function of the same doubles and differ in the order of their
// roundings only: gradH in reverse mode (a vector-Jacobian product of L_H)
// where autograd carries L_H's forward jet, the Hessian from the curvature
// head where autograd has the op-by-op jet of H, per-row sums in the order-2
// jet heads where autograd has ordered broadcast sums. Each sum has at most
// a few hundred terms, so the relative differences stay near 1e-15 (largest
// seen 5e-15 of the loss, 1.2e-14 of a parameter tensor). With CN, SN or SR
// the penalty of df/dx at x (the DG step's field jet, unchanged here) divides
// by the Jacobian's small singular values or eigenvalue real parts, which
// amplifies that round-off by the Jacobian's condition: as in
// general_manual_step_test.cpp those steps are compared to 1e-10 of the loss
// and of the largest gradient (largest seen 4e-12).
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <random>
#include <string>
#include <vector>

#include "models/manual_step_reference.h"
#include "phnn/models/general_ph.h"
#include "phnn/systems/system_file.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/regularizers.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace {

using testing_util::autograd_loss_of;

// A structure without ports: J skew (n_x + n_u)^2 with random entries, S
// = J (no port rows or columns).
ModelStructure portless_structure(int n_x, int n_u, unsigned seed) {
  const int W = n_x + n_u;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  ModelStructure s{n_x, 0, n_u, std::vector<double>(W * W, 0.0), {}};
  for (int r = 0; r < W; ++r) {
    for (int c = r + 1; c < W; ++c) {
      const double v = entry(rng);
      s.S[r * W + c] = v, s.S[c * W + r] = -v;
    }
  }
  s.J = s.S;
  return s;
}

struct Case {
  ModelKind kind;
  std::string system;  // a shipped file, or "" (portless_structure)
  int n_x, n_u;        // portless_structure's sizes
  Regularizer regularizer;
  bool expanded;  // x, x_next, u one [1, B, .] array viewed by every member
};

ModelStructure structure_of(const Case& c) {
  if (c.system.empty()) return portless_structure(c.n_x, c.n_u, static_cast<unsigned>(c.n_x));
  return model_structure(*load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" +
                                           c.system + ".toml"));
}

std::string name_of(const ::testing::TestParamInfo<Case>& info) {
  const Case& c = info.param;
  std::string name = to_string(c.kind) + "_" +
                     (c.system.empty() ? "x" + std::to_string(c.n_x) + "_no_ports" : c.system) +
                     "_" + to_string(c.regularizer) + (c.expanded ? "_expanded" : "_gathered");
  for (char& ch : name) {
    if (ch == '-') ch = '_';
  }
  return name;
}

class Dg4ManualStepTest : public ::testing::TestWithParam<Case> {};

TEST_P(Dg4ManualStepTest, LossAndGradientsAreAutograds) {
  const Case c = GetParam();
  const int64_t E = 3, B = 29;
  ModelOptions options{c.kind, ModelSize::kSmall, SystemKind::kHarmonic};
  options.general = std::make_shared<ModelStructure>(structure_of(c));
  const int n_x = options.general->n_x, n_u = options.general->n_u;
  auto model = DynamicsModel::create(options, {3, 4, 5});
  auto flat = model->flatten_parameters();
  testing_util::move_off_initialization(flat.values);
  torch::manual_seed(12);
  const int64_t rows = c.expanded ? 1 : E;
  auto x = torch::randn({rows, B, n_x}, torch::kFloat64);
  auto x_next = x + 0.05 * torch::randn({rows, B, n_x}, torch::kFloat64);
  x_next.narrow(1, 0, 3).copy_(x.narrow(1, 0, 3) + 1e-12);  // |dx| below the threshold
  auto u = torch::randn({rows, B, n_u}, torch::kFloat64);
  if (c.expanded) {
    x = x.expand({E, B, n_x}), x_next = x_next.expand({E, B, n_x}), u = u.expand({E, B, n_u});
  }
  const double h = 0.05, min_dx_norm = 1e-10;
  const TrainerOptions trainer;

  flat.gradients.zero_();
  const auto loss = autograd_loss_of(*model, IntegratorKind::kDg4, c.regularizer, x, x_next, u, h,
                                     min_dx_norm, trainer);
  loss.sum().backward();
  const auto autograd_loss = loss.detach().clone(), autograd_grad = flat.gradients.clone();
  ASSERT_GT(autograd_grad.abs().sum().item<double>(), 0.0);

  flat.gradients.zero_();
  const auto manual = model->dg4_mean_l1_step(x, x_next, u, h, min_dx_norm,
                                              jacobian_penalty(c.regularizer, trainer));
  ASSERT_TRUE(manual.defined());
  const double tolerance = c.regularizer == Regularizer::kNone ? 1e-12 : 1e-10;
  const double loss_rel =
      ((manual - autograd_loss).abs() / autograd_loss.abs()).max().item<double>();
  const double largest = (flat.gradients - autograd_grad).abs().max().item<double>();
  const double scale = autograd_grad.abs().max().item<double>();
  EXPECT_LT(loss_rel, tolerance) << manual << autograd_loss;
  EXPECT_LT(largest, tolerance * scale) << "largest difference " << largest << " of " << scale;
  // Without a penalty, every parameter tensor's gradient on its own, against
  // its own largest entry (no small gradient may hide under a large one).
  if (c.regularizer != Regularizer::kNone) return;
  int64_t offset = 0;
  for (const auto& p : model->parameters()) {
    const int64_t n = p.numel();
    const auto a = flat.gradients.narrow(0, offset, n), r = autograd_grad.narrow(0, offset, n);
    const double part_scale = r.abs().max().item<double>();
    EXPECT_LE((a - r).abs().max().item<double>(), tolerance * part_scale)
        << "parameter tensor at " << offset << " of largest gradient " << part_scale;
    offset += n;
  }
  ASSERT_EQ(offset, flat.gradients.numel());
}

std::vector<Case> all_cases() {
  std::vector<Case> out;
  bool expanded = false;
  for (ModelKind kind : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (Regularizer r :
         {Regularizer::kNone, Regularizer::kCn, Regularizer::kSn, Regularizer::kSr}) {
      for (const char* system : {"duffing", "coupled-duffing", "mass-chain"}) {
        out.push_back({kind, system, 0, 0, r, expanded = !expanded});
      }
      // Not SR on PHNN-S without ports: its Jacobian S_xx Q has its
      // eigenvalues on the imaginary axis, so SR's rho is a quotient of
      // round-off (losses ~1e8 that differ in the 9th digit).
      if (kind == ModelKind::kPhnnS && r == Regularizer::kSr) continue;
      for (const auto& [n_x, n_u] : {std::pair{2, 1}, std::pair{4, 2}, std::pair{6, 1}}) {
        out.push_back({kind, "", n_x, n_u, r, expanded = !expanded});
      }
    }
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(Models, Dg4ManualStepTest, ::testing::ValuesIn(all_cases()), name_of);

}  // namespace
}  // namespace phnn
