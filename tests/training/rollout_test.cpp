// tests/training/rollout_test.cpp — the inference rollouts of a cell
// (training/rollout.cpp): DG4's Newton steps taken in chunks of rows give
// the bits of one step over all rows; the chunk rule.
#include "training/rollout.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "phnn/training/trainer.h"
#include "training/small_data.h"

namespace phnn {
namespace {

using testing_util::small_data;
using testing_util::train_cell;

// DG4 rollouts take their Newton steps in chunks of rows (rollout.cpp): the
// inference results are bitwise those of all rows at once, for chunks of 1
// and 4 of the 4 inference + 2 figure rows, PHNN-S and PHNN-JR, after 30
// training steps.
TEST(RolloutTest, ChunkedDg4RolloutsAreOneRolloutToTheBit) {
  for (ModelKind model : {ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    CellSpec cell;
    cell.model = model;
    cell.integrator = IntegratorKind::kDg4;
    cell.n_train = 50;
    cell.training.steps = 30;
    cell.training.eval_every = 30;
    cell.seeds = {1, 2};
    std::vector<std::vector<RunResult>> runs;
    for (const int64_t chunk : {int64_t{1} << 40, int64_t{1}, int64_t{4}}) {
      set_dg4_rollout_chunk(chunk);
      runs.push_back(train_cell(cell, small_data(SystemKind::kDuffing)));
    }
    set_dg4_rollout_chunk(0);
    for (std::size_t k = 1; k < runs.size(); ++k) {
      for (std::size_t e = 0; e < runs[0].size(); ++e) {
        const RunResult &a = runs[0][e], &b = runs[k][e];
        ASSERT_TRUE(std::isfinite(a.mse)) << to_string(model);
        EXPECT_EQ(a.mse, b.mse) << to_string(model) << " chunking " << k;
        EXPECT_EQ(a.trajectory_errors, b.trajectory_errors) << to_string(model);
        EXPECT_EQ(a.newton_failures, b.newton_failures) << to_string(model);
        EXPECT_EQ(a.figure_prediction_05, b.figure_prediction_05) << to_string(model);
      }
    }
  }
}

// Only large jets are chunked: n_x = 8 with 10 members in chunks of 40
// rows, the paper's 2-state cells and n_x <= 6 with 10 members not (their
// 102 rollout rows in one chunk), never fewer than 16 rows.
TEST(RolloutTest, Dg4ChunksOnlyLargeJets) {
  EXPECT_EQ(dg4_chunk_rows(10, 8, 1), 40);
  EXPECT_GT(dg4_chunk_rows(10, 2, 1), 500);
  EXPECT_GE(dg4_chunk_rows(10, 6, 1), 102);
  EXPECT_EQ(dg4_chunk_rows(100, 10, 3), 16);
}

}  // namespace
}  // namespace phnn
