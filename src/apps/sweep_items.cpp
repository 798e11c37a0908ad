// src/apps/sweep_items.cpp — SweepRun's work items (sweep_run.h): one
// item trained (from its saved state if it has one), journaled and written
// as rows; and the items idle ranks train ahead of a round's end.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <iostream>
#include <thread>

#include "apps/sweep_checkpoints.h"
#include "apps/sweep_report.h"
#include "apps/sweep_run.h"
#include "apps/sweep_search.h"
#include "phnn/sweep/resumed_items.h"
#include "phnn/sweep/search.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace apps {

namespace {

// Trains one item's cell, from its saved state if it has one. A cell that
// throws is a result too: every run failed, with the message. A cell stopped
// by a signal returns no results (its state is saved; *interrupted), and so
// does one whose data set a signal stopped while it was being generated.
std::vector<RunResult> train_item(const CellSpec& cell, SweepDataSets* data,
                                  const std::string& system, const std::function<void()>& tick,
                                  ItemCheckpoints* checkpoints, const std::string& prefix,
                                  const std::string& label, bool* interrupted) {
  *interrupted = false;
  const auto progress = [&](const TrainProgress&) { tick(); };
  try {
    data->make(system);
    try {
      return data->train(cell, system, progress, &checkpoints->checkpointing());
    } catch (const std::invalid_argument& e) {
      // A saved state that does not fit (e.g. written by another build).
      if (checkpoints->resume_step() == 0 ||
          std::string(e.what()).rfind("training state", 0) != 0) {
        throw;
      }
      std::fprintf(stderr, "%s%s: %s; training it from the start\n", prefix.c_str(),
                   label.c_str(), e.what());
      checkpoints->forget_state();
      return data->train(cell, system, progress, &checkpoints->checkpointing());
    }
  } catch (const CellInterrupted& e) {
    *interrupted = true;
    if (checkpoints->saved_step() == e.step) {
      std::fprintf(stderr, "%s%s stopped after step %d of %d; its training state is in %s\n",
                   prefix.c_str(), label.c_str(), e.step, cell.training.steps,
                   checkpoints->path().c_str());
    } else {
      std::fprintf(stderr, "%s%s stopped after step %d of %d; its state could not be saved "
                   "(see above): it trains again from %s\n", prefix.c_str(), label.c_str(), e.step,
                   cell.training.steps,
                   checkpoints->saved_step() > 0 || checkpoints->resume_step() > 0
                       ? "its last saved state"
                       : "the start");
    }
    return {};
  } catch (const GenerationStopped&) {  // a signal while this rank made its data: nothing trained
    *interrupted = true;
    std::fprintf(stderr, "%s%s stopped while making its data set; it trains at the next run\n",
                 prefix.c_str(), label.c_str());
    return {};
  } catch (const std::exception& e) {
    std::vector<RunResult> failed(cell.seeds.size());
    for (auto& r : failed) {
      r.status = RunStatus::kFailed;
      r.message = e.what();
    }
    std::fprintf(stderr, "%s%s failed: %s\n", prefix.c_str(), label.c_str(), e.what());
    return failed;
  }
}

// "item 3/8: <cell>, 2 seeds", and where it goes on from a saved state.
void announce_item(const std::string& prefix, const std::string& label, const RunConfig& head,
                   const CellSpec& cell, int resume_step) {
  print_item(prefix, label + ": " + describe(head) + ", " + std::to_string(cell.seeds.size()) +
                         " seed" + (cell.seeds.size() > 1 ? "s" : ""));
  if (resume_step > 0) {
    print_item(prefix, label + ": going on after step " + std::to_string(resume_step) + " of " +
                           std::to_string(cell.training.steps) + " (saved training state)");
  }
}

// Journal record first (the source of truth), then the row, each with the
// item's run times, for each run of the item. A failed journal append (a full disk) does
// not stop the row: its space was allocated when the file was made, so the
// result is kept there. Returns "" or the first I/O error.
// The seconds of each go to times[kJournal] and times[kRow].
std::string record_item(const Grid& grid, const WorkItem& item,
                        const std::vector<RunResult>& cell_results, const std::string& started,
                        const std::string& finished, Journal* journal, ResultsFile* results,
                        ItemTimes* times) {
  std::string error;
  auto attempt = [&](ItemTimes::Part part, const auto& write) {
    const auto begin = SweepClock::now();
    try {
      write();
    } catch (const std::exception& e) {
      if (error.empty()) error = cli::with_prefix("phnn sweep: ", e.what());
    }
    times->add(part, begin);
  };
  for (std::size_t k = 0; k < item.runs.size(); ++k) {
    const int row = item.runs[k];
    RunResult result = cell_results[k];
    result.started_utc = started;
    result.finished_utc = finished;
    attempt(ItemTimes::kJournal,
            [&] { journal->append(grid.runs[static_cast<std::size_t>(row)].id(), result); });
    attempt(ItemTimes::kRow, [&] { results->write_run(row, result); });
  }
  return error;
}

}  // namespace

// Trains and records item `index` of `items` of `kind` ("item": the
// round's; "ahead": trained ahead of its end), logged as "item 3/8".
// `stop` is asked at every step; `tick` at every validation.
SweepRun::ItemOutcome SweepRun::train_one(const WorkItem& item, const char* kind, int index,
                                          std::size_t items, std::function<bool()> stop,
                                          const std::function<void()>& tick) {
  const auto item_start = SweepClock::now();
  const std::string label =
      std::string(kind) + " " + std::to_string(index + 1) + "/" + std::to_string(items);
  const RunConfig& head = grid_.runs[static_cast<std::size_t>(item.runs.front())];
  std::vector<int> seeds;
  for (int row : item.runs) seeds.push_back(grid_.runs[static_cast<std::size_t>(row)].seed);
  const CellSpec cell = cell_spec_for(head, seeds);
  ItemCheckpoints checkpoints(out_, item_key(grid_, item.runs, state_key_), checkpoint_every_,
                              std::move(stop), prefix_);
  link_rung_states(spec_, grid_, item.runs, out_, build_key_, &checkpoints);
  const bool quiet = parser_.flag_set("quiet");
  if (!quiet) announce_item(prefix_, label, head, cell, checkpoints.resume_step());
  const auto cell_start = SweepClock::now();
  const std::string started = utc_now();
  ItemOutcome outcome;
  const std::vector<RunResult> cell_results = train_item(
      cell, &data_, head.system_name(), tick, &checkpoints, prefix_, label, &outcome.stopped);
  if (outcome.stopped) {
    times_.add(ItemTimes::kStopped, item_start);
    return outcome;
  }
  const double trained = std::chrono::duration<double>(SweepClock::now() - cell_start).count();
  times_.s[ItemTimes::kTrain] += trained;
  // The runs' wall_time_s of a resumed item includes the time before its
  // saved state: count this process's time alone, all of it as training.
  if (checkpoints.resume_step() > 0) {
    times_.s[ItemTimes::kRuns] += trained;
  } else {
    for (const RunResult& r : cell_results) times_.s[ItemTimes::kRuns] += r.wall_time_s;
  }
  outcome.io_error = record_item(grid_, item, cell_results, started, utc_now(), &*journal_,
                                 &*results_, &times_);
  if (outcome.io_error.empty()) checkpoints.remove();
  // For the decisions taken while the round drains (ahead_ready).
  if (outcome.io_error.empty() && board_ != nullptr) board_->post(item.runs, cell_results);
  outcome.runs = static_cast<int>(item.runs.size());
  if (!quiet && outcome.io_error.empty()) {
    print_item(prefix_, label + " done in " + format_duration(std::chrono::duration<double>(
                                                  SweepClock::now() - cell_start).count()));
  }
  times_.add(ItemTimes::kItem, item_start);
  ++times_.items;
  return outcome;
}

// The runs to train ahead (runs_to_speculate, search_runs_ahead; on every
// rank) as items, largest first; none with --no-speculation. Under the
// comparisons rule they are planned for kAheadSplit times the ranks: they
// have only the end of a round, so they are split as finely as a plan for
// many ranks would (the lean paper grid replayed at 16 ranks: 24.3 min
// planned for the ranks, 21.6 for 4x, 21.1 for 8x, 21.2 for 16x and 64x;
// docs/BENCHMARKS.md). The column-best guess keeps the plan for the ranks
// (25.4 min against 23.1 for its guesses on that grid at 8x: more of them
// are lost), and so does a search, whose next rung goes on from the saved
// state of the same configuration and seeds as the rung's items grouped them.
std::vector<WorkItem> SweepRun::ahead_items() const {
  constexpr int kAheadSplit = 8;
  if (ahead_.empty() || parser_.flag_set("no-speculation")) return {};
  const bool finer = !spec_.search.enabled && spec_.adaptive.rule == AdaptiveRule::kComparisons;
  return plan_work(grid_, ahead_, finer ? size_ * kAheadSplit : size_, split_).items;
}

// The ahead items this rank may take now that were not ready before: with
// the comparisons rule, those of the cells the next round is certain to
// grow (cells_named_early), with a search those of the configurations the
// groups already complete keep (search_cells_known_early) — both on the
// outcomes posted so far, every run of the round's items not posted yet
// counting as pending; with column-best, all of them at the first call (the
// guess of runs_to_speculate). None in a round that retries failed runs
// (--retry-failed): a retried run of an earlier round can change that
// round's decision, so nothing is certain. *decided: the comparisons or
// groups read so far, empty at first; all set when nothing more can become
// ready.
std::vector<int> SweepRun::ahead_ready(const std::vector<WorkItem>& ahead,
                                       const std::vector<WorkItem>& work,
                                       std::vector<char>* decided) {
  std::vector<int> ready;
  const bool known = spec_.search.enabled || spec_.adaptive.rule == AdaptiveRule::kComparisons;
  if (!known) {
    if (decided->empty()) {
      decided->push_back(1);
      for (std::size_t i = 0; i < ahead.size(); ++i) ready.push_back(static_cast<int>(i));
    }
    return ready;
  }
  std::vector<RunStatus> status = round_status_;
  for (const WorkItem& item : work) {
    for (int r : item.runs) {
      if (status[static_cast<std::size_t>(r)] == RunStatus::kFailed) {  // retried
        decided->assign(1, 1);
        return ready;
      }
      status[static_cast<std::size_t>(r)] = RunStatus::kPending;
    }
  }
  std::vector<double> mse = round_mse_, criterion = round_criterion_;
  board_->read(&status, &mse, &criterion);
  const std::vector<int> cells =
      spec_.search.enabled
          ? search_cells_known_early(spec_, grid_, adaptive_.round, status, criterion, mse, decided)
          : cells_named_early(spec_, grid_, adaptive_.active, status, mse, decided);
  for (std::size_t i = 0; i < ahead.size(); ++i) {
    if (std::binary_search(cells.begin(), cells.end(), ahead[i].cell)) {
      ready.push_back(static_cast<int>(i));
    }
  }
  return ready;
}

// While the round's last items train elsewhere, this rank trains ahead
// items as they become ready (ahead_ready, read at most twice a second), the
// first ready one in plan order (largest first: on the lean paper grid
// replayed at 16 ranks 20.2 min against 21.1 taking them in the order they
// became ready), each claimed on the board by one rank; each
// stops (its state saved, for the round that asks for it) once every one of
// the round's `work` items has finished, or on a stop (a signal here is
// posted to the others by train_round, right after). Their results are
// recorded like any other.
void SweepRun::train_ahead(const std::vector<WorkItem>& ahead, const std::vector<WorkItem>& work,
                           WorkQueue* queue, const std::function<void()>& tick,
                           RoundOutcome* outcome) {
  bool round_over = false;
  SweepClock::time_point last_poll{}, last_read{};
  const auto stop = [&] {  // asked at every step: the shared count read at most 10 times a second
    if (g_stop_signal != 0 || round_over) return true;
    if (SweepClock::now() - last_poll < std::chrono::milliseconds(100)) return false;
    last_poll = SweepClock::now();
    queue->progress();
    round_over = queue->done() >= static_cast<int>(work.size()) || queue->stop_requested();
    return round_over;
  };
  std::vector<char> decided;
  std::vector<char> state(ahead.size(), 0);  // per item: 0 not ready, 1 ready, 2 tried here
  while (!stop()) {
    auto first = std::find(state.begin(), state.end(), 1);
    if (SweepClock::now() - last_read >= std::chrono::milliseconds(500)) {
      last_read = SweepClock::now();
      std::vector<int> now;
      try {  // never leave this rank before the collective close: nothing ready instead
        now = ahead_ready(ahead, work, &decided);
      } catch (const std::exception& e) {
        std::cerr << prefix_ << "warning: no items trained ahead this round (" << e.what() << ")\n";
        decided.assign(1, 1);
      }
      for (int k : now) {
        char& item = state[static_cast<std::size_t>(k)];
        item = std::max<char>(item, 1);  // tried stays tried
      }
      first = std::find(state.begin(), state.end(), 1);
    }
    if (first == state.end()) {  // nothing ready now: done if nothing can become ready
      const bool all_read = !decided.empty() && std::all_of(decided.begin(), decided.end(),
                                                            [](char d) { return d != 0; });
      if (all_read) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    *first = 2;  // the first ready in plan order: largest first
    const int i = static_cast<int>(first - state.begin());
    if (!board_->claim(i)) continue;
    const ItemOutcome done =
        train_one(ahead[static_cast<std::size_t>(i)], "ahead", i, ahead.size(), stop, tick);
    outcome->ahead_runs += done.runs;
    if (!done.io_error.empty()) {
      outcome->io_error = done.io_error;
      queue->request_stop();
    }
    // A signal is posted by train_round as soon as this returns.
    if (done.stopped || !done.io_error.empty()) return;
  }
}

}  // namespace apps
}  // namespace phnn
