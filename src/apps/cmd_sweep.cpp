// src/apps/cmd_sweep.cpp — `phnn sweep FILE`: every rank trains work items
// (cells, or member groups of a cell) taken from a shared queue; every result
// lands in one parallel HDF5 file, each run first in this rank's journal
// (fsync), then in its row of the file.
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
#include "apps/provenance.h"
#include "h5/h5file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/journal.h"
#include "phnn/sweep/merge.h"
#include "phnn/sweep/output_check.h"
#include "phnn/sweep/results_file.h"
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
// scancel): finish the item in hand, take no new one, close the file cleanly.
volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void request_stop(int signal) { g_stop_signal = signal; }

// Exit status of a sweep stopped by a signal: EX_TEMPFAIL, "try again" — the
// Slurm job script requeues on it.
constexpr int kExitStopped = 75;

void make_parent_directories(const std::string& path) {
  for (std::size_t pos = path.find('/', 1); pos != std::string::npos; pos = path.find('/', pos + 1)) {
    ::mkdir(path.substr(0, pos).c_str(), 0775);
  }
}

std::string join(const std::vector<std::string>& parts, const char* sep) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? sep : "") + parts[i];
  return out;
}

std::string format_duration(double seconds) {
  char buf[64];
  if (seconds < 120) std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  else if (seconds < 7200) std::snprintf(buf, sizeof buf, "%.1f min", seconds / 60);
  else std::snprintf(buf, sizeof buf, "%.1f h", seconds / 3600);
  return buf;
}

// Rank 0's [progress] line: items done, runs per minute, elapsed time, an ETA
// from the cost model (the estimated cost still to do over the estimated
// cost done per elapsed second: items are handed out largest first, so a
// count of items would overestimate), and the UTC time. Under static
// scheduling rank 0 sees only its own items (every size-th): the line counts
// that share and says so.
class ProgressLine {
 public:
  ProgressLine(const std::vector<WorkItem>& work, int ranks, bool static_share)
      : static_share_(static_share) {
    cost_.push_back(0.0);
    runs_.push_back(0);
    for (std::size_t i = 0; i < work.size(); i += static_share ? static_cast<std::size_t>(ranks) : 1) {
      cost_.push_back(cost_.back() + work[i].estimated_cost_s);
      runs_.push_back(runs_.back() + static_cast<long>(work[i].runs.size()));
    }
  }

  void print(int items_done, double elapsed_s) const {
    const std::size_t n = cost_.size() - 1;
    const std::size_t done = std::min<std::size_t>(static_cast<std::size_t>(items_done), n);
    const double minutes = elapsed_s / 60.0;
    std::string eta = "--";
    if (done > 0 && done < n && cost_[done] > 0.0) {
      eta = format_duration(elapsed_s * (cost_[n] - cost_[done]) / cost_[done]);
    }
    std::printf("[progress] items %zu/%zu%s  %.1f runs/min  elapsed %s  ETA %s  (%s)\n", done, n,
                static_share_ ? " (rank 0's share, static scheduling)" : "",
                minutes > 0 ? static_cast<double>(runs_[done]) / minutes : 0.0,
                format_duration(elapsed_s).c_str(), eta.c_str(), utc_now().c_str());
    std::fflush(stdout);
  }

 private:
  bool static_share_;
  std::vector<double> cost_;  // cumulative estimated cost of the items rank 0 counts
  std::vector<long> runs_;    // cumulative runs of the same items
};

// --split and --max-group-size; throws cli::UsageError.
SplitOptions split_options(const cli::Parser& parser) {
  SplitOptions options;
  try {
    options.mode = parse_split_mode(parser.get("split"));
    options.max_group_size = static_cast<int>(parser.get_int("max-group-size"));
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

// Runs of each cell of `shard` still to train (pending, or failed with
// --retry-failed), in the cell's seed order; *done counts the others.
std::vector<std::vector<int>> pending_runs(const Grid& grid, const std::vector<int>& status_codes,
                                           bool retry_failed, const Shard& shard, int* done) {
  std::vector<std::vector<int>> pending(grid.cells.size());
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    if (!shard.owns_cell(static_cast<int>(c))) continue;
    for (int row : grid.cells[c].runs) {
      const auto s = static_cast<RunStatus>(status_codes[static_cast<std::size_t>(row)]);
      if (s == RunStatus::kPending || (retry_failed && s == RunStatus::kFailed)) {
        pending[c].push_back(row);
      } else {
        ++*done;
      }
    }
  }
  return pending;
}

std::string describe(const RunConfig& run) {
  std::ostringstream s;
  s << to_string(run.system) << " " << model_label(run.model, run.integrator) << " "
    << to_string(run.size) << " n_train=" << run.n_train << " reg=" << to_string(run.regularizer);
  return s.str();
}

// Exit status of a sweep that failed at run time (usage errors: 2).
constexpr int kExitFailed = 1;

// Every rank passes its own (code, message); returns the largest code on
// every rank, and rank 0 prints each distinct non-empty message once. A
// collective call: every rank must reach it, which is the point — an error
// found on one rank reaches all of them instead of leaving them waiting.
int agree(const mpi::communicator& world, int code, const std::string& message) {
  const int worst = mpi::all_reduce(world, code, mpi::maximum<int>());
  if (worst == 0) return 0;
  std::vector<std::string> messages;
  mpi::gather(world, message, messages, 0);
  if (world.rank() == 0) {
    std::set<std::string> printed;
    for (std::size_t r = 0; r < messages.size(); ++r) {
      if (messages[r].empty() || !printed.insert(messages[r]).second) continue;
      if (r > 0) std::cerr << "[rank " << r << "/" << world.size() << "] ";
      std::cerr << messages[r] << "\n";
    }
    std::cerr.flush();
  }
  return worst;
}

// Runs `body` on the ranks where `here` is true, catching what it throws
// (usage errors and std::invalid_argument: status 2; others: 1), then
// agree(). `body` must not make collective calls.
template <class Body>
int agreed(const mpi::communicator& world, bool here, Body&& body) {
  int code = 0;
  std::string message;
  if (here) {
    try {
      body();
    } catch (const cli::UsageError& e) {
      code = cli::kUsageError;
      message = e.message;
    } catch (const std::invalid_argument& e) {
      code = cli::kUsageError;
      message = std::string("phnn sweep: ") + e.what();
    } catch (const std::exception& e) {
      code = kExitFailed;
      message = std::string("phnn sweep: ") + e.what();
    }
  }
  return agree(world, code, message);
}

// srun without PMI starts every task as rank 0 of 1: each would train the
// whole sweep. "" if this launch looks right.
std::string launch_problem(int size) {
  const char* step = std::getenv("SLURM_STEP_NUM_TASKS");
  const char* job = std::getenv("SLURM_NTASKS");
  const char* tasks = step != nullptr ? step : job;
  if (size != 1 || tasks == nullptr || std::atol(tasks) <= 1) return "";
  return std::string("phnn sweep: Slurm started ") + tasks +
         " tasks but MPI sees 1 rank here: every task would run the whole sweep. srun "
         "needs the PMI plugin of your MPI: `srun --mpi=pmix phnn sweep ...` (see `srun "
         "--mpi=list`), or start the ranks with `mpirun` inside the allocation";
}

// Rank 0, holding nothing yet: takes the writer lock of `out`, then decides
// what to do with what is there; a results file of another sweep text is
// replaced by its new version first (sweep_growth.h). Returns 0 = create,
// 1 = resume; throws (UsageError: refusal, status 2; runtime_error: lock
// held, I/O, status 1).
int prepare_output(const std::string& out, const std::string& sweep_path, const SweepSpec& spec,
                   const Grid& grid, WriterLock* lock) {
  make_parent_directories(out);
  const LockOutcome outcome = lock->acquire(out, spec.text_hash);
  if (!outcome.acquired) throw std::runtime_error(outcome.message);
  if (!outcome.message.empty()) std::cerr << outcome.message << "\n";
  const OutputCheck check = inspect_output(out, sweep_path, spec.text_hash);
  switch (check.state) {
    case OutputState::kMissing:
      return 0;
    case OutputState::kResumable:
      return 1;
    case OutputState::kOtherText:
      try {
        std::cout << "phnn sweep: " << write_grown_results(out, spec, grid, program_version())
                  << "\n";
      } catch (const RunSetRefused& e) {
        throw cli::UsageError{std::string("phnn sweep: ") + e.what()};
      }
      return 1;
    case OutputState::kEmpty:
    case OutputState::kDamaged: {
      const bool empty = check.state == OutputState::kEmpty;
      const std::string aside = move_aside(out, empty ? "empty" : "damaged");
      std::cerr << "phnn sweep: " << out << ": " << (empty ? "an empty file" : "damaged: ")
                << (empty ? "" : check.message) << "; moved to " << aside
                << "; rebuilding the results file from the journals in "
                << journal_directory(out) << "\n";
      return 0;
    }
    case OutputState::kRefused:
      break;
  }
  throw cli::UsageError{"phnn sweep: " + check.message};
}

void declare_options(cli::Parser* parser) {
  parser->positional("FILE", "sweep file (sweeps/*.toml; format: sweeps/FORMAT.md)");
  parser->option("out", "results file (default: the sweep file's `output`)");
  parser->flag("dry-run",
               "print `N runs in M cells`, the estimated cost and the simulated schedule "
               "(items, makespan, core-hours, efficiency); train nothing");
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
  parser->option("shard",
                 "I/N: train only cells c with c % N == I (cells largest first), into "
                 "<output>.shard-I-of-N.h5 unless --out is given; one shard per Slurm array "
                 "task, then `phnn merge` (docs/SLURM.md)");
  parser->option("threads", "LibTorch intra-op threads per rank", "1");
  parser->flag("quiet", "no per-item log lines");
}

// Rank 0: replays the journals (the source of truth) into the file and
// returns every row's status code.
std::vector<int> recover_from_journals(ResultsFile* results, const std::string& out,
                                       bool created) {
  int skipped = 0;
  const auto journal = replay_journals(out, &skipped);
  std::vector<RunStatus> statuses = results->read_statuses();
  const auto ids = results->read_run_ids();
  int recovered = 0;
  for (std::size_t row = 0; row < ids.size(); ++row) {
    auto it = journal.find(ids[row]);
    if (it != journal.end() && statuses[row] != it->second.status) {
      results->write_run(static_cast<int>(row), it->second);
      statuses[row] = it->second.status;
      ++recovered;
    }
  }
  if (recovered || skipped) {
    std::cout << "phnn sweep: recovered " << recovered << " finished runs from the journals in "
              << journal_directory(out)
              << (skipped ? " (" + std::to_string(skipped) + " torn records skipped)" : "")
              << (created ? "; delete that directory with the file to start afresh" : "") << "\n";
  }
  std::vector<int> codes;
  for (RunStatus s : statuses) codes.push_back(static_cast<int>(s));
  return codes;
}

// Rank 0's summary line(s) after the file is closed.
void print_summary(const std::string& out, int total_runs, double seconds, bool stopped,
                   const Shard& shard) {
  const ResultsFile summary = ResultsFile::open_read_only(out);
  int counts[4] = {0, 0, 0, 0};
  for (RunStatus s : summary.read_statuses()) ++counts[static_cast<int>(s)];
  std::printf("phnn sweep: %d runs trained in %s; %s now holds %d done, %d diverged, %d failed, "
              "%d pending of %d\n",
              total_runs, format_duration(seconds).c_str(), out.c_str(), counts[1], counts[2],
              counts[3], counts[0], summary.num_runs());
  if (stopped) {
    std::printf("phnn sweep: stopped on a signal; run the same command again to resume\n");
  } else if (shard.count > 1) {
    std::printf("phnn sweep: shard %d/%d done (the pending runs are other shards'); when every "
                "shard is done: phnn merge OUT SHARD...\n",
                shard.index, shard.count);
  } else if (counts[0] > 0 || counts[3] > 0) {
    std::printf("phnn sweep: runs remain; run the same command again%s\n",
                counts[3] > 0 ? " with --retry-failed to retry the failed ones" : "");
  }
}

CellSpec cell_of(const Grid& grid, const WorkItem& item) {
  const RunConfig& head = grid.runs[static_cast<std::size_t>(item.runs.front())];
  CellSpec cell;
  cell.model = head.model;
  cell.integrator = head.integrator;
  cell.size = head.size;
  cell.n_train = head.n_train;
  cell.regularizer = head.regularizer;
  cell.training = head.training;
  cell.seeds.clear();
  for (int row : item.runs) cell.seeds.push_back(grid.runs[static_cast<std::size_t>(row)].seed);
  return cell;
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
                "again. One sweep at a time writes a results file (<results>.lock).") {
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
    if (parser_.flag_set("dry-run")) {
      if (root_) std::cout << dry_run_summary(grid_, ranks_, split_);
      return 0;
    }
    torch::set_num_threads(static_cast<int>(parser_.get_int("threads")));
    out_ = parser_.has("out") ? parser_.get("out")
                              : (shard_.count > 1 ? shard_.output_path(spec_.output) : spec_.output);
    int action = 0;
    if (int status = agreed(world_, root_, [&] {
          action = prepare_output(out_, parser_.get("FILE"), spec_, grid_, &lock_);
        })) {
      return status;
    }
    mpi::broadcast(world_, action, 0);
    if (int status = open_results(action == 1)) return status;
    results_->begin_session(session_provenance(MPI_COMM_WORLD, argc_, argv_));
    if (int status = store_missing_data(action == 1)) return status;
    std::vector<int> status_codes;
    if (int status = agreed(world_, root_, [&] {
          status_codes = recover_from_journals(&*results_, out_, action == 0);
        })) {
      return status;
    }
    mpi::broadcast(world_, status_codes, 0);
    if (int status = agreed(world_, true, [&] { journal_.emplace(out_, rank_); })) return status;
    return train_and_close(status_codes);
  }

 private:
  bool parse() {
    if (!parser_.parse(argc_, argv_, first_)) return false;
    spec_ = parse_sweep_file(parser_.get("FILE"));
    grid_ = expand_grid(spec_);
    if (parser_.get_int("threads") < 1) throw cli::UsageError{"phnn sweep: --threads must be >= 1"};
    split_ = split_options(parser_);
    if (parser_.has("shard")) {
      try {
        shard_ = Shard::parse(parser_.get("shard"));
      } catch (const std::invalid_argument& e) {
        throw cli::UsageError{std::string("phnn sweep: ") + e.what()};
      }
    }
    ranks_ = dry_run_ranks(parser_, size_);
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

  int open_results(bool resume) {
    return agreed(world_, true, [&] {
      if (resume) {
        results_.emplace(ResultsFile::open(out_, MPI_COMM_WORLD, spec_.text_hash));
        return;
      }
      std::vector<std::string> studies;
      for (const auto& s : grid_.run_studies) studies.push_back(join(s, ","));
      results_.emplace(ResultsFile::create(out_, MPI_COMM_WORLD, grid_.runs, studies, spec_.name,
                                           spec_.text, spec_.text_hash, program_version(),
                                           ResultsLayout::for_runs(grid_.runs)));
    });
  }

  // Data sets: deterministic, so every rank makes the ones it needs itself.
  const SystemData& data_for(SystemKind kind) {
    auto it = data_.find(kind);
    if (it == data_.end()) {
      int max_train = 0;
      for (const RunConfig& run : grid_.runs) {
        if (run.system == kind) max_train = std::max(max_train, run.n_train);
      }
      it = data_.emplace(kind, make_system_data(spec_.physics.at(kind), spec_.data, max_train)).first;
    }
    return it->second;
  }

  // /data/<system> for every system of the grid: written at creation, and
  // again on resume if a crash during creation left it missing.
  int store_missing_data(bool resume) {
    std::set<SystemKind> systems;
    for (const RunConfig& run : grid_.runs) systems.insert(run.system);
    std::vector<std::string> missing;
    if (int status = agreed(world_, root_, [&] {
          for (SystemKind kind : systems) {
            if (!results_->has_system_data(to_string(kind))) missing.push_back(to_string(kind));
          }
        })) {
      return status;
    }
    mpi::broadcast(world_, missing, 0);
    for (const std::string& name : missing) {
      results_->store_system_data(name, data_for(parse_system(name)));
    }
    if (root_ && resume && !missing.empty()) {
      std::cerr << "phnn sweep: " << out_ << ": wrote the missing data group(s) /data/"
                << join(missing, ", /data/") << "\n";
    }
    return 0;
  }

  int train_and_close(const std::vector<int>& status_codes);

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
  std::string out_;
  WriterLock lock_;  // rank 0 only; released after the file is closed
  std::optional<ResultsFile> results_;
  std::optional<Journal> journal_;
  std::map<SystemKind, SystemData> data_;
  Clock::time_point start_ = Clock::now();
};

// Rank 0's opening line: what is done, what is left, how it is split.
void print_plan(const SweepSpec& spec, const Grid& grid, const Shard& shard,
                int runs_done_before, int runs_to_do, const WorkPlan& plan, int size,
                ScheduleMode mode, const std::string& out) {
  std::cout << "phnn sweep: " << spec.name << ": " << grid.runs.size() << " runs in "
            << grid.cells.size() << " cells; "
            << (shard.count > 1 ? "shard " + std::to_string(shard.index) + "/" +
                                      std::to_string(shard.count) + ": "
                                : std::string())
            << runs_done_before << " finished before, " << runs_to_do << " to run in "
            << plan.items.size() << " items (" << plan.cells << " cells, " << plan.split_cells
            << " split) on " << size << " rank" << (size > 1 ? "s" : "") << " ("
            << to_string(mode) << " scheduling) -> " << out << std::endl;
}

// Trains one item's cell. A cell that throws is a result too: every run
// failed, with the message.
std::vector<RunResult> train_item(const CellSpec& cell, const SystemData& data,
                                  const std::function<void()>& tick, const std::string& prefix,
                                  int item_number) {
  try {
    return train_cell(cell, data, [&](const TrainProgress&) { tick(); });
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

// Journal record first (the source of truth), then the run times and the
// row, for each run of the item. Returns "" or the I/O error.
std::string record_item(const Grid& grid, const WorkItem& item,
                        const std::vector<RunResult>& cell_results, const std::string& started,
                        const std::string& finished, Journal* journal, ResultsFile* results) {
  try {
    for (std::size_t k = 0; k < item.runs.size(); ++k) {
      const int row = item.runs[k];
      journal->append(grid.runs[static_cast<std::size_t>(row)].id(), cell_results[k]);
      results->write_run_times(row, started, finished);
      results->write_run(row, cell_results[k]);
    }
  } catch (const std::exception& e) {
    return std::string("phnn sweep: ") + e.what();
  }
  return "";
}

void print_item(const char* format, const std::string& prefix, int item_number,
                std::size_t items, const std::string& what) {
  std::printf(format, prefix.c_str(), item_number, items, what.c_str());
  std::fflush(stdout);
}

int SweepRun::train_and_close(const std::vector<int>& status_codes) {
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start_).count(); };
  // The same statuses on every rank give the same plan on every rank.
  int runs_done_before = 0;
  const auto pending =
      pending_runs(grid_, status_codes, parser_.flag_set("retry-failed"), shard_, &runs_done_before);
  const WorkPlan plan = plan_work(grid_, pending, size_, split_);
  const std::vector<WorkItem>& work = plan.items;
  int runs_to_do = 0;
  for (const auto& runs : pending) runs_to_do += static_cast<int>(runs.size());
  const ScheduleMode mode = parser_.flag_set("static") ? ScheduleMode::kStatic : ScheduleMode::kDynamic;
  WorkQueue queue(MPI_COMM_WORLD, static_cast<int>(work.size()), mode);
  if (root_) {
    print_plan(spec_, grid_, shard_, runs_done_before, runs_to_do, plan, size_, queue.mode(), out_);
  }
  const bool quiet = parser_.flag_set("quiet");
  int my_runs = 0;
  double last_progress = -1e9;
  const ProgressLine progress_line(work, size_, queue.mode() == ScheduleMode::kStatic);
  auto report_progress = [&](bool force) {
    if (!root_ || quiet || (!force && elapsed() - last_progress < 10.0)) return;
    last_progress = elapsed();
    progress_line.print(queue.done(), elapsed());
  };
  // An I/O error on this rank: it takes no more items; the others finish
  // theirs, then every rank learns of it (agree below) and exits 1.
  std::string io_error;
  for (int i = g_stop_signal ? -1 : queue.next(); i >= 0; i = g_stop_signal ? -1 : queue.next()) {
    const WorkItem& item = work[static_cast<std::size_t>(i)];
    const RunConfig& head = grid_.runs[static_cast<std::size_t>(item.runs.front())];
    const CellSpec cell = cell_of(grid_, item);
    if (!quiet) {
      print_item("%sitem %d/%zu: %s\n", prefix_, i + 1, work.size(),
                 describe(head) + ", " + std::to_string(cell.seeds.size()) + " seed" +
                     (cell.seeds.size() > 1 ? "s" : ""));
    }
    const auto cell_start = Clock::now();
    const std::string started = utc_now();
    const std::vector<RunResult> cell_results = train_item(
        cell, data_for(head.system), [&] { report_progress(false); }, prefix_, i + 1);
    io_error = record_item(grid_, item, cell_results, started, utc_now(), &*journal_, &*results_);
    if (!io_error.empty()) break;
    my_runs += static_cast<int>(item.runs.size());
    queue.mark_done();
    if (!quiet) {
      print_item("%sitem %d/%zu done in %s\n", prefix_, i + 1, work.size(),
                 format_duration(std::chrono::duration<double>(Clock::now() - cell_start).count()));
    }
    report_progress(true);
  }
  const int stopped = mpi::all_reduce(world_, g_stop_signal ? 1 : 0, mpi::maximum<int>());
  queue.close();
  const int total_runs = mpi::all_reduce(world_, my_runs, std::plus<int>());
  const int failed = agree(world_, io_error.empty() ? 0 : kExitFailed, io_error);
  try {
    results_->end_session(utc_now());
    results_->close();
  } catch (const std::exception& e) {
    std::cerr << prefix_ << e.what() << "\n";
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  if (root_) print_summary(out_, total_runs, elapsed(), stopped != 0, shard_);
  if (failed) return failed;
  return stopped ? kExitStopped : 0;
}

}  // namespace

int run_sweep(int argc, char** argv, int first) {
  // Before MPI_Init: a SIGTERM/SIGUSR1 while starting up is a clean stop too
  // (exit 75), not 143/138.
  std::signal(SIGTERM, request_stop);
  std::signal(SIGUSR1, request_stop);
  mpi::environment env(argc, argv);
  return SweepRun(argc, argv, first).run();
}

}  // namespace apps
}  // namespace phnn
