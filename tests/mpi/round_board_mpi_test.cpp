// tests/mpi/round_board_mpi_test.cpp — RoundBoard on 1, 2 and 3 ranks: every
// rank reads what every other posted, bit for bit (MSEs including inf and a
// subnormal), runs never posted stay as the reader had them, and each claim
// goes to exactly one rank.
#include <mpi.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "phnn/sweep/round_board.h"

namespace phnn {
namespace {

int rank_of() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int size_of() {
  int s = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

// Run r's outcome as rank r % size posts it.
RunStatus status_of(int r) { return r % 4 == 3 ? RunStatus::kDiverged : RunStatus::kDone; }
double mse_of(int r) {
  if (r == 5) return std::numeric_limits<double>::infinity();
  if (r == 6) return std::numeric_limits<double>::denorm_min();
  return 1e-3 * (r + 1) / 3.0;
}

TEST(RoundBoardMpiTest, EveryRankReadsWhatEveryRankPosted) {
  const int rank = rank_of(), size = size_of(), runs = 12;
  RoundBoard board(MPI_COMM_WORLD, runs, 4);
  ASSERT_TRUE(board.ok());
  std::vector<int> mine;  // runs 0..9; 10 and 11 are never posted
  std::vector<RunResult> results;
  for (int r = rank; r < 10; r += size) {
    mine.push_back(r);
    RunResult result;
    result.status = status_of(r);
    result.mse = mse_of(r);
    result.best_validation_loss = -mse_of(r);
    results.push_back(result);
  }
  board.post(mine, results);
  MPI_Barrier(MPI_COMM_WORLD);
  std::vector<RunStatus> seen(runs, RunStatus::kPending);
  std::vector<double> seen_mse(runs, -1.0), seen_criterion(runs, -2.0);
  board.read(&seen, &seen_mse, &seen_criterion);
  for (int r = 0; r < runs; ++r) {
    if (r >= 10) {
      EXPECT_EQ(seen[r], RunStatus::kPending) << "run " << r;
      EXPECT_EQ(seen_mse[r], -1.0) << "run " << r;
      EXPECT_EQ(seen_criterion[r], -2.0) << "run " << r;
      continue;
    }
    EXPECT_EQ(seen[r], status_of(r)) << "run " << r;
    const double want = mse_of(r), criterion = -mse_of(r);
    EXPECT_EQ(std::memcmp(&seen_mse[r], &want, sizeof want), 0) << "run " << r;
    EXPECT_EQ(std::memcmp(&seen_criterion[r], &criterion, sizeof criterion), 0) << "run " << r;
  }
  MPI_Barrier(MPI_COMM_WORLD);
  board.close();
}

TEST(RoundBoardMpiTest, EachItemIsClaimedByOneRank) {
  const int items = 40;
  RoundBoard board(MPI_COMM_WORLD, 3, items);
  ASSERT_TRUE(board.ok());
  std::vector<int> won(items, 0), total(items, 0);
  for (int i = 0; i < items; ++i) won[i] = board.claim(i) ? 1 : 0;
  for (int i = 0; i < items; ++i) EXPECT_FALSE(board.claim(i)) << "item " << i << " claimed twice";
  MPI_Allreduce(won.data(), total.data(), items, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  for (int i = 0; i < items; ++i) EXPECT_EQ(total[i], 1) << "item " << i;
  board.close();
}

}  // namespace
}  // namespace phnn
