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
#include <iostream>
#include <map>
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
#include "h5/h5file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/journal.h"
#include "phnn/sweep/results_file.h"
#include "phnn/sweep/scheduler.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/sweep/version.h"
#include "phnn/sweep/work_plan.h"
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

bool file_exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
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

// Runs of each cell still to train (pending, or failed with --retry-failed),
// in the cell's seed order; *done counts the others.
std::vector<std::vector<int>> pending_runs(const Grid& grid, const std::vector<int>& status_codes,
                                           bool retry_failed, int* done) {
  std::vector<std::vector<int>> pending(grid.cells.size());
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
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

}  // namespace

int run_sweep(int argc, char** argv, int first) {
  mpi::environment env(argc, argv);
  mpi::communicator world;
  const int rank = world.rank(), size = world.size();
  const bool root = rank == 0;
  const std::string prefix = "[rank " + std::to_string(rank) + "/" + std::to_string(size) + "] ";

  cli::Parser parser("sweep",
                     "Runs a sweep file over the MPI ranks (mpirun -np N phnn sweep FILE):\n"
                     "work items (cells, or member groups of a cell) largest first from a shared\n"
                     "counter, one parallel HDF5 results file, resume by running the same command\n"
                     "again.");
  parser.positional("FILE", "sweep file (sweeps/*.toml; format: sweeps/FORMAT.md)");
  parser.option("out", "results file (default: the sweep file's `output`)");
  parser.flag("dry-run",
              "print `N runs in M cells`, the estimated cost and the simulated schedule "
              "(items, makespan, core-hours, efficiency); train nothing");
  parser.option("ranks",
                "rank counts for --dry-run's schedule, one line each, e.g. 2,16,128 "
                "(default: this run's)");
  parser.option("split",
                "auto: split cells into contiguous member groups where the cost model's simulated "
                "schedule on this run's ranks is >1 % shorter (results are identical either way); "
                "off: one item per cell",
                "auto");
  parser.option("max-group-size",
                "at most K runs per work item (forces splitting, with --split auto); 0 = no cap",
                "0");
  parser.flag("static", "static round-robin scheduling instead of the MPI-3 shared counter");
  parser.flag("retry-failed", "re-run runs whose status is failed (done/diverged are kept)");
  parser.option("threads", "LibTorch intra-op threads per rank", "1");
  parser.flag("quiet", "no per-item log lines");
  // Bad configuration fails on every rank alike, before any collective call;
  // only rank 0 speaks.
  SweepSpec spec;
  Grid grid;
  SplitOptions split;
  std::vector<int> ranks;
  try {
    if (!parser.parse(argc, argv, first)) return 0;
    spec = parse_sweep_file(parser.get("FILE"));
    grid = expand_grid(spec);
    if (parser.get_int("threads") < 1) throw cli::UsageError{"phnn sweep: --threads must be >= 1"};
    split = split_options(parser);
    ranks = dry_run_ranks(parser, size);
  } catch (const cli::UsageError& e) {
    if (root) std::cerr << e.message << "\n";
    return cli::kUsageError;
  } catch (const std::invalid_argument& e) {
    if (root) std::cerr << "phnn sweep: " << e.what() << "\n";
    return cli::kUsageError;
  }

  // Every rank must have read the same file (shared filesystem).
  std::string root_hash = spec.text_hash;
  mpi::broadcast(world, root_hash, 0);
  const int mismatch = mpi::all_reduce(world, root_hash != spec.text_hash ? 1 : 0, mpi::maximum<int>());
  if (mismatch) {
    if (root_hash != spec.text_hash) {
      std::cerr << prefix << parser.get("FILE") << ": differs from rank 0's copy (hash "
                << spec.text_hash << " vs " << root_hash << "); put it on a shared filesystem\n";
    }
    return cli::kUsageError;
  }

  if (parser.flag_set("dry-run")) {
    if (root) std::cout << dry_run_summary(grid, ranks, split);
    return 0;
  }

  torch::set_num_threads(static_cast<int>(parser.get_int("threads")));
  const std::string out = parser.has("out") ? parser.get("out") : spec.output;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

  // --- open or create the results file ------------------------------------
  // 0 = create, 1 = resume, 2 = refuse (message printed by rank 0).
  int action = 0;
  std::string refusal;
  if (root) {
    make_parent_directories(out);
    if (file_exists(out)) {
      action = 1;
      if (!h5::File::is_hdf5(out)) {
        // Not readable as HDF5: a crash mid-creation. The journals hold every
        // finished run; set the broken file aside and rebuild.
        const std::string aside = out + ".unreadable-" + std::to_string(std::time(nullptr));
        std::rename(out.c_str(), aside.c_str());
        std::cerr << prefix << out << ": not a readable HDF5 file; moved to " << aside
                  << " and rebuilding from the journals\n";
        action = 0;
      } else {
        try {
          const ResultsFile existing = ResultsFile::open_read_only(out);
          if (existing.sweep_hash() != spec.text_hash) {
            refusal = out + " was written by sweep '" + existing.sweep_name() + "' (hash " +
                      existing.sweep_hash() + "), not by " + parser.get("FILE") + " (hash " +
                      spec.text_hash + "); pass a new --out path or delete the file";
            action = 2;
          }
        } catch (const std::exception& e) {
          refusal = e.what();
          action = 2;
        }
      }
    }
  }
  mpi::broadcast(world, action, 0);
  if (action == 2) {
    if (root) std::cerr << "phnn sweep: " << refusal << "\n";
    return cli::kUsageError;
  }

  // Data sets: deterministic, so every rank makes the ones it needs itself.
  std::map<SystemKind, int> max_train;
  for (const RunConfig& run : grid.runs) max_train[run.system] = std::max(max_train[run.system], run.n_train);
  std::map<SystemKind, SystemData> data;
  auto data_for = [&](SystemKind kind) -> const SystemData& {
    auto it = data.find(kind);
    if (it == data.end()) {
      it = data.emplace(kind, make_system_data(spec.physics.at(kind), spec.data, max_train[kind])).first;
    }
    return it->second;
  };

  ResultsFile results = [&]() -> ResultsFile {
    try {
      if (action == 1) return ResultsFile::open(out, MPI_COMM_WORLD, spec.text_hash);
      std::vector<std::string> studies;
      for (const auto& s : grid.run_studies) studies.push_back(join(s, ","));
      ResultsFile file = ResultsFile::create(out, MPI_COMM_WORLD, grid.runs, studies, spec.name, spec.text,
                                             spec.text_hash, program_version(),
                                             ResultsLayout::for_runs(grid.runs));
      for (const auto& [kind, n] : max_train) file.store_system_data(to_string(kind), data_for(kind));
      return file;
    } catch (const std::exception& e) {
      // Policy 4 (STYLE.md): an exception inside collective HDF5 code aborts.
      std::cerr << prefix << e.what() << "\n";
      MPI_Abort(MPI_COMM_WORLD, 1);
      throw;
    }
  }();

  // --- recover from the journals (the source of truth), then plan ---------
  std::vector<int> status_codes;
  if (root) {
    int skipped = 0;
    const auto journal = replay_journals(out, &skipped);
    std::vector<RunStatus> statuses = results.read_statuses();
    const auto ids = results.read_run_ids();
    int recovered = 0;
    for (std::size_t row = 0; row < ids.size(); ++row) {
      auto it = journal.find(ids[row]);
      if (it != journal.end() && statuses[row] != it->second.status) {
        results.write_run(static_cast<int>(row), it->second);
        statuses[row] = it->second.status;
        ++recovered;
      }
    }
    if (recovered || skipped) {
      std::cout << "phnn sweep: recovered " << recovered << " finished runs from the journals in "
                << journal_directory(out)
                << (skipped ? " (" + std::to_string(skipped) + " torn records skipped)" : "")
                << (action == 0 ? "; delete that directory with the file to start afresh" : "")
                << "\n";
    }
    for (RunStatus s : statuses) status_codes.push_back(static_cast<int>(s));
  }
  mpi::broadcast(world, status_codes, 0);
  // The same statuses on every rank give the same plan on every rank.
  int runs_done_before = 0;
  const WorkPlan plan = plan_work(
      grid, pending_runs(grid, status_codes, parser.flag_set("retry-failed"), &runs_done_before),
      size, split);
  const std::vector<WorkItem>& work = plan.items;
  const int runs_to_do = static_cast<int>(grid.runs.size()) - runs_done_before;
  ScheduleMode mode = parser.flag_set("static") ? ScheduleMode::kStatic : ScheduleMode::kDynamic;
  WorkQueue queue(MPI_COMM_WORLD, static_cast<int>(work.size()), mode);
  if (root) {
    std::cout << "phnn sweep: " << spec.name << ": " << grid.runs.size() << " runs in "
              << grid.cells.size() << " cells; " << runs_done_before << " finished before, "
              << runs_to_do << " to run in " << work.size() << " items (" << plan.cells
              << " cells, " << plan.split_cells << " split) on " << size << " rank"
              << (size > 1 ? "s" : "") << " (" << to_string(queue.mode()) << " scheduling) -> "
              << out << std::endl;
  }
  std::signal(SIGTERM, request_stop);
  std::signal(SIGUSR1, request_stop);

  // --- train ----------------------------------------------------------------
  Journal journal(out, rank);
  const bool quiet = parser.flag_set("quiet");
  int my_runs = 0;
  double last_progress = -1e9;
  auto report_progress = [&](bool force) {
    if (!root || (!force && elapsed() - last_progress < 10.0)) return;
    last_progress = elapsed();
    const int items_done = queue.done();
    const double minutes = elapsed() / 60.0;
    const double rate = minutes > 0 ? items_done / minutes : 0.0;
    const double runs_per_item = work.empty() ? 0.0 : static_cast<double>(runs_to_do) / work.size();
    std::string eta = "--";
    if (items_done > 0 && items_done < static_cast<int>(work.size())) {
      eta = format_duration((work.size() - items_done) / rate * 60.0);
    }
    std::printf("[progress] items %d/%zu  %.1f runs/min  elapsed %s  ETA %s\n", items_done,
                work.size(), rate * runs_per_item, format_duration(elapsed()).c_str(), eta.c_str());
    std::fflush(stdout);
  };
  for (int i = g_stop_signal ? -1 : queue.next(); i >= 0; i = g_stop_signal ? -1 : queue.next()) {
    const WorkItem& item = work[static_cast<std::size_t>(i)];
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
    if (!quiet) {
      std::printf("%sitem %d/%zu: %s, %zu seed%s\n", prefix.c_str(), i + 1, work.size(),
                  describe(head).c_str(), cell.seeds.size(), cell.seeds.size() > 1 ? "s" : "");
      std::fflush(stdout);
    }
    const auto cell_start = Clock::now();
    std::vector<RunResult> cell_results;
    try {
      cell_results = train_cell(cell, data_for(head.system), [&](const TrainProgress&) {
        report_progress(false);
      });
    } catch (const std::exception& e) {
      // A run that throws is a result too: status failed, with the message.
      cell_results.assign(cell.seeds.size(), RunResult{});
      for (auto& r : cell_results) {
        r.status = RunStatus::kFailed;
        r.message = e.what();
      }
      std::fprintf(stderr, "%sitem %d failed: %s\n", prefix.c_str(), i + 1, e.what());
    }
    for (std::size_t k = 0; k < item.runs.size(); ++k) {
      const int row = item.runs[k];
      journal.append(grid.runs[static_cast<std::size_t>(row)].id(), cell_results[k]);
      results.write_run(row, cell_results[k]);
    }
    my_runs += static_cast<int>(item.runs.size());
    queue.mark_done();
    if (!quiet) {
      std::printf("%sitem %d/%zu done in %s\n", prefix.c_str(), i + 1, work.size(),
                  format_duration(std::chrono::duration<double>(Clock::now() - cell_start).count()).c_str());
      std::fflush(stdout);
    }
    report_progress(true);
  }
  const int stopped = mpi::all_reduce(world, g_stop_signal ? 1 : 0, mpi::maximum<int>());
  queue.close();
  const int total_runs = mpi::all_reduce(world, my_runs, std::plus<int>());
  try {
    results.close();
  } catch (const std::exception& e) {
    std::cerr << prefix << e.what() << "\n";
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  if (root) {
    const ResultsFile summary = ResultsFile::open_read_only(out);
    int counts[4] = {0, 0, 0, 0};
    for (RunStatus s : summary.read_statuses()) ++counts[static_cast<int>(s)];
    std::printf("phnn sweep: %d runs trained in %s; %s now holds %d done, %d diverged, %d failed, "
                "%d pending of %d\n",
                total_runs, format_duration(elapsed()).c_str(), out.c_str(), counts[1], counts[2],
                counts[3], counts[0], summary.num_runs());
    if (stopped) {
      std::printf("phnn sweep: stopped on a signal; run the same command again to resume\n");
    } else if (counts[0] > 0 || counts[3] > 0) {
      std::printf("phnn sweep: runs remain; run the same command again%s\n",
                  counts[3] > 0 ? " with --retry-failed to retry the failed ones" : "");
    }
  }
  return stopped ? kExitStopped : 0;
}

}  // namespace apps
}  // namespace phnn
