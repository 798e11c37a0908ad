// src/sweep/round_board.cpp — RoundBoard (phnn/sweep/round_board.h): run
// outcomes and claim flags in one MPI-3 window on rank 0.
#include "phnn/sweep/round_board.h"

#include <cstring>

#include "sweep/rank0_window.h"

namespace phnn {

static_assert(sizeof(long) == sizeof(double), "an MSE's bits travel in one long");

RoundBoard::RoundBoard(MPI_Comm comm, int num_runs, int num_items)
    : comm_(comm), num_runs_(num_runs), num_items_(num_items) {
  window_ = allocate_rank0_window(
      comm_, static_cast<MPI_Aint>(num_items) + 3 * static_cast<MPI_Aint>(num_runs), &slots_);
}

// close() is collective; a destructor during stack unwinding on one rank
// must not block, so it frees nothing.
RoundBoard::~RoundBoard() = default;

namespace {
long bits_of(double x) {
  long bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  return bits;
}
}  // namespace

void RoundBoard::post(const std::vector<int>& runs, const std::vector<RunResult>& results) {
  if (!ok()) return;
  // Origin buffers stay untouched until the flush that completes them.
  std::vector<long> mse(runs.size()), criterion(runs.size()), codes(runs.size());
  for (std::size_t k = 0; k < runs.size(); ++k) {
    mse[k] = bits_of(results[k].mse);
    criterion[k] = bits_of(results[k].best_validation_loss);
    codes[k] = static_cast<long>(results[k].status) + 1;
  }
  for (std::size_t k = 0; k < runs.size(); ++k) {
    MPI_Accumulate(&mse[k], 1, MPI_LONG, 0, mse_at(runs[k]), 1, MPI_LONG, MPI_REPLACE, window_);
    MPI_Accumulate(&criterion[k], 1, MPI_LONG, 0, criterion_at(runs[k]), 1, MPI_LONG, MPI_REPLACE,
                   window_);
  }
  MPI_Win_flush(0, window_);  // the numbers are complete at rank 0 before any status
  for (std::size_t k = 0; k < runs.size(); ++k) {
    MPI_Accumulate(&codes[k], 1, MPI_LONG, 0, status_at(runs[k]), 1, MPI_LONG, MPI_REPLACE,
                   window_);
  }
  MPI_Win_flush(0, window_);
}

void RoundBoard::read(std::vector<RunStatus>* status, std::vector<double>* mse,
                      std::vector<double>* criterion) const {
  if (!ok() || num_runs_ == 0) return;
  std::vector<long> codes(static_cast<std::size_t>(num_runs_)), numbers(2 * codes.size());
  // Statuses first: a run's numbers are complete at rank 0 before its status is posted.
  MPI_Get_accumulate(nullptr, 0, MPI_LONG, codes.data(), num_runs_, MPI_LONG, 0, status_at(0),
                     num_runs_, MPI_LONG, MPI_NO_OP, window_);
  MPI_Win_flush(0, window_);
  MPI_Get_accumulate(nullptr, 0, MPI_LONG, numbers.data(), 2 * num_runs_, MPI_LONG, 0, mse_at(0),
                     2 * num_runs_, MPI_LONG, MPI_NO_OP, window_);
  MPI_Win_flush(0, window_);
  for (std::size_t r = 0; r < codes.size(); ++r) {
    if (codes[r] == 0) continue;
    (*status)[r] = static_cast<RunStatus>(codes[r] - 1);
    std::memcpy(&(*mse)[r], &numbers[r], sizeof(double));
    std::memcpy(&(*criterion)[r], &numbers[codes.size() + r], sizeof(double));
  }
}

// A fetch-and-add, not MPI_Compare_and_swap: Open MPI 4.1's shared-memory
// transport crashes in its compare-and-swap emulation (osc/rdma over vader,
// seen here); the first rank to add finds 0.
bool RoundBoard::claim(int item) {
  if (!ok()) return false;
  const long one = 1;
  long previous = 1;
  MPI_Fetch_and_op(&one, &previous, MPI_LONG, 0, item, MPI_SUM, window_);
  MPI_Win_flush(0, window_);
  return previous == 0;
}

void RoundBoard::close() { free_rank0_window(&window_); }

}  // namespace phnn
