// tests/training/cell_checkpoint_test.cpp — saved training states inside a
// cell (CellCheckpointing): a cell stopped and resumed, once or twice, ends
// bitwise as the uninterrupted cell (weights, MSE, trace, budget
// checkpoints, frozen members), on built-in and file-defined systems, in
// float64 and float32; a rung's final state ([search]) goes on to a larger
// step budget bitwise as training straight through; a state that does not
// fit the cell is refused.
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/systems/system_file.h"
#include "phnn/training/trainer.h"
#include "training/small_data.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

const testing_util::SystemAndData& duffing() { return testing_util::small_data(SystemKind::kDuffing); }
const testing_util::SystemAndData& harmonic() { return testing_util::small_data(SystemKind::kHarmonic); }
using testing_util::train_cell;

using Train = std::function<std::vector<RunResult>(const CellCheckpointing*)>;

// Trains through `train`, stopping after each step listed in `stops` (as a
// signal would) and resuming from the saved state; returns the results and
// the steps the states were saved at.
std::vector<RunResult> stopped_and_resumed(const Train& train, const std::vector<int>& stops,
                                           std::vector<int>* saved_at) {
  std::string state;
  int polls = 0;
  for (std::size_t k = 0;; ++k) {
    CellCheckpointing c;
    c.resume_from = state;
    c.save = [&](const std::string& s, int step) {
      state = s;
      saved_at->push_back(step);
    };
    c.stop_requested = [&] { return k < stops.size() && ++polls == stops[k]; };
    try {
      return train(&c);
    } catch (const CellInterrupted& e) {
      EXPECT_EQ(e.step, stops[k]);
      polls = e.step;  // polls count steps: the next run goes on from here
    }
  }
}

// Everything a run's result holds except its timings, bitwise.
void expect_same_results(const std::vector<RunResult>& a, const std::vector<RunResult>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t e = 0; e < a.size(); ++e) {
    SCOPED_TRACE("member " + std::to_string(e));
    EXPECT_EQ(a[e].status, b[e].status);
    EXPECT_EQ(a[e].message, b[e].message);
    EXPECT_EQ(a[e].mse, b[e].mse);
    EXPECT_EQ(a[e].trajectory_errors, b[e].trajectory_errors);
    EXPECT_EQ(a[e].weights, b[e].weights);
    EXPECT_EQ(a[e].best_step, b[e].best_step);
    EXPECT_EQ(a[e].best_validation_loss, b[e].best_validation_loss);
    EXPECT_EQ(a[e].checkpoint_steps, b[e].checkpoint_steps);
    EXPECT_EQ(a[e].checkpoint_mse, b[e].checkpoint_mse);
    EXPECT_EQ(a[e].figure_prediction_05, b[e].figure_prediction_05);
    ASSERT_EQ(a[e].trace.size(), b[e].trace.size());
    for (std::size_t i = 0; i < a[e].trace.size(); ++i) {
      EXPECT_EQ(a[e].trace[i].step, b[e].trace[i].step);
      EXPECT_EQ(a[e].trace[i].train_loss, b[e].trace[i].train_loss);
      EXPECT_EQ(a[e].trace[i].validation_loss, b[e].trace[i].validation_loss);
      EXPECT_EQ(a[e].trace[i].kappa, b[e].trace[i].kappa);
    }
  }
}

// PHNN-JR-DG + CN on Duffing, N_train 100 > batch 64: the batch order's
// position inside an epoch, Adam's moments and the best weights carry over;
// stops before, at and after a budget checkpoint and a validation point.
TEST(CellCheckpointTest, StoppedTwiceEndsBitwiseAsUninterrupted) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnJr;
  cell.integrator = IntegratorKind::kDg;
  cell.n_train = 100;
  cell.regularizer = Regularizer::kCn;
  cell.training.steps = 60;
  cell.training.eval_every = 10;
  cell.training.checkpoints = {20, 60};
  cell.seeds = {3, 8};
  const Train train = [&](const CellCheckpointing* c) {
    return train_cell(cell, duffing(), {}, nullptr, c);
  };
  const auto plain = train(nullptr);
  std::vector<int> saved_at;
  const auto resumed = stopped_and_resumed(train, {7, 20, 33}, &saved_at);
  EXPECT_EQ(saved_at, (std::vector<int>{7, 20, 33}));
  expect_same_results(resumed, plain);
}

// A stop asked once training is over — before the inference rollouts (poll
// steps + 1) or during them (polls steps + 2, + 4: every 32 rollout steps) —
// saves the state of the last step; the cell goes on from it straight to
// inference and ends bitwise as uninterrupted. PHNN-S-DG: its Newton
// rollouts are the long ones.
TEST(CellCheckpointTest, AStopDuringInferenceGoesOnStraightToInference) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.integrator = IntegratorKind::kDg;
  cell.n_train = 25;
  cell.training.steps = 30;
  cell.training.eval_every = 10;
  cell.seeds = {1, 2};
  const Train train = [&](const CellCheckpointing* c) {
    return train_cell(cell, duffing(), {}, nullptr, c);
  };
  const auto plain = train(nullptr);
  for (int stop_at : {31, 32, 34}) {
    SCOPED_TRACE("stop at poll " + std::to_string(stop_at));
    std::string state;
    std::vector<int> saved_at;
    int polls = 0;
    CellCheckpointing c;
    c.save = [&](const std::string& s, int step) {
      state = s;
      saved_at.push_back(step);
    };
    c.stop_requested = [&] { return ++polls == stop_at; };
    try {
      train(&c);
      ADD_FAILURE() << "not stopped";
    } catch (const CellInterrupted& e) {
      EXPECT_EQ(e.step, 30);
    }
    EXPECT_EQ(polls, stop_at);
    EXPECT_EQ(saved_at, std::vector<int>{30});
    CellCheckpointing r;
    r.resume_from = state;
    r.save = [&](const std::string&, int step) { saved_at.push_back(step); };
    r.stop_requested = [] { return false; };
    expect_same_results(train(&r), plain);
    EXPECT_EQ(saved_at, std::vector<int>{30});  // nothing more to save
  }
}

// Float32 training with a member that diverges (frozen) before the stop:
// the frozen weights and the divergence step survive the restart.
TEST(CellCheckpointTest, FrozenMembersAndFloat32Survive) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.training.precision = Precision::kFloat32;
  cell.training.steps = 50;
  cell.training.eval_every = 10;
  cell.training.learning_rate = 1e3;  // seeds 0 and 1 overflow within 50 steps
  cell.seeds = {0, 1, 2};
  const Train train = [&](const CellCheckpointing* c) {
    return train_cell(cell, harmonic(), {}, nullptr, c);
  };
  const auto plain = train(nullptr);
  ASSERT_THAT(plain[0].message, HasSubstr("training loss non-finite"));
  std::vector<int> saved_at;
  expect_same_results(stopped_and_resumed(train, {45}, &saved_at), plain);
}

// A file-defined system (n_x = 4) through the general models, NODE RK4.
TEST(CellCheckpointTest, FileDefinedSystemResumesBitwise) {
  static const auto system =
      load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/coupled-duffing.toml");
  DatasetOptions options;
  options.num_validation = 30;
  options.num_inference = 2;
  const PhSystemData data = make_ph_system_data(*system, options, 25);
  for (ModelKind model : {ModelKind::kNode, ModelKind::kPhnnJr}) {
    CellSpec cell;
    cell.model = model;
    cell.integrator = IntegratorKind::kRk4;
    cell.n_train = 25;
    cell.training.steps = 30;
    cell.training.eval_every = 10;
    cell.seeds = {1, 2};
    const Train train = [&](const CellCheckpointing* c) {
      return train_cell(cell, data, *system, {}, nullptr, c);
    };
    std::vector<int> saved_at;
    expect_same_results(stopped_and_resumed(train, {12}, &saved_at), train(nullptr));
  }
}

// interval_s > 0 saves on time without stopping, never after the last step,
// and changes no result; the last state saved resumes to the same results.
TEST(CellCheckpointTest, TimedSavesChangeNothing) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnJr;
  cell.n_train = 100;
  cell.training.steps = 25;
  cell.training.eval_every = 5;
  cell.seeds = {0, 1};
  const auto plain = train_cell(cell, duffing());
  std::vector<int> saved_at;
  std::vector<std::string> states;
  CellCheckpointing c;
  c.interval_s = 1e-12;  // every step
  c.save = [&](const std::string& s, int step) {
    states.push_back(s);
    saved_at.push_back(step);
  };
  expect_same_results(train_cell(cell, duffing(), {}, nullptr, &c), plain);
  ASSERT_EQ(saved_at.size(), 24u);
  EXPECT_EQ(saved_at.front(), 1);
  EXPECT_EQ(saved_at.back(), 24);
  CellCheckpointing resume;
  resume.resume_from = states[10];
  expect_same_results(train_cell(cell, duffing(), {}, nullptr, &resume), plain);
}

// Trains `cell` at each budget of `budgets` in turn, each going on from the
// final state of the one before (save_final), as [search] rungs do.
std::vector<RunResult> through_rungs(CellSpec cell, const std::vector<int>& budgets,
                                     const std::function<std::vector<RunResult>(
                                         const CellSpec&, const CellCheckpointing*)>& train) {
  std::string state;
  std::vector<RunResult> results;
  for (int budget : budgets) {
    cell.training.steps = budget;
    CellCheckpointing c;
    c.resume_from = state;
    c.save = [](const std::string&, int) {};
    c.save_final = [&](const std::string& s, int) { state = s; };
    results = train(cell, &c);
  }
  return results;
}

// [search] rungs: PHNN-JR-DG + CN with batches (N_train 100 > 64), NODE-RK2,
// and float32 PHNN-S whose members diverge (frozen, or all of them dead
// before the rung ends) go on from 20 to 40 to 60 steps bitwise as 60
// steps straight through.
TEST(CellCheckpointTest, ARungsFinalStateGoesOnBitwiseToALargerBudget) {
  CellSpec jr;
  jr.model = ModelKind::kPhnnJr;
  jr.integrator = IntegratorKind::kDg;
  jr.n_train = 100;
  jr.regularizer = Regularizer::kCn;
  jr.training.eval_every = 10;
  jr.seeds = {3, 8};
  CellSpec node = jr;
  node.model = ModelKind::kNode;
  node.integrator = IntegratorKind::kRk2;
  node.regularizer = Regularizer::kNone;
  CellSpec diverging;
  diverging.model = ModelKind::kPhnnS;
  diverging.training.precision = Precision::kFloat32;
  diverging.training.eval_every = 10;
  diverging.training.learning_rate = 1e3;
  diverging.seeds = {0, 1, 2};
  CellSpec all_dead = diverging;
  all_dead.seeds = {0, 1};
  for (const CellSpec* cell : {&jr, &node, &diverging, &all_dead}) {
    const auto& data = cell == &jr || cell == &node ? duffing() : harmonic();
    const auto train = [&](const CellSpec& c, const CellCheckpointing* k) {
      return train_cell(c, data, {}, nullptr, k);
    };
    CellSpec straight = *cell;
    straight.training.steps = 60;
    const auto plain = train(straight, nullptr);
    if (cell == &diverging || cell == &all_dead) {  // the members the comment says diverge do
      for (std::size_t e = 0; e < 2; ++e) {
        EXPECT_THAT(plain[e].message, HasSubstr("training loss non-finite")) << e;
        EXPECT_LT(plain[e].trace.back().step, 20) << e;
      }
    }
    expect_same_results(through_rungs(*cell, {20, 40, 60}, train), plain);
  }
}

// skip_inference (a rung before the last): no rollouts, MSE NaN, and every
// training result (weights, best step and loss, trace, status) as with them.
TEST(CellCheckpointTest, ARungBeforeTheLastSkipsInferenceAndChangesNothingElse) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnJr;
  cell.integrator = IntegratorKind::kDg;
  cell.training.steps = 30;
  cell.training.eval_every = 10;
  cell.seeds = {0, 1};
  const auto full = train_cell(cell, harmonic());
  cell.training.skip_inference = true;
  const auto skipped = train_cell(cell, harmonic());
  ASSERT_EQ(skipped.size(), full.size());
  for (std::size_t e = 0; e < full.size(); ++e) {
    EXPECT_TRUE(std::isnan(skipped[e].mse));
    EXPECT_TRUE(skipped[e].trajectory_errors.empty());
    EXPECT_TRUE(skipped[e].figure_prediction_05.empty());
    EXPECT_THAT(skipped[e].message, HasSubstr("No inference"));
    EXPECT_EQ(skipped[e].status, full[e].status);
    EXPECT_EQ(skipped[e].weights, full[e].weights);
    EXPECT_EQ(skipped[e].best_step, full[e].best_step);
    EXPECT_EQ(skipped[e].best_validation_loss, full[e].best_validation_loss);
    ASSERT_EQ(skipped[e].trace.size(), full[e].trace.size());
    EXPECT_EQ(skipped[e].trace.back().validation_loss, full[e].trace.back().validation_loss);
  }
}

// A rung's state goes on only to a larger budget that is a validation step
// of the cell, without budget checkpoints.
TEST(CellCheckpointTest, ARungsStateFitsOnlyALargerValidationStep) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.training.steps = 20;
  cell.training.eval_every = 10;
  cell.seeds = {0, 1};
  std::string state;
  CellCheckpointing c;
  c.save = [](const std::string&, int) {};
  c.save_final = [&](const std::string& s, int) { state = s; };
  train_cell(cell, harmonic(), {}, nullptr, &c);
  ASSERT_FALSE(state.empty());
  auto outcome = [&](CellSpec other) {
    CellCheckpointing r;
    r.resume_from = state;
    try {
      train_cell(other, harmonic(), {}, nullptr, &r);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CellSpec larger = cell;
  larger.training.steps = 30;
  EXPECT_EQ(outcome(larger), "accepted");
  CellSpec smaller = cell;
  smaller.training.steps = 10;
  EXPECT_THAT(outcome(smaller), HasSubstr("another cell"));
  CellSpec off_step = cell;  // 20 is no validation step at eval_every 15
  off_step.training.steps = 45;
  off_step.training.eval_every = 15;
  EXPECT_THAT(outcome(off_step), HasSubstr("another cell"));
  CellSpec with_checkpoints = larger;
  with_checkpoints.training.checkpoints = {30};
  EXPECT_THAT(outcome(with_checkpoints), HasSubstr("another cell"));
}

// A state of other seeds, other steps or cut short is refused before training.
TEST(CellCheckpointTest, AStateOfAnotherCellIsRefused) {
  CellSpec cell;
  cell.model = ModelKind::kPhnnS;
  cell.training.steps = 10;
  cell.seeds = {0, 1};
  std::string state;
  CellCheckpointing c;
  c.save = [&](const std::string& s, int) { state = s; };
  c.stop_requested = [] { return true; };
  EXPECT_THROW(train_cell(cell, harmonic(), {}, nullptr, &c), CellInterrupted);
  ASSERT_FALSE(state.empty());
  auto refused = [&](CellSpec other, const std::string& bytes) {
    CellCheckpointing r;
    r.resume_from = bytes;
    try {
      train_cell(other, harmonic(), {}, nullptr, &r);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CellSpec other_seeds = cell;
  other_seeds.seeds = {0, 2};
  EXPECT_THAT(refused(other_seeds, state), HasSubstr("another cell"));
  CellSpec other_steps = cell;
  other_steps.training.steps = 11;
  EXPECT_THAT(refused(other_steps, state), HasSubstr("another cell"));
  CellSpec other_model = cell;
  other_model.model = ModelKind::kPhnnJr;
  EXPECT_THAT(refused(other_model, state), HasSubstr("another cell"));
  EXPECT_THAT(refused(cell, state.substr(0, state.size() - 3)), HasSubstr("training state"));
  EXPECT_THAT(refused(cell, state + "x"), HasSubstr("left over"));
}

}  // namespace
}  // namespace phnn
