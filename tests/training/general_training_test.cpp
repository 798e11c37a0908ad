// tests/training/general_training_test.cpp — train_cell on a file-defined
// system (the coupled Duffing oscillator, n_x = 4, n_w = 2): every model,
// integrator and regularizer trains and rolls out; a member's result does
// not depend on the members stacked with it; training lowers the loss.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "phnn/systems/system_file.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/trainer.h"
#include "training/rollout.h"

namespace phnn {
namespace {

struct CoupledData {
  std::unique_ptr<PhSystem> system;
  PhSystemData data;
};

const CoupledData& coupled() {
  static const CoupledData d = [] {
    CoupledData out;
    out.system = load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/coupled-duffing.toml");
    DatasetOptions options;
    options.num_validation = 60;
    options.num_inference = 4;
    out.data = make_ph_system_data(*out.system, options, 25);
    return out;
  }();
  return d;
}

CellSpec cell(ModelKind model, IntegratorKind integrator, Regularizer reg, int steps) {
  CellSpec c;
  c.model = model;
  c.integrator = integrator;
  c.regularizer = reg;
  c.n_train = 25;
  c.seeds = {0, 1};
  c.training.steps = steps;
  c.training.eval_every = 10;
  return c;
}

TEST(GeneralTrainingTest, EveryModelIntegratorAndRegularizerTrains) {
  struct Pair { ModelKind m; IntegratorKind i; };
  for (const Pair& p : {Pair{ModelKind::kNode, IntegratorKind::kRk2}, Pair{ModelKind::kPhnnJr, IntegratorKind::kDg},
                        Pair{ModelKind::kPhnnJr, IntegratorKind::kRk2}, Pair{ModelKind::kPhnnS, IntegratorKind::kDg},
                        Pair{ModelKind::kPhnnS, IntegratorKind::kRk2}, Pair{ModelKind::kPhnnS, IntegratorKind::kDg4}}) {
    for (Regularizer r : {Regularizer::kNone, Regularizer::kCn, Regularizer::kSn, Regularizer::kSr}) {
      const auto results = train_cell(cell(p.m, p.i, r, 20), coupled().data, *coupled().system);
      ASSERT_EQ(results.size(), 2u);
      for (const RunResult& res : results) {
        const std::string what = model_label(p.m, p.i) + " " + to_string(r);
        EXPECT_EQ(res.status, RunStatus::kDone) << what << ": " << res.message;
        EXPECT_TRUE(std::isfinite(res.mse)) << what;
        EXPECT_EQ(res.trajectory_errors.size(), 4u) << what;
        EXPECT_TRUE(std::isfinite(res.trace.back().kappa) && res.trace.back().kappa >= 1.0) << what;
        // Figure trajectories of a system file: inference trajectories 0 and 1.
        const auto& states = coupled().data.inference.states;
        ASSERT_EQ(res.figure_reference_075.size(), states[1].size() * 4) << what;
        EXPECT_EQ(res.figure_reference_075[4 * 7 + 2], states[1][7](2)) << what;
        ASSERT_EQ(res.figure_prediction_05.size(), states[0].size() * 4) << what;
        for (int j = 0; j < 4; ++j) EXPECT_EQ(res.figure_prediction_05[j], states[0][0](j)) << what;
      }
    }
  }
}

// Stacking is exact: seed 1 trained with seeds 0 and 2 equals seed 1 alone.
TEST(GeneralTrainingTest, AMembersResultDoesNotDependOnItsStackmates) {
  struct Pair { ModelKind m; IntegratorKind i; };
  for (const Pair& p : {Pair{ModelKind::kPhnnJr, IntegratorKind::kDg}, Pair{ModelKind::kPhnnJr, IntegratorKind::kRk2},
                        Pair{ModelKind::kPhnnS, IntegratorKind::kDg4}, Pair{ModelKind::kNode, IntegratorKind::kRk2}}) {
    const IntegratorKind i = p.i;
    CellSpec stacked = cell(p.m, i, Regularizer::kCn, 30);
    stacked.seeds = {0, 1, 2};
    CellSpec alone = stacked;
    alone.seeds = {1};
    const auto a = train_cell(stacked, coupled().data, *coupled().system);
    const auto b = train_cell(alone, coupled().data, *coupled().system);
    EXPECT_EQ(a[1].mse, b[0].mse) << model_label(p.m, i);
    EXPECT_EQ(a[1].weights, b[0].weights) << model_label(p.m, i);
    EXPECT_EQ(a[1].trajectory_errors, b[0].trajectory_errors) << model_label(p.m, i);
  }
}

// Time-varying inputs: the rollout of inference trajectory 0 (the first
// figure row) replays its recorded u_n on step n -> n + 1. Checked against
// a hand-written loop over the same model, RK2 and DG.
TEST(GeneralTrainingTest, RolloutsReplayTheRecordedInputs) {
  const auto system = compile_system(R"(name = "forced"
states = ["q", "p"]
inputs = ["u"]
ports = ["w"]
H = "p^2/2 + q^2/2 + q^4/4"
z = ["0.2*w"]
S = [[0, 1, 0, 0], [-1, 0, -1, 1], [0, 1, 0, 0], [0, -1, 0, 0]]
[initial]
method = "energy"
energy = [0.1, 1.0]
[control]
design = "sines"
frequencies = [1.0, 2.5]
amplitude = [0.5, 1.0]
)", "forced.toml");
  DatasetOptions options;
  options.num_validation = 10;
  options.num_inference = 2;
  options.beta = 1.0;  // 100 inference steps
  const PhSystemData data = make_ph_system_data(*system, options, 5);
  const CellData cd = make_cell_data(data, *system);
  ASSERT_FALSE(cd.inference_inputs.empty());
  for (IntegratorKind integrator : {IntegratorKind::kRk2, IntegratorKind::kDg}) {
    CellSpec spec = cell(ModelKind::kPhnnS, integrator, Regularizer::kNone, 1);
    spec.seeds = {3};
    const auto model = DynamicsModel::create(inference_model_options(spec, cd), {3});
    const Rollouts r = roll_out(*model, spec, cd);
    torch::NoGradGuard no_grad;
    const std::vector<VecX>& states = data.inference.states[0];
    auto x = torch::tensor({states[0](0), states[0](1)}, torch::kFloat64).reshape({1, 1, 2});
    DgInferenceOptions dg;  // roll_out's, from the cell
    dg.tolerance = spec.training.newton_tolerance;
    dg.max_iterations = spec.training.newton_max_iterations;
    dg.min_dx_norm = spec.training.dg_min_dx_norm;
    DgNewtonJacobian cache;
    double worst = 0.0;
    for (int n = 1; n <= r.steps; ++n) {
      const auto u = torch::full({1, 1, 1}, data.inference.inputs[0][static_cast<std::size_t>(n - 1)](0),
                                 torch::kFloat64);
      x = integrator == IntegratorKind::kDg ? dg_inference_step(*model, x, u, data.inference.step, dg, &cache).x_next
                                            : explicit_step(*model, integrator, x, u, data.inference.step);
      const auto rolled = r.figure[0][n][0];
      worst = std::max(worst, (rolled - x.reshape({2})).abs().max().item<double>() /
                                  (1.0 + x.abs().max().item<double>()));
    }
    EXPECT_LT(worst, 1e-9) << to_string(integrator);
  }
}

TEST(GeneralTrainingTest, TrainingLowersTheValidationLoss) {
  const auto results = train_cell(cell(ModelKind::kPhnnS, IntegratorKind::kRk2, Regularizer::kNone, 300),
                                  coupled().data, *coupled().system);
  for (const RunResult& r : results) {
    EXPECT_LT(r.best_validation_loss, 0.5 * r.trace.front().validation_loss);
  }
}

}  // namespace
}  // namespace phnn
