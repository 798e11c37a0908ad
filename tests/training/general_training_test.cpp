// tests/training/general_training_test.cpp — train_cell on a file-defined
// system (the coupled Duffing oscillator, n_x = 4, n_w = 2): every model,
// integrator and regularizer trains and rolls out; a member's result does
// not depend on the members stacked with it; training lowers the loss.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "phnn/systems/system_file.h"
#include "phnn/training/trainer.h"

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

TEST(GeneralTrainingTest, TrainingLowersTheValidationLoss) {
  const auto results = train_cell(cell(ModelKind::kPhnnS, IntegratorKind::kRk2, Regularizer::kNone, 300),
                                  coupled().data, *coupled().system);
  for (const RunResult& r : results) {
    EXPECT_LT(r.best_validation_loss, 0.5 * r.trace.front().validation_loss);
  }
}

}  // namespace
}  // namespace phnn
