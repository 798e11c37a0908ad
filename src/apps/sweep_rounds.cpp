// src/apps/sweep_rounds.cpp — SweepRun's rounds (sweep_run.h): plan what is
// left as work items, train them from the shared queue (each item:
// sweep_items.cpp), close and report; an adaptive or search sweep round
// after round, each replayed from the finished file.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <iostream>
#include <sstream>

#include <boost/mpi/collectives.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/vector.hpp>

#include "apps/sweep_report.h"
#include "apps/sweep_run.h"
#include "apps/sweep_search.h"
#include "phnn/common/counted.h"
#include "phnn/sweep/resumed_items.h"
#include "phnn/sweep/scheduler.h"
#include "phnn/sweep/search.h"

namespace phnn {
namespace apps {

namespace mpi = boost::mpi;


// Every rank closes the file (collective, but nothing is left to write: rows
// are raw data in allocated space), every rank learns every error, rank 0
// ends the session in place and prints the summary. Returns the exit status
// of a failure (0: none).
int SweepRun::close_and_report(std::string io_error, bool stopped, int total_runs,
                               double seconds) {
  try {
    results_->close();
  } catch (const std::exception& e) {
    if (io_error.empty()) io_error = prefix_ + e.what();
  }
  int failed = agree(world_, io_error.empty() ? 0 : kExitFailed, io_error);
  if (int status = agreed(world_, root_, [&] {
        ResultsFile file = ResultsFile::open(out_, MPI_COMM_NULL, spec_.text_hash);
        file.end_session(session_, utc_now());
        file.close();
      })) {
    failed = std::max(failed, status);
  }
  if (!root_) return failed;
  try {
    print_summary(out_, total_runs, seconds,
                  failed ? StopReason::kError : stopped ? StopReason::kSignal : StopReason::kNone,
                  shard_, adaptive_line());
  } catch (const std::exception& e) {
    std::cerr << cli::with_prefix("phnn sweep: ", e.what()) << "\n";
  }
  return failed;
}

// What is left to train, as work items: the saved states' items as they
// were (rank 0 reads the states), then the plan of the rest. The same
// broadcast lists give the same items on every rank.
SweepRun::Planned SweepRun::plan(const std::vector<int>& status_codes) {
  Planned p;
  // --retry-failed retries in the session's first round only (an adaptive
  // sweep plans again after each round; a run that fails again stays failed).
  auto pending = pending_runs(grid_, status_codes, parser_.flag_set("retry-failed") && !planned_once_,
                              shard_, &p.runs_done_before);
  planned_once_ = true;
  for (const auto& runs : pending) p.runs_to_do += static_cast<int>(runs.size());
  if (in_rounds()) {  // the runs no round asked for read as finished
    p.runs_done_before -= static_cast<int>(grid_.runs.size()) - adaptive_.active_runs();
  }
  std::vector<std::vector<int>> resumed;
  if (root_) {
    try {
      resumed = resumed_groups(grid_, &pending, out_, state_key_, ahead_);
    } catch (const std::exception& e) {  // never leave the others waiting in the broadcast
      std::cerr << "phnn sweep: cannot read the saved training states (" << e.what()
                << "); their items train from the start\n";
      resumed.clear();
    }
  }
  mpi::broadcast(world_, resumed, 0);
  mpi::broadcast(world_, pending, 0);
  p.plan = plan_work(grid_, pending, size_, split_);
  p.plan.items = with_resumed(grid_, resumed, p.plan.items);
  p.resumed = resumed.size();
  return p;
}

SweepRun::RoundOutcome SweepRun::train_round(const std::vector<int>& status_codes) {
  const Planned planned = plan(status_codes);
  const std::vector<WorkItem>& work = planned.plan.items;
  const ScheduleMode mode = parser_.flag_set("static") ? ScheduleMode::kStatic : ScheduleMode::kDynamic;
  WorkQueue queue(MPI_COMM_WORLD, static_cast<int>(work.size()), mode);
  // Items to train ahead while the round drains, their queue made now (a
  // collective call); they need the shared count of finished items, which
  // static mode lacks.
  const std::vector<WorkItem> ahead =
      queue.mode() == ScheduleMode::kDynamic ? ahead_items() : std::vector<WorkItem>();
  std::optional<RoundBoard> board;
  if (!ahead.empty()) {
    board.emplace(MPI_COMM_WORLD, static_cast<int>(grid_.runs.size()),
                  static_cast<int>(ahead.size()));
    board_ = &*board;
  }
  if (root_) {
    print_plan(spec_, grid_, shard_, planned.runs_done_before, planned.runs_to_do, planned.plan,
               size_, queue.mode(), out_);
    if (planned.resumed > 0) {
      std::cout << "phnn sweep: " << planned.resumed
                << " of them go on from their saved training state\n";
    }
  }
  RoundOutcome outcome;
  double last_progress = -1e9;
  const ProgressLine progress_line(work, size_, queue.mode() == ScheduleMode::kStatic);
  // A stop signal on any rank stops every rank at its next item boundary:
  // this rank posts it at once, from the training's progress ticks too.
  // An I/O error on this rank: it takes no more items, nor do the others
  // after the one in hand; then every rank learns of it (agree below) and
  // exits 1 (outcome.io_error).
  auto post_stop = [&] {
    if (g_stop_signal != 0 && !queue.stop_requested()) queue.request_stop();
  };
  auto report_progress = [&](bool force) {
    if (!root_ || parser_.flag_set("quiet") || (!force && elapsed() - last_progress < 10.0)) return;
    last_progress = elapsed();
    progress_line.print(queue.done(), elapsed());
  };
  const auto tick = [&] {
    post_stop();
    queue.progress();  // rank 0's window answers the others mid-cell too
    report_progress(false);
  };
  const auto signalled = [] { return g_stop_signal != 0; };
  bool ended = false;  // stopped by a signal or an I/O error
  for (;;) {
    const auto asking = SweepClock::now();
    post_stop();
    const int i = queue.next();
    times_.add(ItemTimes::kQueue, asking);
    if (i < 0) break;
    const ItemOutcome done =
        train_one(work[static_cast<std::size_t>(i)], "item", i, work.size(), signalled, tick);
    outcome.my_runs += done.runs;
    outcome.io_error = done.io_error;
    ended = done.stopped || !done.io_error.empty();
    if (!done.io_error.empty()) queue.request_stop();  // the others stop at their next item too
    if (ended) break;
    const auto marking = SweepClock::now();
    queue.mark_done();
    times_.add(ItemTimes::kQueue, marking);
    report_progress(true);
  }
  post_stop();  // before any collective call: the others stop at their next step or item
  if (board) {
    if (!ended) train_ahead(ahead, work, &queue, tick, &outcome);
    post_stop();
    board_ = nullptr;
    board->close();
  }
  outcome.stopped =
      mpi::all_reduce(world_, queue.stop_requested() ? 1 : 0, mpi::maximum<int>()) != 0;
  queue.close();
  return outcome;
}

// Trains what is left; an adaptive sweep round after round, each decided on
// the finished file (every rank closes it, rank 0 replays the rounds, every
// rank opens it again), until its rule names no cell that can grow.
int SweepRun::train_and_close(std::vector<int> status_codes) {
  int my_runs = 0;
  RoundOutcome round;
  for (;;) {
    round = train_round(status_codes);
    my_runs += round.my_runs + round.ahead_runs;
    const bool io_failed =
        mpi::all_reduce(world_, round.io_error.empty() ? 0 : 1, mpi::maximum<int>()) != 0;
    if (!in_rounds() || round.stopped || io_failed) break;
    std::string close_error;
    try {
      results_->close();
    } catch (const std::exception& e) {
      close_error = prefix_ + e.what();
    }
    if (int status = agree(world_, close_error.empty() ? 0 : kExitFailed, close_error)) {
      return status;
    }
    const int round_before = adaptive_.round;
    const int round_runs = mpi::all_reduce(world_, round.my_runs, std::plus<int>());
    if (int status = replay_rounds(&status_codes)) return status;
    if (int status = open_results()) return status;
    if (adaptive_.complete) {
      remove_unused_states();
      break;
    }
    if (round_runs == 0 && adaptive_.round == round_before) {  // never loop without progress
      round.io_error = prefix_ + "adaptive round " + std::to_string(round_before) +
                       " has pending runs that this sweep did not train; stopping";
      break;
    }
  }
  const int total_runs = mpi::all_reduce(world_, my_runs, std::plus<int>());
  const int failed = close_and_report(round.io_error, round.stopped, total_runs, elapsed());
  if (parser_.flag_set("timings")) report_times();
  if (failed) return failed;
  return round.stopped ? kExitStopped : 0;
}

// Rank 0 at the end of a sweep in rounds: the item states left (items
// trained ahead of the last round, stopped at its end) belong to runs no
// round asked for; they go. A [search]'s rung states stay (sweep_search.h).
void SweepRun::remove_unused_states() const {
  if (!root_) return;
  try {
    std::vector<std::vector<int>> none(grid_.cells.size());
    resumed_groups(grid_, &none, out_, state_key_);
  } catch (const std::exception& e) {
    std::cerr << "phnn sweep: warning: cannot remove the states of items trained ahead (" << e.what()
              << "); they are removed at the next run\n";
  }
}

// --timings: "per item (N items, R ranks, mean): ..." on rank 0.
void SweepRun::report_times() {
  std::vector<double> sums(times_.s.begin(), times_.s.end());
  sums.push_back(times_.items);
  std::vector<double> all(sums.size());
  mpi::reduce(world_, sums.data(), static_cast<int>(sums.size()), all.data(), std::plus<double>(), 0);
  if (!root_ || all.back() == 0) return;
  const double n = all.back();
  const auto ms = [&](double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2f ms", 1e3 * s / n);
    return std::string(text);
  };
  const double recorded = all[ItemTimes::kJournal] + all[ItemTimes::kRow];
  std::cout << "phnn sweep: time per item (" << static_cast<long>(n) << " items on " << size_
            << " rank" << (size_ > 1 ? "s" : "") << ", mean): " << ms(all[ItemTimes::kItem])
            << " in all: the runs' training " << ms(all[ItemTimes::kRuns]) << ", its setup "
            << ms(all[ItemTimes::kTrain] - all[ItemTimes::kRuns]) << " (data set, models, "
            << "tensors), journal " << ms(all[ItemTimes::kJournal]) << ", results row "
            << ms(all[ItemTimes::kRow]) << ", the rest "
            << ms(all[ItemTimes::kItem] - all[ItemTimes::kTrain] - recorded)
            << " (checkpoint file, log lines); shared queue " << ms(all[ItemTimes::kQueue])
            << " between items; " << ms(all[ItemTimes::kStopped])
            << " in items stopped with their state saved (ahead of a round's end, or a signal)\n";
}

// Rank 0 replays an adaptive sweep's rounds on the file (closed on every
// rank), every rank gets the state, and the runs no round asked for read as
// finished in *status_codes, so no rank plans them.
int SweepRun::replay_rounds(std::vector<int>* status_codes) {
  std::vector<int> codes;
  if (int status = agreed(world_, root_, [&] {
        const ResultsFile file = ResultsFile::open_read_only(out_);
        const std::vector<RunStatus> statuses = file.read_statuses();
        round_mse_ = file.read_double_column("mse");
        round_criterion_ = file.read_double_column("best_validation_loss");
        adaptive_ = spec_.search.enabled
                        ? replay_search(spec_, grid_, statuses, round_criterion_, round_mse_).state
                        : replay_adaptive_rounds(spec_, grid_, statuses, round_mse_);
        for (RunStatus st : statuses) codes.push_back(static_cast<int>(st));
        ahead_ = spec_.search.enabled ? search_runs_ahead(spec_, grid_, adaptive_.round, statuses,
                                                          round_criterion_, round_mse_)
                                      : runs_to_speculate(spec_, grid_, adaptive_, statuses);
      })) {
    return status;
  }
  // What the other ranks use of the state (cell_seeds, pending and failed
  // stay rank 0's).
  mpi::broadcast(world_, codes, 0);
  mpi::broadcast(world_, adaptive_.active, 0);
  mpi::broadcast(world_, adaptive_.cells_grown, 0);
  mpi::broadcast(world_, adaptive_.round, 0);
  mpi::broadcast(world_, adaptive_.complete, 0);
  mpi::broadcast(world_, adaptive_.trained_ahead, 0);
  mpi::broadcast(world_, ahead_, 0);
  mpi::broadcast(world_, round_mse_, 0);
  mpi::broadcast(world_, round_criterion_, 0);
  round_status_.clear();
  for (int code : codes) round_status_.push_back(static_cast<RunStatus>(code));
  for (std::size_t i = 0; i < codes.size(); ++i) {
    if (!adaptive_.active[i]) codes[i] = static_cast<int>(RunStatus::kDone);
  }
  *status_codes = codes;
  const int round = adaptive_.round, failed = adaptive_.failed;
  const std::vector<int>& cells_grown = adaptive_.cells_grown;
  if (root_ && failed > 0) {
    std::cout << "phnn sweep: warning: " << failed << " failed run" << (failed > 1 ? "s" : "")
              << " asked for by the rounds so far (their messages: phnn reduce --per-run); the "
                 "rounds were decided without them; --retry-failed retries them and the rounds "
                 "after are decided again" << std::endl;
  }
  if (root_ && spec_.search.enabled && !adaptive_.complete) {
    std::cout << search_round_line(spec_, adaptive_) << std::endl;
  } else if (root_ && !adaptive_.complete) {
    std::cout << "phnn sweep: adaptive round " << round << ": " << adaptive_.active_runs()
              << " runs asked for of at most " << grid_.runs.size() << " ("
              << (round == 0 ? std::string("every cell's first ") +
                                   std::to_string(spec_.adaptive.initial_seeds.size()) + " seeds"
                             : counted(cells_grown.back(), "cell") + " got " +
                                   std::to_string(spec_.adaptive.batch) + " more seeds after round " +
                                   std::to_string(round - 1))
              << ", rule " << to_string(spec_.adaptive.rule) << ")" << std::endl;
  }
  return 0;
}

// --dry-run of an adaptive sweep: round 0's schedule and the worst case,
// every cell at max_seeds.
std::string SweepRun::adaptive_dry_run() const {
  std::ostringstream out;
  out << "adaptive sweep (rule " << to_string(spec_.adaptive.rule) << ", batch "
      << spec_.adaptive.batch << ", max_seeds " << spec_.adaptive.max_seeds << ")\n"
      << "round 0 (" << spec_.adaptive.initial_seeds.size() << " seeds per cell):\n"
      << dry_run_summary(expand_grid(round_zero_spec(spec_)), ranks_, split_)
      << "worst case (every cell at " << spec_.adaptive.max_seeds << " seeds):\n"
      << dry_run_summary(grid_, ranks_, split_)
      << "the rounds after round 0 depend on its results: replay a finished file's rounds per "
         "rank count, with barriers and speculation, with analysis/rounds_replay.py\n";
  return out.str();
}

std::string SweepRun::adaptive_line() const {
  if (spec_.search.enabled) return search_complete_line(spec_, grid_, adaptive_);
  if (!spec_.adaptive.enabled || !adaptive_.complete) return "";
  const int asked = adaptive_.active_runs();
  const int left = static_cast<int>(grid_.runs.size()) - asked;
  const int ahead = adaptive_.trained_ahead;
  return "adaptive sweep complete after round " + std::to_string(adaptive_.round) + ": " +
         std::to_string(asked) + " runs of at most " + std::to_string(grid_.runs.size()) +
         (left == 0 ? std::string(" (every cell at max_seeds)")
                    : "; the other " + std::to_string(left) + " are seeds no round asked for" +
                          (ahead > 0 ? " (" + std::to_string(ahead) +
                                           " of them finished: trained ahead while a round "
                                           "drained, or asked for by another rule; left out of "
                                           "every table)"
                                     : ""));
}

}  // namespace apps
}  // namespace phnn
