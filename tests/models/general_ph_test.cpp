// tests/models/general_ph_test.cpp — the n-dimensional NODE, PHNN-S and
// PHNN-JR: a built-in system's name and its shipped file give the same
// model, bit for bit; on a 4-state system their
// jets match autograd, their fields dissipate as the structure says, their
// discrete gradient satisfies the chain rule; the general regularizer
// statistics match the 2 x 2 closed forms.
#include "phnn/models/general_ph.h"

#include <string>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/systems/system_file.h"
#include "phnn/training/regularizers.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace {

const std::vector<std::uint64_t> kSeeds = {0, 1, 2};

std::string shipped(const std::string& name) {
  return std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml";
}

torch::Tensor uniform(std::vector<int64_t> shape, double scale, uint64_t seed) {
  torch::manual_seed(seed);
  return scale * (2.0 * torch::rand(shape, torch::kFloat64) - 1.0);
}

std::unique_ptr<DynamicsModel> general_model(ModelKind kind, const PhSystem& system) {
  ModelOptions options{kind, ModelSize::kSmall, SystemKind::kHarmonic};
  options.general = std::make_shared<ModelStructure>(model_structure(system));
  return DynamicsModel::create(options, kSeeds);
}

double max_rel(const torch::Tensor& a, const torch::Tensor& b) {
  return ((a - b).abs().max() / (b.abs().max() + 1e-300)).item<double>();
}

// A built-in name and its shipped system file give the same model: the
// same structure (BuiltinStructureTest), seeds and streams, so the same
// fields, energy, DG fields and their Jacobians, bit for bit.
TEST(GeneralModelTest, BuiltinNamesAndShippedFilesGiveTheSameModels) {
  for (SystemKind kind : all_systems()) {
    const auto system = make_system(to_string(kind));
    for (ModelKind m : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
      const auto named = DynamicsModel::create(ModelOptions{m, ModelSize::kSmall, kind}, kSeeds);
      const auto file = general_model(m, *system);
      ASSERT_EQ(named->parameter_count(), file->parameter_count());
      const auto x = uniform({3, 40, 2}, 0.5, 1), u = uniform({3, 40, 1}, 1.0, 2);
      const auto dx = uniform({3, 40, 2}, 0.02, 3);
      const std::string tag = to_string(kind) + " " + to_string(m);
      const FieldEval a = named->field(x, u, true), b = file->field(x, u, true);
      EXPECT_TRUE(torch::equal(b.f, a.f)) << tag;
      EXPECT_TRUE(torch::equal(b.dfdx, a.dfdx)) << tag;
      if (m == ModelKind::kNode) continue;
      EXPECT_TRUE(torch::equal(file->hamiltonian(x), named->hamiltonian(x))) << tag;
      EXPECT_TRUE(torch::equal(file->discrete_gradient_field(x, dx, u, 6e-6),
                               named->discrete_gradient_field(x, dx, u, 6e-6)))
          << tag;
      const FieldEval ja = named->discrete_gradient_field_with_jacobian(x, dx, u, 6e-6);
      const FieldEval jb = file->discrete_gradient_field_with_jacobian(x, dx, u, 6e-6);
      EXPECT_TRUE(torch::equal(jb.dfdx, ja.dfdx)) << tag;
      const FieldEval da = named->discrete_gradient4_field(x, dx, u, 0.01, 6e-6);
      const FieldEval db = file->discrete_gradient4_field(x, dx, u, 0.01, 6e-6);
      EXPECT_TRUE(torch::equal(db.f, da.f)) << tag;
    }
  }
}

// gradH without a graph (rollouts: reverse mode through L_H) against
// autograd's gradient of H on the op-by-op networks with the same weights,
// on the coupled oscillator (n_x = 4) with x expanded over the members.
TEST(GeneralModelTest, RolloutGradientIsAutogradsGradientOfH) {
  const auto system = load_system_file(shipped("coupled-duffing"));
  for (ModelKind m : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (ModelSize size : {ModelSize::kSmall, ModelSize::kLarge}) {
      ModelOptions options{m, size, SystemKind::kHarmonic};
      options.general = std::make_shared<ModelStructure>(model_structure(*system));
      const auto fused = DynamicsModel::create(options, kSeeds);
      options.fused_networks = false;
      const auto reference = DynamicsModel::create(options, kSeeds);
      const auto x = uniform({1, 30, 4}, 0.8, 6).expand({3, 30, 4});
      torch::Tensor g;
      {
        torch::NoGradGuard no_grad;
        g = fused->grad_hamiltonian(x);
      }
      const auto xr = x.contiguous().clone().requires_grad_(true);
      const auto expected =
          torch::autograd::grad({reference->hamiltonian(xr).sum()}, {xr})[0];
      EXPECT_LT(max_rel(g, expected), 1e-12) << to_string(m) << " " << to_string(size);
    }
  }
}

// Forward-mode jets against autograd on the coupled oscillator (n_x = 4).
TEST(GeneralModelTest, JetsMatchAutogradInFourStates) {
  const auto system = load_system_file(shipped("coupled-duffing"));
  for (ModelKind m : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    const auto model = general_model(m, *system);
    const auto x = uniform({3, 5, 4}, 0.5, 4).requires_grad_(true);
    const auto u = uniform({3, 5, 1}, 1.0, 5);
    const FieldEval fe = model->field(x, u, true);
    for (int i = 0; i < 4; ++i) {
      const auto row = torch::autograd::grad({fe.f.select(-1, i).sum()}, {x}, {}, true)[0];
      EXPECT_LT((fe.dfdx.select(-2, i) - row).abs().max().item<double>(), 1e-12) << to_string(m);
    }
    if (m == ModelKind::kNode) continue;
    const auto H = model->hamiltonian(x);
    const auto grad = torch::autograd::grad({H.sum()}, {x}, {}, true, true)[0];
    EXPECT_LT((model->grad_hamiltonian(x) - grad).abs().max().item<double>(), 1e-12);
  }
}

// The fused heads (general_heads.h) against the op-by-op jets, same weights:
// H, the RK field and the DG field, and the gradients of a loss on each
// with respect to every parameter, on 4 states (n_w = 2) and 6 states
// (n_w = 3, so the skew part K of z is used), and on a 2-state system.
TEST(GeneralModelTest, FusedHeadsMatchTheReferenceJetsWithGradients) {
  // A lossless forced oscillator: no ports (PHNN-S is S_x [gradH; u]).
  const std::string lossless = R"(name = "lossless"
states = ["q", "p"]
inputs = ["u"]
H = "p^2/2 + q^2/2"
S = [[0, 1, 0], [-1, 0, 1], [0, -1, 0]]
[initial]
method = "energy"
energy = [0.1, 1.0]
[control]
design = "constant"
range = [[-1, 1]]
)";
  for (const std::string name : {"harmonic", "coupled-duffing", "mass-chain", "lossless"}) {
    const auto system = name == "lossless" ? compile_system(lossless, "lossless.toml")
                                           : load_system_file(shipped(name));
    const int n = system->n_x();
    for (ModelKind m : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
      ModelOptions options{m, ModelSize::kSmall, SystemKind::kHarmonic};
      options.general = std::make_shared<ModelStructure>(model_structure(*system));
      const auto fused = DynamicsModel::create(options, kSeeds);
      options.fused_networks = false;
      const auto reference = DynamicsModel::create(options, kSeeds);
      const auto x = uniform({3, 30, n}, 0.5, 11), u = uniform({3, 30, 1}, 1.0, 12);
      const auto dx = uniform({3, 30, n}, 0.02, 13), w = uniform({3, 30, n}, 1.0, 14);
      const auto loss = [&](const DynamicsModel& model, int which) {
        if (which == 0) return (model.hamiltonian(x) * w.select(-1, 0)).sum();
        if (which == 1) return (model.field(x, u, false).f * w).sum();
        return (model.discrete_gradient_field(x, dx, u, 6e-6) * w).sum();
      };
      for (int which = 0; which < 3; ++which) {
        const auto la = loss(*fused, which), lb = loss(*reference, which);
        EXPECT_LT(std::abs((la - lb).item<double>()), 1e-12 * (1.0 + std::abs(lb.item<double>())))
            << name << " " << to_string(m) << " " << which;
        // H does not use the dissipation network: its gradients are unused.
        const auto ga = torch::autograd::grad({la}, fused->parameters(), {}, false, false, true);
        const auto gb = torch::autograd::grad({lb}, reference->parameters(), {}, false, false, true);
        ASSERT_EQ(ga.size(), gb.size());
        for (std::size_t k = 0; k < ga.size(); ++k) {
          ASSERT_EQ(ga[k].defined(), gb[k].defined()) << name << " " << which << " " << k;
          if (!ga[k].defined()) continue;
          EXPECT_LT(max_rel(ga[k], gb[k]), 1e-10) << name << " " << to_string(m) << " " << which
                                                  << " parameter " << k;
        }
      }
    }
  }
}

// PHNN-JR with u = 0: gradH^T f = -gradH^T R_xx gradH <= 0; PHNN-S with
// u = 0: gradH^T f = -w^T z(w) = -|L_z w|^2 <= 0 (J, S skew).
TEST(GeneralModelTest, FieldsDissipateEnergyWithoutInput) {
  for (const std::string name : {"coupled-duffing", "mass-chain"}) {
    const auto system = load_system_file(shipped(name));
    for (ModelKind m : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
      const auto model = general_model(m, *system);
      const auto x = uniform({3, 200, system->n_x()}, 0.5, 6);
      const auto u = torch::zeros({3, 200, 1}, torch::kFloat64);
      const auto power = (model->grad_hamiltonian(x) * model->field(x, u, false).f).sum(-1);
      EXPECT_LE(power.max().item<double>(), 1e-14) << name << " " << to_string(m);
    }
  }
}

// dg(x, dx)^T dx = H_theta(x + dx) - H_theta(x) for the learned H.
TEST(GeneralModelTest, LearnedDiscreteGradientSatisfiesTheChainRule) {
  const auto system = load_system_file(shipped("mass-chain"));
  const auto model = general_model(ModelKind::kPhnnS, *system);
  const auto& ph = dynamic_cast<const PortHamiltonianModel&>(*model);
  const auto x = uniform({3, 50, 6}, 0.5, 7), dx = uniform({3, 50, 6}, 0.05, 8);
  const auto lhs = (ph.discrete_gradient(x, dx, 6e-6) * dx).sum(-1);
  const auto rhs = model->hamiltonian(x + dx) - model->hamiltonian(x);
  EXPECT_LT((lhs - rhs).abs().max().item<double>(), 1e-13);
}

// The n x n spectral quantities by SVD and eigenvalues equal the 2 x 2
// closed forms (real and complex eigenvalue pairs both occur).
TEST(GeneralRegularizerTest, SvdAndEigenvaluePathMatchesTheClosedForm) {
  const auto J = uniform({2, 500, 2, 2}, 3.0, 9);
  const JacobianStats a = jacobian_stats(J, 1e-6), b = jacobian_stats_general(J, 1e-6);
  EXPECT_LT((a.sigma_max - b.sigma_max).abs().max().item<double>(), 1e-12);
  EXPECT_LT((a.sigma_min - b.sigma_min).abs().max().item<double>(), 1e-12);
  EXPECT_LT(max_rel(b.kappa, a.kappa), 1e-8);
  EXPECT_LT(max_rel(b.rho, a.rho), 1e-8);
}

TEST(GeneralRegularizerTest, GeneralStatisticsAreDifferentiable) {
  auto J = uniform({1, 8, 4, 4}, 1.0, 10).requires_grad_(true);
  const JacobianStats s = jacobian_stats(J, 1e-6);
  const auto loss = (s.kappa * s.kappa).mean() + s.sigma_max.mean() + ((s.rho - 1) * (s.rho - 1)).mean();
  const auto g = torch::autograd::grad({loss}, {J})[0];
  EXPECT_TRUE(torch::isfinite(g).all().item<bool>());
  EXPECT_GT(g.abs().max().item<double>(), 0.0);
}

}  // namespace
}  // namespace phnn
