// src/apps/sweep_run.h — SweepRun, one `phnn sweep` on one rank (private
// to src/apps): its setup (options, the results file, the data) in
// cmd_sweep.cpp, its rounds of work items in sweep_rounds.cpp.
#pragma once

#include <array>
#include <chrono>
#include <csignal>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <boost/mpi/communicator.hpp>

#include "apps/cli.h"
#include "apps/provenance.h"
#include "apps/sweep_data.h"
#include "apps/sweep_phases.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/merge.h"
#include "phnn/sweep/round_board.h"
#include "phnn/sweep/scheduler.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/sweep/work_plan.h"
#include "phnn/sweep/writer_lock.h"

namespace phnn {
namespace apps {

// Set by SIGTERM / SIGUSR1 (Slurm's --signal before the time limit, or
// scancel) once the sweep writes: save the training state of the item in
// hand (sweep_checkpoints.h), take no new one, close the file cleanly.
// Before that a stop ends the process at once (early_signals.h).
extern volatile std::sig_atomic_t g_stop_signal;

using SweepClock = std::chrono::steady_clock;

/// Where this rank's time per item goes (`phnn sweep --timings`) [s]:
/// kItem an item from its start to its last line, of which kTrain trains its
/// cell (kRuns of that: the runs' own wall_time_s, the trainer's clock; a
/// resumed item's time here counts wholly as the runs'), kJournal and kRow
/// record it; kQueue the shared counter between items; kStopped items
/// stopped with their state saved (ahead of a round's end, or a signal).
struct ItemTimes {
  enum Part { kItem, kTrain, kRuns, kJournal, kRow, kQueue, kStopped, kParts };
  std::array<double, kParts> s{};
  int items = 0;  // recorded (stopped ones are not counted)
  void add(Part part, SweepClock::time_point since) {
    s[part] += std::chrono::duration<double>(SweepClock::now() - since).count();
  }
};

// One `phnn sweep` on this rank: each phase that can fail on some ranks ends
// in agree(), so every rank fails together and none waits forever.
class SweepRun {
 public:
  SweepRun(int argc, char** argv, int first);

  int run();

 private:
  // The setup phases (cmd_sweep.cpp).
  bool parse();
  int check_same_sweep_file();
  std::vector<int> prepare_results(const Provenance& session);
  void check_stored_data(const ResultsFile& file);
  void store_missing_data(ResultsFile* file, bool resume);

  // The rounds of work items (sweep_rounds.cpp).
  struct Planned {
    WorkPlan plan;  // items: the resumed ones first
    int runs_done_before = 0, runs_to_do = 0;
    std::size_t resumed = 0;
  };
  Planned plan(const std::vector<int>& status_codes);
  struct RoundOutcome {
    int my_runs = 0;     // runs of the round's items trained here
    int ahead_runs = 0;  // runs trained here ahead of the round's end
    std::string io_error;
    bool stopped = false;  // a stop signal on any rank
  };
  RoundOutcome train_round(const std::vector<int>& status_codes);
  struct ItemOutcome {
    int runs = 0;          // recorded
    bool stopped = false;  // stopped before its end, its state saved
    std::string io_error;
  };
  ItemOutcome train_one(const WorkItem& item, const char* kind, int index, std::size_t items,
                        std::function<bool()> stop, const std::function<void()>& tick);
  std::vector<WorkItem> ahead_items() const;
  void train_ahead(const std::vector<WorkItem>& ahead, const std::vector<WorkItem>& work,
                   WorkQueue* queue, const std::function<void()>& tick, RoundOutcome* outcome);
  std::vector<int> ahead_ready(const std::vector<WorkItem>& ahead,
                               const std::vector<WorkItem>& work, std::vector<char>* decided);
  int train_and_close(std::vector<int> status_codes);
  int open_results() {
    return agreed(world_, true, [&] {
      results_.emplace(ResultsFile::open(out_, MPI_COMM_WORLD, spec_.text_hash));
    });
  }
  int replay_rounds(std::vector<int>* status_codes);
  void remove_unused_states() const;
  // Trained in rounds decided on the results: [adaptive] or [search].
  bool in_rounds() const { return spec_.adaptive.enabled || spec_.search.enabled; }
  std::string adaptive_dry_run() const;
  std::string adaptive_line() const;
  // Seconds since this sweep started.
  double elapsed() const {
    return std::chrono::duration<double>(SweepClock::now() - start_).count();
  }
  int close_and_report(std::string io_error, bool stopped, int total_runs, double seconds);

  int argc_;
  char** argv_;
  int first_;
  boost::mpi::communicator world_;
  int rank_, size_;
  bool root_;
  std::string prefix_;
  cli::Parser parser_;
  SweepSpec spec_;
  Grid grid_;
  SplitOptions split_;
  Shard shard_;  // 0/1: the whole sweep
  std::vector<int> ranks_;
  double checkpoint_every_ = 300.0;
  // What a saved training state must match besides its runs: the sweep text,
  // the build (a changed trainer would mix two builds in one cell) and the
  // intra-op thread count.
  std::string state_key_;
  // The build and thread count alone: what a [search] rung state must match
  // besides its runs' configurations and seeds (apps/sweep_search.h).
  std::string build_key_;
  std::string out_;
  WriterLock lock_;  // rank 0 only; released after the file is closed
  std::optional<ResultsFile> results_;
  std::optional<Journal> journal_;
  int session_ = 0;  // this run's /provenance/session_<k>
  SweepDataSets data_{spec_, grid_};
  // An adaptive sweep's rounds so far (replay_rounds); unused otherwise.
  AdaptiveState adaptive_;
  ItemTimes times_;
  // Rank 0 prints every rank's ItemTimes, summed (collective).
  void report_times();
  // The runs idle ranks may train ahead of the round in progress, per cell
  // (runs_to_speculate, search_runs_ahead; the same on every rank).
  std::vector<std::vector<int>> ahead_;
  // Every run's status, MSE and best validation loss at the round's start
  // (replay_rounds; every rank), for the decisions taken while the round
  // drains (cells_named_early, search_cells_known_early).
  std::vector<RunStatus> round_status_;
  std::vector<double> round_mse_, round_criterion_;
  // The round's shared outcomes and claims while it has items to train
  // ahead (train_round); train_one posts every recorded item there.
  RoundBoard* board_ = nullptr;
  bool planned_once_ = false;
  SweepClock::time_point start_ = SweepClock::now();
};

}  // namespace apps
}  // namespace phnn
