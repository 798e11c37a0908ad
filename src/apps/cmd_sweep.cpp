// src/apps/cmd_sweep.cpp — `phnn sweep FILE`: every rank trains work items
// (cells, or member groups of a cell) taken from a shared queue; every result
// lands in one parallel HDF5 file, each run first in this rank's journal
// (fsync), then in its row of the file. The phases that can fail on some
// ranks: sweep_phases.cpp; what rank 0 prints: sweep_report.cpp; the data
// sets: sweep_data.cpp.
// Size: one command; its rank-agreement steps read best in one place.
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <boost/mpi/collectives.hpp>
#include <boost/mpi/communicator.hpp>
#include <boost/mpi/environment.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/vector.hpp>
#include <torch/torch.h>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/early_signals.h"
#include "apps/provenance.h"
#include "apps/sweep_checkpoints.h"
#include "apps/sweep_data.h"
#include "apps/sweep_phases.h"
#include "apps/sweep_report.h"
#include "h5/h5file.h"
#include "phnn/common/counted.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "phnn/store/scratch_file.h"
#include "apps/sweep_search.h"
#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/search.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/merge.h"
#include "phnn/sweep/output_check.h"
#include "phnn/sweep/resumed_items.h"
#include "phnn/sweep/scheduler.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/sweep/sweep_growth.h"
#include "phnn/sweep/version.h"
#include "phnn/sweep/work_plan.h"
#include "phnn/sweep/writer_lock.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace apps {
namespace {

namespace mpi = boost::mpi;
using Clock = std::chrono::steady_clock;

// Set by SIGTERM / SIGUSR1 (Slurm's --signal before the time limit, or
// scancel) once the sweep writes: save the training state of the item in
// hand (sweep_checkpoints.h), take no new one, close the file cleanly.
// Before that a stop ends the process at once (early_signals.h).
volatile std::sig_atomic_t g_stop_signal = 0;

// --split and --max-group-size; throws cli::UsageError.
SplitOptions split_options(const cli::Parser& parser) {
  SplitOptions options;
  try {
    options.mode = parse_split_mode(parser.get("split"));
    options.max_group_size = parser.get_int_in("max-group-size", 0, 1 << 30);
    options.validate();
  } catch (const std::invalid_argument& e) {
    throw cli::UsageError{"phnn sweep: --split/--max-group-size: " + std::string(e.what())};
  }
  return options;
}

// --ranks for --dry-run: "128" or "2,16,128"; this run's size by default.
std::vector<int> dry_run_ranks(const cli::Parser& parser, int size) {
  if (!parser.has("ranks")) return {size};
  std::vector<int> ranks;
  for (std::int64_t r : cli::parse_int_list("ranks", parser.get("ranks"))) {
    if (r < 1) throw cli::UsageError{"phnn sweep: --ranks: every rank count must be >= 1"};
    ranks.push_back(static_cast<int>(r));
  }
  return ranks;
}

void declare_options(cli::Parser* parser) {
  parser->positional("FILE", "sweep file (sweeps/*.toml; format: sweeps/FORMAT.md)");
  parser->option("out", "results file (default: the sweep file's `output`)");
  parser->flag("dry-run",
               "print `N runs in M cells`, the estimated cost and the simulated schedule "
               "(items, makespan, core-hours, efficiency); train nothing");
  parser->flag("cell-costs",
               "with --dry-run: the cost model's estimate of every cell as CSV (cell, "
               "configuration, members, fixed/member/estimated seconds, run ids) instead of "
               "the summary");
  parser->flag("items",
               "with --dry-run and one --ranks value: the plan's work items as CSV (item, "
               "cell, runs, estimated seconds, run ids) in the order the ranks take them, "
               "instead of the summary");
  parser->option("ranks",
                 "rank counts for --dry-run's schedule, one line each, e.g. 2,16,128 "
                 "(default: this run's)");
  parser->option("split",
                 "auto: split cells into contiguous member groups where the cost model's "
                 "simulated schedule on this run's ranks is >1 % shorter (results are identical "
                 "either way); off: one item per cell",
                 "auto");
  parser->option("max-group-size",
                 "at most K runs per work item (forces splitting, with --split auto); 0 = no cap",
                 "0");
  parser->flag("static", "static round-robin scheduling instead of the MPI-3 shared counter");
  parser->flag("retry-failed", "re-run runs whose status is failed (done/diverged are kept)");
  parser->flag("mix-kernels", "resume a results file whose runs another kernel set computed, "
                              "or whose stored data sets this binary does not regenerate bit for "
                              "bit (results differ by round-off; refused without it)");
  parser->option("shard",
                 "I/N: train only cells c with c % N == I (cells largest first), into "
                 "<output>.shard-I-of-N.h5 unless --out is given; one shard per Slurm array "
                 "task, then `phnn merge` (docs/SLURM.md)");
  parser->option("checkpoint-every",
                 "save each cell's training state every SECONDS of its training (and at once "
                 "on SIGTERM/SIGUSR1), beside the journals; a stopped, killed or requeued cell "
                 "goes on from it, bitwise as if never interrupted; 0: only on a signal",
                 "300");
  parser->option("threads", "LibTorch intra-op threads per rank", "1");
  parser->flag("quiet", "no per-item log lines");
}

// One `phnn sweep` on this rank: each phase that can fail on some ranks ends
// in agree(), so every rank fails together and none waits forever.
class SweepRun {
 public:
  SweepRun(int argc, char** argv, int first)
      : argc_(argc), argv_(argv), first_(first), rank_(world_.rank()), size_(world_.size()),
        root_(rank_ == 0),
        prefix_("[rank " + std::to_string(rank_) + "/" + std::to_string(size_) + "] "),
        parser_("sweep",
                "Runs a sweep file over the MPI ranks (mpirun -np N phnn sweep FILE):\n"
                "work items (cells, or member groups of a cell) largest first from a shared\n"
                "counter, one parallel HDF5 results file, resume by running the same command\n"
                "again. One sweep at a time writes a results file (<results>.lock).\n\n"
                "Example: mpirun -np 2 phnn sweep sweeps/demo.toml   (then: phnn reduce results/demo.h5)") {
    declare_options(&parser_);
  }

  int run() {
    bool help = false;
    // Bad configuration fails on every rank alike, before any collective I/O.
    if (int status = agreed(world_, true, [&] { help = !parse(); })) return status;
    if (help) return 0;
    if (const std::string problem = launch_problem(size_); !problem.empty()) {
      std::cerr << problem << "\n";
      return cli::kUsageError;
    }
    if (int status = check_same_sweep_file()) return status;
    out_ = parser_.has("out") ? parser_.get("out")
                              : (shard_.count > 1 ? shard_.output_path(spec_.output) : spec_.output);
    if (const std::string problem = output_name_problem(out_); !problem.empty()) {
      if (root_) std::cerr << "phnn sweep: " << problem << "\n";
      return cli::kUsageError;
    }
    if (parser_.flag_set("dry-run")) {
      if (root_) {
        if (parser_.flag_set("cell-costs")) {
          std::cout << cell_costs_csv(grid_);
        } else if (parser_.flag_set("items")) {
          std::cout << plan_items_csv(grid_, plan_work(grid_, ranks_.front(), split_));
        } else if (spec_.adaptive.enabled) {
          std::cout << adaptive_dry_run();
        } else if (spec_.search.enabled) {
          std::cout << search_dry_run(spec_, grid_, ranks_, split_);
        } else {
          std::cout << dry_run_summary(grid_, ranks_, split_);
        }
      }
      return 0;
    }
    if (int status = follow_output_link(root_, &out_)) return status;
    torch::set_num_threads(parser_.get_int_in("threads", 1, 4096));
    const Provenance session = session_provenance(MPI_COMM_WORLD, argc_, argv_);
    // Rank 0 alone creates or updates the file, serially; the other ranks open
    // it only to write their rows (docs/DECISIONS.md, "No rank waits forever").
    std::vector<int> status_codes;
    end_setup_stops();  // from here on a stop is graceful: the lock, the file
    data_.set_stop([] { return g_stop_signal != 0; });  // and a long data generation
    if (int status = agreed(world_, root_, [&] { status_codes = prepare_results(session); })) {
      return status;
    }
    mpi::broadcast(world_, status_codes, 0);
    mpi::broadcast(world_, session_, 0);
    if (in_rounds()) {
      if (int status = replay_rounds(&status_codes)) return status;
    }
    if (int status = open_results()) return status;
    if (int status = agreed(world_, true, [&] { journal_.emplace(out_, rank_); })) return status;
    return train_and_close(status_codes);
  }

 private:
  bool parse() {
    if (!parser_.parse(argc_, argv_, first_)) return false;
    spec_ = parse_sweep_file(parser_.get("FILE"));
    grid_ = expand_grid(spec_);
    parser_.get_int_in("threads", 1, 4096);
    // 0: save a cell's training state only when stopped by a signal.
    checkpoint_every_ = parser_.get_double_in("checkpoint-every", 0, 1e9);
    build_key_ = git_commit() + " threads=" + parser_.get("threads");
    state_key_ = spec_.text_hash + " " + build_key_;
    if (parser_.flag_set("cell-costs") && !parser_.flag_set("dry-run")) {
      throw cli::UsageError{"phnn sweep: --cell-costs prints the cost model's estimates and trains "
                            "nothing: add --dry-run"};
    }
    if (parser_.flag_set("items") &&
        (!parser_.flag_set("dry-run") || parser_.flag_set("cell-costs"))) {
      throw cli::UsageError{"phnn sweep: --items prints one plan's work items and trains "
                            "nothing: use it with --dry-run, without --cell-costs"};
    }
    split_ = split_options(parser_);
    // [search]: a rung's item goes on from the state of the same seeds at
    // the rung before, so cells stay whole unless --split asks otherwise.
    if (spec_.search.enabled && !parser_.has("split") && !parser_.has("max-group-size")) {
      split_.mode = SplitOptions::Mode::kOff;
    }
    if (parser_.has("shard")) {
      try {
        shard_ = Shard::parse(parser_.get("shard"));
      } catch (const std::invalid_argument& e) {
        throw cli::UsageError{cli::with_prefix("phnn sweep: ", e.what())};
      }
    }
    if (in_rounds() && shard_.count > 1) {
      throw cli::UsageError{"phnn sweep: --shard: an adaptive or search sweep ([adaptive], "
                            "[search]) decides each round from every cell's results, which one "
                            "shard does not hold; run it as one job (its ranks share the cells)"};
    }
    ranks_ = dry_run_ranks(parser_, size_);
    if (parser_.flag_set("items") && ranks_.size() != 1) {
      throw cli::UsageError{"phnn sweep: --items lists the items of one plan: give one rank "
                            "count, e.g. --ranks 128"};
    }
    return true;
  }

  // Every rank must have read the same file (shared filesystem).
  int check_same_sweep_file() {
    std::string root_hash = spec_.text_hash;
    mpi::broadcast(world_, root_hash, 0);
    const bool differs = root_hash != spec_.text_hash;
    return agree(world_, differs ? cli::kUsageError : 0,
                 differs ? "phnn sweep: " + parser_.get("FILE") + ": differs from rank 0's copy (hash " +
                               spec_.text_hash + " vs " + root_hash +
                               "); put it on a shared filesystem"
                         : std::string());
  }

  // Rank 0, alone: the writer lock and what is at out_ (prepare_output);
  // then the new file, or a copy of the one to resume, gets the data groups
  // it lacks, this session's provenance and the journals' results, and
  // replaces out_ atomically (scratch_file.h): a failure here (a full disk)
  // leaves out_ as it was. Returns every row's status code.
  std::vector<int> prepare_results(const Provenance& session) {
    const bool resume = prepare_output(out_, parser_.get("FILE"), spec_, grid_, &lock_) == 1;
    std::vector<int> codes;
    write_atomically(out_, resume ? "updating" : "creating", [&](const std::string& scratch) {
      std::optional<ResultsFile> file;
      if (resume) {
        copy_file(out_, scratch);
        file.emplace(ResultsFile::open(scratch, MPI_COMM_NULL, spec_.text_hash));
        const std::string problem =
            kernel_mix_problem(file->read_sessions(), file->sessions_with_runs(),
                               kernel_set_of(session), out_);
        if (!problem.empty() && !parser_.flag_set("mix-kernels")) {
          throw cli::UsageError{"phnn sweep: " + problem};
        }
        repair_file_damage(&*file, out_, spec_, grid_, &data_);
        if (!parser_.flag_set("mix-kernels")) check_stored_data(*file);
      } else {
        std::vector<std::string> studies;
        for (const auto& s : grid_.run_studies) studies.push_back(join(s, ","));
        file.emplace(ResultsFile::create(scratch, MPI_COMM_NULL, grid_.runs, studies, spec_.name,
                                         spec_.text, spec_.text_hash, program_version(),
                                         ResultsLayout::for_runs(grid_.runs),
                                         ResultsFile::CreateMode::kInPlace));
      }
      store_missing_data(&*file, resume);
      session_ = file->begin_session(session);
      codes = recover_from_journals(&*file, out_, !resume);
      file->close();
    });
    return codes;
  }

  // A resume regenerates each system's data set: it must be the stored one
  // (a measured data file has its own checksum, checked where it is read).
  void check_stored_data(const ResultsFile& file) {
    std::set<std::string> systems;
    for (const RunConfig& run : grid_.runs) systems.insert(run.system_name());
    for (const std::string& name : systems) {
      const SweepSystemFile* system_file = spec_.system_file(name);
      if (!file.has_system_data(name) || (system_file && system_file->is_data())) continue;
      data_.make(name);
      const std::string problem = data_.stored_data_problem(name, file);
      if (!problem.empty()) throw cli::UsageError{"phnn sweep: " + out_ + ": " + problem};
    }
  }

  // /data/<system> for every system of the grid: written at creation, and
  // again on resume if a crash during creation left it missing.
  void store_missing_data(ResultsFile* file, bool resume) {
    std::set<std::string> systems;
    for (const RunConfig& run : grid_.runs) systems.insert(run.system_name());
    std::vector<std::string> missing;
    for (const std::string& name : systems) {
      if (file->has_system_data(name)) continue;
      data_.make(name);
      data_.store(name, file);
      missing.push_back(name);
    }
    if (resume && !missing.empty()) {
      std::cerr << "phnn sweep: " << out_ << ": wrote the missing data group(s) /data/"
                << join(missing, ", /data/") << "\n";
    }
  }

  struct Planned {
    WorkPlan plan;  // items: the resumed ones first
    int runs_done_before = 0, runs_to_do = 0;
    std::size_t resumed = 0;
  };
  Planned plan(const std::vector<int>& status_codes);
  struct RoundOutcome {
    int my_runs = 0;
    std::string io_error;
    bool stopped = false;  // a stop signal on any rank
  };
  RoundOutcome train_round(const std::vector<int>& status_codes);
  int train_and_close(std::vector<int> status_codes);
  int open_results() {
    return agreed(world_, true, [&] {
      results_.emplace(ResultsFile::open(out_, MPI_COMM_WORLD, spec_.text_hash));
    });
  }
  int replay_rounds(std::vector<int>* status_codes);
  // Trained in rounds decided on the results: [adaptive] or [search].
  bool in_rounds() const { return spec_.adaptive.enabled || spec_.search.enabled; }
  std::string adaptive_dry_run() const;
  std::string adaptive_line() const;
  // Seconds since this sweep started.
  double elapsed() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
  }
  int close_and_report(std::string io_error, bool stopped, int total_runs, double seconds);

  int argc_;
  char** argv_;
  int first_;
  mpi::communicator world_;
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
  bool planned_once_ = false;
  Clock::time_point start_ = Clock::now();
};

// Trains one item's cell, from its saved state if it has one. A cell that
// throws is a result too: every run failed, with the message. A cell stopped
// by a signal returns no results (its state is saved; *interrupted), and so
// does one whose data set a signal stopped while it was being generated.
std::vector<RunResult> train_item(const CellSpec& cell, SweepDataSets* data,
                                  const std::string& system, const std::function<void()>& tick,
                                  ItemCheckpoints* checkpoints, const std::string& prefix,
                                  int item_number, bool* interrupted) {
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
      std::fprintf(stderr, "%sitem %d: %s; training it from the start\n", prefix.c_str(),
                   item_number, e.what());
      checkpoints->forget_state();
      return data->train(cell, system, progress, &checkpoints->checkpointing());
    }
  } catch (const CellInterrupted& e) {
    *interrupted = true;
    if (checkpoints->saved_step() == e.step) {
      std::fprintf(stderr, "%sitem %d stopped after step %d of %d; its training state is in %s\n",
                   prefix.c_str(), item_number, e.step, cell.training.steps,
                   checkpoints->path().c_str());
    } else {
      std::fprintf(stderr, "%sitem %d stopped after step %d of %d; its state could not be saved "
                   "(see above): it trains again from %s\n", prefix.c_str(), item_number, e.step,
                   cell.training.steps,
                   checkpoints->saved_step() > 0 || checkpoints->resume_step() > 0
                       ? "its last saved state"
                       : "the start");
    }
    return {};
  } catch (const GenerationStopped&) {  // a signal while this rank made its data: nothing trained
    *interrupted = true;
    std::fprintf(stderr, "%sitem %d stopped while making its data set; it trains at the next run\n",
                 prefix.c_str(), item_number);
    return {};
  } catch (const std::exception& e) {
    std::vector<RunResult> failed(cell.seeds.size());
    for (auto& r : failed) {
      r.status = RunStatus::kFailed;
      r.message = e.what();
    }
    std::fprintf(stderr, "%sitem %d failed: %s\n", prefix.c_str(), item_number, e.what());
    return failed;
  }
}

// "item 3/8: <cell>, 2 seeds", and where it goes on from a saved state.
void announce_item(const std::string& prefix, int number, std::size_t items,
                   const RunConfig& head, const CellSpec& cell, int resume_step) {
  print_item("%sitem %d/%zu: %s\n", prefix, number, items,
             describe(head) + ", " + std::to_string(cell.seeds.size()) + " seed" +
                 (cell.seeds.size() > 1 ? "s" : ""));
  if (resume_step > 0) {
    print_item("%sitem %d/%zu: going on after step %s\n", prefix, number, items,
               std::to_string(resume_step) + " of " + std::to_string(cell.training.steps) +
                   " (saved training state)");
  }
}

// Journal record first (the source of truth), then the row, each with the
// item's run times, for each run of the item. A failed journal append (a full disk) does
// not stop the row: its space was allocated when the file was made, so the
// result is kept there. Returns "" or the first I/O error.
std::string record_item(const Grid& grid, const WorkItem& item,
                        const std::vector<RunResult>& cell_results, const std::string& started,
                        const std::string& finished, Journal* journal, ResultsFile* results) {
  std::string error;
  auto attempt = [&](const auto& write) {
    try {
      write();
    } catch (const std::exception& e) {
      if (error.empty()) error = cli::with_prefix("phnn sweep: ", e.what());
    }
  };
  for (std::size_t k = 0; k < item.runs.size(); ++k) {
    const int row = item.runs[k];
    RunResult result = cell_results[k];
    result.started_utc = started;
    result.finished_utc = finished;
    attempt([&] { journal->append(grid.runs[static_cast<std::size_t>(row)].id(), result); });
    attempt([&] { results->write_run(row, result); });
  }
  return error;
}

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
      resumed = resumed_groups(grid_, &pending, out_, state_key_);
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
  if (root_) {
    print_plan(spec_, grid_, shard_, planned.runs_done_before, planned.runs_to_do, planned.plan,
               size_, queue.mode(), out_);
    if (planned.resumed > 0) {
      std::cout << "phnn sweep: " << planned.resumed
                << " of them go on from their saved training state\n";
    }
  }
  const bool quiet = parser_.flag_set("quiet");
  RoundOutcome outcome;
  double last_progress = -1e9;
  const ProgressLine progress_line(work, size_, queue.mode() == ScheduleMode::kStatic);
  auto report_progress = [&](bool force) {
    if (!root_ || quiet || (!force && elapsed() - last_progress < 10.0)) return;
    last_progress = elapsed();
    progress_line.print(queue.done(), elapsed());
  };
  // An I/O error on this rank: it takes no more items, nor do the others
  // after the one in hand; then every rank learns of it (agree below) and
  // exits 1 (outcome.io_error).
  // A stop signal on any rank stops every rank at its next item boundary:
  // this rank posts it at once, from the training's progress ticks too.
  auto post_stop = [&] {
    if (g_stop_signal != 0 && !queue.stop_requested()) queue.request_stop();
  };
  auto next_item = [&] {
    post_stop();
    return queue.next();
  };
  for (int i = next_item(); i >= 0; i = next_item()) {
    const WorkItem& item = work[static_cast<std::size_t>(i)];
    const RunConfig& head = grid_.runs[static_cast<std::size_t>(item.runs.front())];
    std::vector<int> seeds;
    for (int row : item.runs) seeds.push_back(grid_.runs[static_cast<std::size_t>(row)].seed);
    const CellSpec cell = cell_spec_for(head, seeds);
    ItemCheckpoints checkpoints(out_, item_key(grid_, item.runs, state_key_),
                                checkpoint_every_, &g_stop_signal, prefix_);
    link_rung_states(spec_, grid_, item.runs, out_, build_key_, &checkpoints);
    if (!quiet) announce_item(prefix_, i + 1, work.size(), head, cell, checkpoints.resume_step());
    const auto cell_start = Clock::now();
    const std::string started = utc_now();
    bool interrupted = false;
    const std::vector<RunResult> cell_results =
        train_item(cell, &data_, head.system_name(), [&] {
          post_stop();
          queue.progress();  // rank 0's window answers the others mid-cell too
          report_progress(false);
        }, &checkpoints, prefix_, i + 1, &interrupted);
    if (interrupted) {
      post_stop();
      break;
    }
    std::string& io_error = outcome.io_error;
    io_error = record_item(grid_, item, cell_results, started, utc_now(), &*journal_, &*results_);
    if (io_error.empty()) checkpoints.remove();
    outcome.my_runs += static_cast<int>(item.runs.size());
    if (!io_error.empty()) {
      queue.request_stop();  // the others stop at their next item too
      break;
    }
    queue.mark_done();
    if (!quiet) {
      print_item("%sitem %d/%zu done in %s\n", prefix_, i + 1, work.size(),
                 format_duration(std::chrono::duration<double>(Clock::now() - cell_start).count()));
    }
    report_progress(true);
  }
  post_stop();
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
    my_runs += round.my_runs;
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
    if (adaptive_.complete) break;
    if (round_runs == 0 && adaptive_.round == round_before) {  // never loop without progress
      round.io_error = prefix_ + "adaptive round " + std::to_string(round_before) +
                       " has pending runs that this sweep did not train; stopping";
      break;
    }
  }
  const int total_runs = mpi::all_reduce(world_, my_runs, std::plus<int>());
  const int failed = close_and_report(round.io_error, round.stopped, total_runs, elapsed());
  if (failed) return failed;
  return round.stopped ? kExitStopped : 0;
}

// Rank 0 replays an adaptive sweep's rounds on the file (closed on every
// rank), every rank gets the state, and the runs no round asked for read as
// finished in *status_codes, so no rank plans them.
int SweepRun::replay_rounds(std::vector<int>* status_codes) {
  std::vector<int> codes;
  if (int status = agreed(world_, root_, [&] {
        const ResultsFile file = ResultsFile::open_read_only(out_);
        const std::vector<RunStatus> statuses = file.read_statuses();
        adaptive_ = spec_.search.enabled
                        ? replay_search(spec_, grid_, statuses,
                                        file.read_double_column("best_validation_loss"),
                                        file.read_double_column("mse"))
                              .state
                        : replay_adaptive_rounds(spec_, grid_, statuses, file.read_double_column("mse"));
        for (RunStatus st : statuses) codes.push_back(static_cast<int>(st));
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
      << dry_run_summary(grid_, ranks_, split_);
  return out.str();
}

std::string SweepRun::adaptive_line() const {
  if (spec_.search.enabled) return search_complete_line(spec_, grid_, adaptive_);
  if (!spec_.adaptive.enabled || !adaptive_.complete) return "";
  const int asked = adaptive_.active_runs();
  const int left = static_cast<int>(grid_.runs.size()) - asked;
  return "adaptive sweep complete after round " + std::to_string(adaptive_.round) + ": " +
         std::to_string(asked) + " runs of at most " + std::to_string(grid_.runs.size()) +
         (left > 0 ? "; the " + std::to_string(left) + " pending runs are seeds no round asked for"
                   : " (every cell at max_seeds)");
}

}  // namespace

int run_sweep(int argc, char** argv, int first) {
  // Before MPI_Init: a SIGTERM/SIGUSR1 while starting up, or during the
  // symbolic work of a system file, is a clean stop too (exit 75, at once),
  // not 143/138; one caught before main (early_signals.h) counts.
  begin_setup_stops(&g_stop_signal, kExitStopped,
                    "phnn sweep: stopped on a signal; run the same command again to resume "
                    "(nothing was written yet)\n");
  mpi::environment env(argc, argv);
  return SweepRun(argc, argv, first).run();
}

}  // namespace apps
}  // namespace phnn
