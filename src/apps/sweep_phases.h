// src/apps/sweep_phases.h — the phases of `phnn sweep` that can fail on some
// ranks only, and how every rank then fails together (agree): the launch
// check, rank 0's output preparation (writer lock, resume, growth, damaged
// files) and journal recovery, and the plan of what is still to train.
#pragma once

#include <string>
#include <vector>

#include <boost/mpi/communicator.hpp>

#include "apps/cli.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/merge.h"  // Shard
#include "phnn/sweep/sweep_file.h"
#include "phnn/sweep/work_plan.h"
#include "phnn/sweep/writer_lock.h"

namespace phnn {
namespace apps {

/// Exit status of a sweep that failed at run time (usage errors: 2).
constexpr int kExitFailed = 1;
/// Exit status of a sweep stopped by a signal: EX_TEMPFAIL, "try again" —
/// the Slurm job script requeues on it.
constexpr int kExitStopped = 75;

// Every rank passes its own (code, message); returns the largest code on
// every rank, and rank 0 prints each distinct non-empty message once. A
// collective call: every rank must reach it, which is the point — an error
// found on one rank reaches all of them instead of leaving them waiting.
int agree(const boost::mpi::communicator& world, int code, const std::string& message);

// Runs `body` on the ranks where `here` is true, catching what it throws
// (usage errors and std::invalid_argument: status 2; others: 1), then
// agree(). `body` must not make collective calls.
template <class Body>
int agreed(const boost::mpi::communicator& world, bool here, Body&& body) {
  int code = 0;
  std::string message;
  if (here) {
    try {
      body();
    } catch (const cli::UsageError& e) {
      code = cli::kUsageError;
      message = e.message;
    } catch (const GenerationStopped&) {  // a signal during a long data generation
      code = kExitStopped;
      message = "phnn sweep: stopped on a signal while generating the data; run the same command "
                "again to resume (no run had started)";
    } catch (const std::invalid_argument& e) {
      code = cli::kUsageError;
      message = cli::with_prefix("phnn sweep: ", e.what());
    } catch (const std::exception& e) {
      code = kExitFailed;
      message = cli::with_prefix("phnn sweep: ", e.what());
    }
  }
  return agree(world, code, message);
}

/// srun without PMI starts every task as rank 0 of 1: each would train the
/// whole sweep. "" if this launch looks right.
std::string launch_problem(int size);

/// A symbolic link as --out: *out becomes the file it names (rank 0 says
/// so), so the sweep's lock and journals are that file's. Returns 0, or
/// cli::kUsageError for a link that names no file (rank 0 prints why).
int follow_output_link(bool root, std::string* out);

/// Rank 0, holding nothing yet: takes the writer lock of `out`, then decides
/// what to do with what is there; a results file of another sweep text is
/// replaced by its new version first (sweep_growth.h). Returns 0 = create,
/// 1 = resume; throws (UsageError: refusal, status 2; runtime_error: lock
/// held, I/O, status 1).
int prepare_output(const std::string& out, const std::string& sweep_path, const SweepSpec& spec,
                   const Grid& grid, WriterLock* lock);

class SweepDataSets;  // apps/sweep_data.h

/// Rank 0, resuming (a serial copy of the file, checksum rule 2): repairs
/// what ResultsFile::file_damage finds: the sweep attributes and
/// configuration columns rewritten from the sweep's runs, a damaged /data
/// group stored again from the data this program makes (both must give the
/// recorded bytes), each named on stderr. Throws cli::UsageError naming
/// what it cannot repair and the way out (move the file aside).
void repair_file_damage(ResultsFile* file, const std::string& out, const SweepSpec& spec,
                        const Grid& grid, SweepDataSets* data);

/// Rank 0: replays the journals (the source of truth) into the file and
/// returns every row's status code; damaged rows first (rewritten from
/// their record, or trained again).
std::vector<int> recover_from_journals(ResultsFile* results, const std::string& out,
                                       bool created);

/// Runs of each cell of `shard` still to train (pending, or failed with
/// --retry-failed), in the cell's seed order; *done counts the others.
std::vector<std::vector<int>> pending_runs(const Grid& grid, const std::vector<int>& status_codes,
                                           bool retry_failed, const Shard& shard, int* done);

std::string join(const std::vector<std::string>& parts, const char* sep);

}  // namespace apps
}  // namespace phnn
