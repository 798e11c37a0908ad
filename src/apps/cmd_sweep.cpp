// src/apps/cmd_sweep.cpp — `phnn sweep FILE`: every rank trains work items
// (cells, or member groups of a cell) taken from a shared queue; every result
// lands in one parallel HDF5 file, each run first in this rank's journal
// (fsync), then in its row of the file. Here: the options and the setup
// (SweepRun in sweep_run.h: parse, check, create or resume the results
// file); the rounds of work items: sweep_rounds.cpp; the phases that can fail
// on some ranks: sweep_phases.cpp; what rank 0 prints: sweep_report.cpp; the
// data sets: sweep_data.cpp.
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
#include "apps/sweep_run.h"
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

volatile std::sig_atomic_t g_stop_signal = 0;

namespace {

namespace mpi = boost::mpi;

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
  parser->flag("no-speculation",
               "[adaptive] and [search]: ranks left idle while a round drains "
               "wait instead of training runs of the next round (the certain ones, or under "
               "rule = \"column-best\" the likely ones)");
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
  parser->flag("timings", "at the end, where the time per work item went (training, its setup, "
               "journal, results row, shared queue), mean over every rank's items");
}

}  // namespace

SweepRun::SweepRun(int argc, char** argv, int first)
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

int SweepRun::run() {
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

bool SweepRun::parse() {
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
int SweepRun::check_same_sweep_file() {
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
std::vector<int> SweepRun::prepare_results(const Provenance& session) {
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
void SweepRun::check_stored_data(const ResultsFile& file) {
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
void SweepRun::store_missing_data(ResultsFile* file, bool resume) {
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
