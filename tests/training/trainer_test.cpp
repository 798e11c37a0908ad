// tests/training/trainer_test.cpp — train_cell's guarantees (stacking, checkpoints,
// freezing, the knobs), in float64 and float32 training.
// Size: one test file per module.
#include "phnn/training/trainer.h"
#include "reference/oscillator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/data/ph_dataset.h"
#include "phnn/systems/system_file.h"
#include "training/cell_trainer.h"
#include "training/small_data.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

using testing_util::small_data;
using testing_util::SystemAndData;
using testing_util::train_cell;

double rel(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); }

// A PHNN-JR-DG + CN cell on Duffing (N_train 100 > batch: per-member
// reshuffling is exercised) in `precision`, trained as a stack of seeds
// {4, 7, 9} and as seed 7 alone.
struct StackedAndAlone {
  std::vector<RunResult> stacked, alone;
};
StackedAndAlone train_stacked_and_alone(Precision precision) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnJr;
  cell.integrator = IntegratorKind::kDg;
  cell.n_train = 100;
  cell.regularizer = Regularizer::kCn;
  cell.training.precision = precision;
  cell.training.steps = 200;
  cell.training.eval_every = 100;
  cell.seeds = {4, 7, 9};
  StackedAndAlone out;
  out.stacked = train_cell(cell, small_data(SystemKind::kDuffing));
  cell.seeds = {7};
  out.alone = train_cell(cell, small_data(SystemKind::kDuffing));
  return out;
}

// Members trained in a stack of 3 agree with the same seeds trained alone.
TEST(TrainerTest, StackingIsExact) {
  const auto [stacked, alone] = train_stacked_and_alone(Precision::kFloat64);
  ASSERT_EQ(stacked[1].trace.size(), alone[0].trace.size());
  for (std::size_t k = 0; k < alone[0].trace.size(); ++k) {
    EXPECT_LE(rel(stacked[1].trace[k].validation_loss, alone[0].trace[k].validation_loss), 1e-9);
    EXPECT_LE(rel(stacked[1].trace[k].kappa, alone[0].trace[k].kappa), 1e-9);
  }
  EXPECT_LE(rel(stacked[1].mse, alone[0].mse), 1e-9);
  EXPECT_NE(stacked[0].mse, stacked[1].mse);  // members are different models
}

// The same in float32 training, bitwise: every trace value, best step,
// stored weight and the MSE. (The reference networks' LibTorch ops and the
// per-member sgemm calls are elementwise or per member; inference is the
// float64 path above.)
TEST(TrainerTest, StackingIsExactInFloat32) {
  const auto [stacked, alone] = train_stacked_and_alone(Precision::kFloat32);
  ASSERT_EQ(stacked[1].trace.size(), alone[0].trace.size());
  for (std::size_t k = 0; k < alone[0].trace.size(); ++k) {
    const TracePoint &a = stacked[1].trace[k], &b = alone[0].trace[k];
    EXPECT_EQ(a.train_loss, b.train_loss) << k;
    EXPECT_EQ(a.validation_loss, b.validation_loss) << k;
    EXPECT_EQ(a.kappa, b.kappa) << k;
    EXPECT_EQ(a.sigma_max, b.sigma_max) << k;
    EXPECT_EQ(a.rho, b.rho) << k;
  }
  EXPECT_EQ(stacked[1].best_step, alone[0].best_step);
  EXPECT_EQ(stacked[1].weights, alone[0].weights);
  EXPECT_EQ(stacked[1].mse, alone[0].mse);
  EXPECT_NE(stacked[0].mse, stacked[1].mse);  // members are different models
}

// precision = float32 trains in float32: every logged loss and Jacobian
// statistic and every stored weight is a float32 value (a float64 run's are
// not); the step-0 losses (the same initial weights, rounded, on the data
// rounded) agree with float64's to float32 round-off but not beyond; and a
// 0-step run stores the float64 initial weights rounded to float32.
TEST(TrainerTest, Float32TrainingRunsInFloat32) {
  const auto is_float = [](double v) { return static_cast<double>(static_cast<float>(v)) == v; };
  for (IntegratorKind integrator : {IntegratorKind::kRk2, IntegratorKind::kDg}) {
    SCOPED_TRACE(to_string(integrator));
    CellSpec cell;
    cell.model = ModelKind::kPhnnJr;
    cell.integrator = integrator;
    cell.regularizer = Regularizer::kSn;
    cell.training.steps = 20;
    cell.training.eval_every = 10;
    cell.seeds = {1};
    const RunResult f64 = train_cell(cell, small_data(SystemKind::kDuffing))[0];
    cell.training.precision = Precision::kFloat32;
    const RunResult f32 = train_cell(cell, small_data(SystemKind::kDuffing))[0];
    ASSERT_EQ(f32.trace.size(), 3u);
    for (const TracePoint& tp : f32.trace) {
      for (double v : {tp.train_loss, tp.validation_loss, tp.kappa, tp.sigma_max, tp.rho}) {
        EXPECT_TRUE(is_float(v)) << "step " << tp.step << ": " << v;
      }
    }
    EXPECT_FALSE(is_float(f64.trace[0].validation_loss));
    ASSERT_EQ(static_cast<long>(f32.weights.size()), f32.parameter_count);
    EXPECT_EQ(std::count_if(f32.weights.begin(), f32.weights.end(), is_float),
              static_cast<long>(f32.weights.size()));
    EXPECT_LT(std::count_if(f64.weights.begin(), f64.weights.end(), is_float), 10);
    // Step 0: float32 round-off of the data, weights and ops (measured
    // 8e-8 for RK2, 3e-8 for DG), far above float64's ~1e-16.
    const double r0 = rel(f32.trace[0].validation_loss, f64.trace[0].validation_loss);
    char measured[32];
    std::snprintf(measured, sizeof measured, "%.2e", r0);
    RecordProperty("step0_relative_difference_" + to_string(integrator), measured);
    EXPECT_LT(r0, 1e-5);
    EXPECT_GT(r0, 1e-10);
    EXPECT_TRUE(std::isfinite(f32.mse));
    EXPECT_NE(f32.mse, f64.mse);
  }
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.training.steps = 0;
  cell.seeds = {3};
  const RunResult f64 = train_cell(cell, small_data(SystemKind::kHarmonic))[0];
  cell.training.precision = Precision::kFloat32;
  const RunResult f32 = train_cell(cell, small_data(SystemKind::kHarmonic))[0];
  ASSERT_EQ(f32.weights.size(), f64.weights.size());
  for (std::size_t i = 0; i < f64.weights.size(); ++i) {
    EXPECT_EQ(f32.weights[i], static_cast<double>(static_cast<float>(f64.weights[i]))) << i;
  }
}

// Float32 training keeps the trainer's other guarantees: a checkpoint's MSE
// is bitwise a shorter run's and changes nothing, and a member whose loss
// turns non-finite is frozen while the others train as they would alone.
TEST(TrainerTest, Float32KeepsCheckpointsAndFreezing) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.integrator = IntegratorKind::kDg;
  cell.training.precision = Precision::kFloat32;
  cell.training.steps = 40;
  cell.training.eval_every = 20;
  cell.seeds = {2, 5};
  const auto plain = train_cell(cell, small_data(SystemKind::kDuffing));
  cell.training.checkpoints = {20, 40};
  const auto with = train_cell(cell, small_data(SystemKind::kDuffing));
  CellSpec shorter = cell;
  shorter.training.checkpoints.clear();
  shorter.training.steps = 20;
  const auto run = train_cell(shorter, small_data(SystemKind::kDuffing));
  for (std::size_t e = 0; e < 2; ++e) {
    EXPECT_EQ(with[e].mse, plain[e].mse) << e;
    EXPECT_EQ(with[e].weights, plain[e].weights) << e;
    ASSERT_EQ(with[e].checkpoint_mse.size(), 2u);
    EXPECT_EQ(with[e].checkpoint_mse[0], run[e].mse) << e;
    EXPECT_EQ(with[e].checkpoint_mse[1], plain[e].mse) << e;
  }
  // PHNN-S at lr 1e3 overflows float32 (H is quadratic in the weights) in
  // seeds 0, 1, 3 and 4 within 50 steps, not 2 and 5 (measured; float64 in
  // none).
  CellSpec blow_up;
  blow_up.model = ModelKind::kPhnnS;
  blow_up.training.precision = Precision::kFloat32;
  blow_up.training.steps = 50;
  blow_up.training.eval_every = 10;
  blow_up.training.learning_rate = 1e3;
  blow_up.seeds = {0, 1, 2, 3, 4, 5};
  const auto r = train_cell(blow_up, small_data(SystemKind::kHarmonic));
  ASSERT_THAT(r[0].message, HasSubstr("training loss non-finite"));
  ASSERT_EQ(r[2].status, RunStatus::kDone);
  for (int seed : {0, 2}) {
    CellSpec alone = blow_up;
    alone.seeds = {seed};
    const RunResult a = train_cell(alone, small_data(SystemKind::kHarmonic))[0];
    const RunResult& s = r[static_cast<std::size_t>(seed)];
    EXPECT_EQ(a.status, s.status) << seed;
    EXPECT_EQ(a.message, s.message) << seed;
    EXPECT_EQ(a.best_step, s.best_step) << seed;
    EXPECT_EQ(a.weights, s.weights) << seed;
    EXPECT_EQ(a.trace.size(), s.trace.size()) << seed;
    EXPECT_EQ(a.mse, s.mse) << seed;
  }
}

// A checkpoint's inference MSE is bitwise the MSE of a run trained for that
// many steps (same first steps, same validations, same best weights), and
// checkpoints leave the run's own results bitwise unchanged.
TEST(TrainerTest, CheckpointsEqualShorterRunsAndChangeNothing) {
  for (IntegratorKind integrator : {IntegratorKind::kRk2, IntegratorKind::kDg}) {
    CellSpec cell;
    cell.model = ModelKind::kPhnnS;
    cell.integrator = integrator;
    cell.n_train = 100;
    cell.training.steps = 600;
    cell.training.eval_every = 100;
    cell.seeds = {2, 5};
    const auto plain = train_cell(cell, small_data(SystemKind::kDuffing));
    cell.training.checkpoints = {200, 400, 600};
    const auto with = train_cell(cell, small_data(SystemKind::kDuffing));
    for (std::size_t e = 0; e < 2; ++e) {
      const std::string tag = to_string(integrator) + " member " + std::to_string(e);
      EXPECT_EQ(with[e].mse, plain[e].mse) << tag;
      EXPECT_EQ(with[e].best_step, plain[e].best_step) << tag;
      EXPECT_EQ(with[e].trajectory_errors, plain[e].trajectory_errors) << tag;
      ASSERT_EQ(with[e].checkpoint_steps, (std::vector<int>{200, 400, 600})) << tag;
      EXPECT_EQ(with[e].checkpoint_mse[2], plain[e].mse) << tag;
      ASSERT_EQ(with[e].checkpoint_train_seconds.size(), 3u);
      EXPECT_LT(with[e].checkpoint_train_seconds[0], with[e].checkpoint_train_seconds[2]) << tag;
    }
    for (int budget : {200, 400}) {
      CellSpec shorter = cell;
      shorter.training.checkpoints.clear();
      shorter.training.steps = budget;
      const auto run = train_cell(shorter, small_data(SystemKind::kDuffing));
      for (std::size_t e = 0; e < 2; ++e) {
        EXPECT_EQ(with[e].checkpoint_mse[budget / 200 - 1], run[e].mse)
            << to_string(integrator) << " member " << e << " budget " << budget;
      }
    }
  }
}

// A NaN or inf anywhere in the data a cell uses is refused before training
// with the set and index named (instead of NaN losses freezing every member).
TEST(TrainerTest, NonFiniteDataIsRefusedWithItsPlace) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnJr;
  cell.n_train = 25;
  cell.training.steps = 10;
  cell.seeds = {0};
  {
    SystemAndData data = small_data(SystemKind::kHarmonic);
    data.data.train.x_next[3](1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THAT([&] { train_cell(cell, data); },
                ThrowsMessage<std::invalid_argument>(HasSubstr("training pair 3 has a non-finite")));
    data.data.train.x_next[3](1) = 0.0;
    data.data.train.x[30](0) = std::numeric_limits<double>::infinity();  // beyond n_train: unused
    EXPECT_NO_THROW(train_cell(cell, data));
  }
  {
    SystemAndData data = small_data(SystemKind::kHarmonic);
    data.data.validation.u[7](0) = std::numeric_limits<double>::infinity();
    EXPECT_THAT([&] { train_cell(cell, data); },
                ThrowsMessage<std::invalid_argument>(HasSubstr("validation pair 7")));
  }
  {
    SystemAndData data = small_data(SystemKind::kHarmonic);
    data.data.inference.states[2][40](0) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THAT([&] { train_cell(cell, data); },
                ThrowsMessage<std::invalid_argument>(
                    HasSubstr("inference trajectory 2 has a non-finite value (input u or the state at step 40)")));
  }
}

// Checkpoints must be validation steps within the run, increasing.
TEST(TrainerTest, CheckpointsAreValidated) {
  TrainerOptions options;
  options.steps = 1000;
  options.eval_every = 500;
  for (std::vector<int> bad : {std::vector<int>{250}, {500, 500}, {1500}, {0}}) {
    options.checkpoints = bad;
    EXPECT_THROW(options.validate(), std::invalid_argument) << bad[0];
  }
  options.checkpoints = {500, 1000};
  EXPECT_NO_THROW(options.validate());
}

// Learning smoke test: every model x integrator on every system reduces the
// validation loss >= 5x within 5 000 steps at N_train = 100, median over the
// paper's 10 seeds. Single seeds can stall on a plateau: for Duffing
// PHNN-S-DG seeds 0, 1 and 4 sit at 3.6-4.9x after 5 000 steps while the
// other 7 reach 21-49x (measured; PHNN-S-RK2 behaves alike).
TEST(TrainerTest, EveryModelLearnsEverySystem) {
  const std::pair<ModelKind, IntegratorKind> models[] = {
      {ModelKind::kNode, IntegratorKind::kRk2},  {ModelKind::kPhnnJr, IntegratorKind::kDg},
      {ModelKind::kPhnnJr, IntegratorKind::kRk2}, {ModelKind::kPhnnS, IntegratorKind::kDg},
      {ModelKind::kPhnnS, IntegratorKind::kRk2}};
  for (SystemKind sys : all_systems()) {
    for (const auto& [model, integrator] : models) {
      CellSpec cell;
      cell.model = model;
      cell.integrator = integrator;
      cell.n_train = 100;
      cell.training.steps = 5000;
      cell.seeds = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
      const auto r = train_cell(cell, small_data(sys));
      std::vector<double> reductions;
      for (const auto& run : r) {
        reductions.push_back(run.trace.front().validation_loss / run.best_validation_loss);
        EXPECT_TRUE(std::isfinite(run.mse));
      }
      std::sort(reductions.begin(), reductions.end());
      const double median = 0.5 * (reductions[4] + reductions[5]);
      EXPECT_GE(median, 5.0) << to_string(sys) << " " << model_label(model, integrator);
      RecordProperty(to_string(sys) + "_" + model_label(model, integrator),
                     "min " + std::to_string(reductions.front()) + " median " +
                         std::to_string(median) + " max " + std::to_string(reductions.back()));
    }
  }
}

TEST(TrainerTest, ResultsCarryTraceAndFigureTrajectories) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.integrator = IntegratorKind::kRk2;
  cell.training.steps = 30;
  cell.training.eval_every = 10;
  cell.seeds = {0, 1};
  const auto r = train_cell(cell, small_data(SystemKind::kSelfSustained));
  ASSERT_EQ(r.size(), 2u);
  ASSERT_EQ(r[0].trace.size(), 4u);  // steps 0, 10, 20, 30
  EXPECT_EQ(r[0].trace.back().step, 30);
  EXPECT_EQ(r[0].trajectory_errors.size(), 4u);
  EXPECT_EQ(r[0].figure_prediction_05.size(), 2u * 501u);
  EXPECT_EQ(r[0].figure_reference_075.size(), 2u * 501u);
  EXPECT_EQ(r[0].parameter_count, 852);
  // The figure reference starts at H(x0) = 0.5 J.
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kSelfSustained));
  EXPECT_NEAR(osc.hamiltonian(Vec2(r[0].figure_reference_05[0], r[0].figure_reference_05[1])), 0.5, 1e-12);
  // The MSE is the mean of the per-trajectory errors (Eq. 31).
  double sum = 0;
  for (double e : r[0].trajectory_errors) sum += e;
  EXPECT_NEAR(r[0].mse, sum / 4.0, 1e-15 * sum);
}

// Far from the usual regime, stacking stays exact in float64: at lr 1e3 the
// NODE weights grow large (tanh saturates, so no member's loss becomes
// non-finite: measured up to lr 1e250, where all diverge at once; the
// freezing of one diverged member among others is tested in float32,
// Float32KeepsCheckpointsAndFreezing). Each member of a stack of 4 equals its
// seed trained alone, bitwise. The final weights are compared (the best
// validation point at this rate is step 0, whose weights say nothing).
TEST(TrainerTest, HugeLearningRateKeepsStackingExact) {
  CellSpec cell;
  cell.model = ModelKind::kNode;
  cell.training.steps = 50;
  cell.training.eval_every = 10;
  cell.training.learning_rate = 1e3;
  cell.training.inference_weights = InferenceWeights::kFinal;
  cell.seeds = {0, 1, 2, 3};
  const auto r = train_cell(cell, small_data(SystemKind::kHarmonic));
  for (std::size_t e = 0; e < cell.seeds.size(); ++e) {
    CellSpec alone = cell;
    alone.seeds = {cell.seeds[e]};
    const RunResult a = train_cell(alone, small_data(SystemKind::kHarmonic))[0];
    EXPECT_EQ(a.status, r[e].status) << e;
    EXPECT_EQ(a.best_step, r[e].best_step) << e;
    EXPECT_EQ(a.weights, r[e].weights) << e;
    EXPECT_EQ(a.mse, r[e].mse) << e;
  }
  // Far from the usual regime: some final weight is > 10 (initial ones are < 1).
  double largest = 0.0;
  for (const RunResult& run : r) {
    for (double w : run.weights) largest = std::max(largest, std::abs(w));
  }
  EXPECT_GT(largest, 10.0);
}

// loss_norm applies to the logged training loss and to the validation loss
// (which picks the best weights): at step 0 (same weights) sum-l1 is twice
// mean-l1 and mse is the mean of squares, on every model.
TEST(TrainerTest, LossNormAppliesToTrainingAndValidationLoss) {
  for (ModelKind model : {ModelKind::kNode, ModelKind::kPhnnS}) {
    CellSpec cell;
    cell.model = model;
    cell.integrator = IntegratorKind::kRk2;
    cell.training.steps = 0;
    cell.seeds = {3};
    std::map<LossNorm, TracePoint> first;
    for (LossNorm norm : all_loss_norms()) {
      cell.training.loss_norm = norm;
      first[norm] = train_cell(cell, small_data(SystemKind::kHarmonic))[0].trace.at(0);
    }
    const TracePoint& l1 = first[LossNorm::kMeanL1];
    EXPECT_LE(rel(first[LossNorm::kSumL1].validation_loss, 2.0 * l1.validation_loss), 1e-14);
    EXPECT_LE(rel(first[LossNorm::kSumL1].train_loss, 2.0 * l1.train_loss), 1e-14);
    // Jensen: mean(e^2) >= mean(|e|)^2, with equality only for constant |e|.
    EXPECT_GT(first[LossNorm::kMse].validation_loss, l1.validation_loss * l1.validation_loss);
  }
}

// dg_structure_point reaches the model of a PHNN-JR-DG cell: with the same
// initial weights, R at the start changes both the validation loss
// (training's DG step) and the inference MSE (the Newton rollouts).
TEST(TrainerTest, DgStructurePointAppliesToTrainingAndInference) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnJr;
  cell.integrator = IntegratorKind::kDg;
  cell.training.steps = 0;
  cell.seeds = {2};
  const auto midpoint = train_cell(cell, small_data(SystemKind::kDuffing))[0];
  cell.training.dg_structure_point = DgStructurePoint::kStart;
  const auto start = train_cell(cell, small_data(SystemKind::kDuffing))[0];
  EXPECT_GT(rel(start.trace.at(0).validation_loss, midpoint.trace.at(0).validation_loss), 1e-9);
  EXPECT_GT(rel(start.mse, midpoint.mse), 1e-9);
  EXPECT_EQ(start.trace.at(0).kappa, midpoint.trace.at(0).kappa);  // continuous field: unchanged
}

// inference_weights = final rolls out the weights after the last step: the
// training (trace) is bitwise that of the default, the kept step is the last,
// and the weights equal those a default run validating only at step 0 and
// at the last step keeps (its best is its last validation there), bitwise.
// The learning rate is high enough that some member's best validation point
// is not the last one, so the two settings differ.
TEST(TrainerTest, InferenceWeightsFinalRollsOutTheLastWeights) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.integrator = IntegratorKind::kRk2;
  cell.training.steps = 300;
  cell.training.eval_every = 100;
  cell.training.learning_rate = 3e-2;
  cell.seeds = {1, 2, 3};
  const SystemAndData& data = small_data(SystemKind::kHarmonic);
  const auto best = train_cell(cell, data);
  cell.training.inference_weights = InferenceWeights::kFinal;
  const auto final = train_cell(cell, data);
  CellSpec coarse = cell;
  coarse.training.inference_weights = InferenceWeights::kBestValidation;
  coarse.training.eval_every = 300;
  const auto ends = train_cell(coarse, data);
  int differ = 0;
  for (std::size_t e = 0; e < 3; ++e) {
    SCOPED_TRACE("member " + std::to_string(e));
    ASSERT_EQ(final[e].trace.size(), best[e].trace.size());
    for (std::size_t i = 0; i < best[e].trace.size(); ++i) {
      EXPECT_EQ(final[e].trace[i].validation_loss, best[e].trace[i].validation_loss) << i;
    }
    EXPECT_EQ(final[e].best_step, 300);
    EXPECT_EQ(final[e].best_validation_loss, final[e].trace.back().validation_loss);
    ASSERT_EQ(ends[e].best_step, 300) << "precondition: the last step beats step 0";
    EXPECT_EQ(final[e].weights, ends[e].weights);
    EXPECT_EQ(final[e].mse, ends[e].mse);
    if (best[e].best_step != 300) {
      ++differ;
      EXPECT_NE(final[e].weights, best[e].weights);
    }
  }
  EXPECT_GE(differ, 1) << "no member's best validation point came before the last step";
}

TEST(CellSpecTest, RejectsNodeWithDgAndBadCounts) {
  CellSpec cell;
  cell.model = ModelKind::kNode;
  cell.integrator = IntegratorKind::kDg;
  EXPECT_THAT([&] { cell.validate(small_data(SystemKind::kHarmonic).data); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("integrator = dg with model = node")));
  cell.integrator = IntegratorKind::kRk2;
  cell.n_train = 401;
  EXPECT_THAT([&] { cell.validate(small_data(SystemKind::kHarmonic).data); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("n_train = 401")));
  cell.n_train = 25;
  cell.training.steps = -1;
  EXPECT_THAT([&] { cell.validate(small_data(SystemKind::kHarmonic).data); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("steps = -1")));
}

}  // namespace
}  // namespace phnn

namespace phnn {
namespace {

// The loss passes without gradients take their steps in chunks of pairs
// (trainer.cpp): the trace (validation and training-set losses) and the
// MSE are bitwise those of one pass over all pairs, for chunks that divide
// the 2 500 validation pairs and for ragged ones, on both model stacks.
TEST(TrainerTest, ChunkedLossPassesAreOnePassToTheBit) {
  struct Case {
    ModelKind model;
    IntegratorKind integrator;
    Regularizer reg;
    Precision precision;
    bool general;
  };
  const std::unique_ptr<PhSystem> coupled = load_system_file(
      std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/coupled-duffing.toml");
  DatasetOptions options;
  options.num_inference = 2;
  const PhSystemData coupled_data = make_ph_system_data(*coupled, options, 100);
  const Case cases[] = {
      {ModelKind::kPhnnJr, IntegratorKind::kDg, Regularizer::kCn, Precision::kFloat64, false},
      {ModelKind::kPhnnS, IntegratorKind::kRk2, Regularizer::kNone, Precision::kFloat64, false},
      {ModelKind::kNode, IntegratorKind::kRk4, Regularizer::kNone, Precision::kFloat64, false},
      {ModelKind::kPhnnS, IntegratorKind::kDg4, Regularizer::kNone, Precision::kFloat64, false},
      {ModelKind::kPhnnJr, IntegratorKind::kRk2, Regularizer::kNone, Precision::kFloat32, false},
      {ModelKind::kPhnnS, IntegratorKind::kDg, Regularizer::kSn, Precision::kFloat64, true},
      {ModelKind::kPhnnJr, IntegratorKind::kRk2, Regularizer::kNone, Precision::kFloat64, true}};
  for (const Case& c : cases) {
    CellSpec cell;
    cell.model = c.model;
    cell.integrator = c.integrator;
    cell.regularizer = c.reg;
    cell.n_train = 100;
    cell.training.precision = c.precision;
    cell.training.steps = 2;
    cell.training.eval_every = 1;
    cell.seeds = {1, 2};
    std::vector<std::vector<RunResult>> runs;
    for (const int64_t chunk : {int64_t{1} << 40, int64_t{500}, int64_t{333}}) {
      internal::set_step_chunk(chunk);
      runs.push_back(c.general ? phnn::train_cell(cell, coupled_data, *coupled)
                               : train_cell(cell, small_data(SystemKind::kDuffing)));
    }
    internal::set_step_chunk(500);
    const std::string name = model_label(c.model, c.integrator) + " " + to_string(c.reg);
    for (std::size_t k = 1; k < runs.size(); ++k) {
      for (std::size_t e = 0; e < runs[0].size(); ++e) {
        const RunResult &a = runs[0][e], &b = runs[k][e];
        ASSERT_EQ(a.trace.size(), b.trace.size()) << name;
        for (std::size_t i = 0; i < a.trace.size(); ++i) {
          EXPECT_EQ(a.trace[i].validation_loss, b.trace[i].validation_loss) << name << " " << i;
          EXPECT_EQ(a.trace[i].train_loss, b.trace[i].train_loss) << name << " " << i;
        }
        EXPECT_EQ(a.mse, b.mse) << name;
        EXPECT_EQ(a.weights, b.weights) << name;
      }
    }
  }
}

}  // namespace
}  // namespace phnn
