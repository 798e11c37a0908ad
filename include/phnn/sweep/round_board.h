// include/phnn/sweep/round_board.h — what the ranks of a sweep share while an
// adaptive round or a search rung drains: the outcome of every run finished in it
// (posted by the rank that trained it) and a claim flag per item that idle
// ranks may train ahead. One MPI-3 window on rank 0; every element is read
// and written with element-wise atomic one-sided operations.
#pragma once

#include <mpi.h>

#include <vector>

#include "phnn/config/run_result.h"

namespace phnn {

/// The round's shared board (docs/METHOD.md, "Speculation").
///
///   RoundBoard board(comm, grid.runs.size(), ahead.size());  // collective
///   board.post(item.runs, outcomes);           // after an item is recorded
///   board.read(&status, &mse, &criterion);     // what every rank posted so far
///   if (board.claim(i)) train(ahead[i]);      // one rank gets item i
///   board.close();                            // collective
class RoundBoard {
 public:
  /// Collective. If the window cannot be made on some rank, ok() is false on
  /// every rank, post() and read() do nothing and claim() returns false.
  RoundBoard(MPI_Comm comm, int num_runs, int num_items);
  ~RoundBoard();
  RoundBoard(const RoundBoard&) = delete;
  RoundBoard& operator=(const RoundBoard&) = delete;

  bool ok() const { return window_ != MPI_WIN_NULL; }
  /// Posts the outcomes of grid runs `runs` (results[k] of runs[k]: status,
  /// MSE, best validation loss): the numbers first, completed at rank 0
  /// before the statuses, so a reader that sees a status sees its numbers.
  void post(const std::vector<int>& runs, const std::vector<RunResult>& results);
  /// Sets (*status)[r], (*mse)[r], (*criterion)[r] (the best validation
  /// loss) of every run r posted so far; leaves the others as they are.
  void read(std::vector<RunStatus>* status, std::vector<double>* mse,
            std::vector<double>* criterion) const;
  /// True on the one rank whose call first claims item `item`.
  bool claim(int item);
  /// Collective: frees the window.
  void close();

 private:
  MPI_Comm comm_;
  int num_runs_ = 0, num_items_ = 0;
  MPI_Win window_ = MPI_WIN_NULL;
  // Rank 0's window: num_items claim flags, then per run its status + 1 (0:
  // not posted), then per run the bits of its MSE, then of its criterion.
  long* slots_ = nullptr;
  MPI_Aint status_at(int run) const { return num_items_ + run; }
  MPI_Aint mse_at(int run) const { return static_cast<MPI_Aint>(num_items_) + num_runs_ + run; }
  MPI_Aint criterion_at(int run) const { return mse_at(run) + num_runs_; }
};

}  // namespace phnn
