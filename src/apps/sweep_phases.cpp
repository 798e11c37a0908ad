// src/apps/sweep_phases.cpp — see sweep_phases.h.
#include "apps/sweep_phases.h"

#include <sys/stat.h>

#include <cstdlib>
#include <iostream>
#include <map>
#include <set>

#include <boost/mpi/collectives.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/vector.hpp>

#include "apps/sweep_data.h"
#include "phnn/store/journal.h"
#include "phnn/sweep/output_check.h"
#include "phnn/sweep/sweep_growth.h"
#include "phnn/sweep/version.h"

namespace phnn {
namespace apps {

namespace mpi = boost::mpi;

namespace {

void make_parent_directories(const std::string& path) {
  for (std::size_t pos = path.find('/', 1); pos != std::string::npos; pos = path.find('/', pos + 1)) {
    ::mkdir(path.substr(0, pos).c_str(), 0775);
  }
}

}  // namespace

std::string join(const std::vector<std::string>& parts, const char* sep) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? sep : "") + parts[i];
  return out;
}

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

int follow_output_link(bool root, std::string* out) {
  std::string target;
  const std::string problem = resolve_output_link(*out, &target);
  if (!problem.empty()) {
    if (root) std::cerr << "phnn sweep: " << problem << "\n";
    return cli::kUsageError;
  }
  if (root && target != *out) {
    std::cerr << "phnn sweep: " << *out << " is a symbolic link; writing the file it names, "
              << target << "\n";
  }
  *out = target;
  return 0;
}

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
        // Computed first: an error must not follow a half-printed line.
        const std::string grown = write_grown_results(out, spec, grid, program_version());
        std::cout << "phnn sweep: " << grown << "\n";
      } catch (const RunSetRefused& e) {
        throw cli::UsageError{cli::with_prefix("phnn sweep: ", e.what())};
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

namespace {

// Rows whose check fails (their checksum, or a value out of range):
// every result column rewritten from the journal's record, or, if the
// journal lacks it or its record does not fit the row, made pending again
// (trained anew: the same bits); each named. `phnn verify` tells the same
// apart with the same calls (ResultsFile::rewrite_problem).
void repair_damaged_rows(ResultsFile* results, const std::map<std::string, RunResult>& journal,
                         const std::vector<std::string>& ids, const std::string& out) {
  std::vector<std::string> repaired, requeued, unfit;
  for (int row : results->damaged_rows()) {
    const std::string& id = ids[static_cast<std::size_t>(row)];
    const auto it = journal.find(id);
    const std::string problem =
        it == journal.end() ? "" : results->rewrite_problem(row, it->second);
    if (it != journal.end() && problem.empty()) {
      results->write_run(row, it->second);
      repaired.push_back(id);
    } else {
      results->requeue_run(row);
      if (problem.empty()) {
        requeued.push_back(id);
      } else {
        unfit.push_back(id + " (" + problem + ")");
      }
    }
  }
  const std::string head = "phnn sweep: " + out + ": ";
  if (!repaired.empty()) {
    std::cerr << head << repaired.size()
              << " damaged rows (checksum mismatch) repaired from the journals: "
              << join(repaired, ", ") << "\n";
  }
  if (!requeued.empty()) {
    std::cerr << head << requeued.size() << " damaged rows not in the journals, trained again: "
              << join(requeued, ", ") << "\n";
  }
  if (!unfit.empty()) {
    std::cerr << head << unfit.size() << " damaged rows whose journal record does not fit the "
              << "row, trained again: " << join(unfit, ", ") << "\n";
  }
}

}  // namespace

void repair_file_damage(ResultsFile* file, const std::string& out, const SweepSpec& spec,
                        const Grid& grid, SweepDataSets* data) {
  if (file->checksum_version() != ResultsFile::kChecksumVersion) return;
  std::vector<std::string> studies;
  for (const auto& s : grid.run_studies) studies.push_back(join(s, ","));
  std::vector<std::string> repaired;
  try {
    repaired = file->repair_configuration(grid.runs, studies, spec.name, spec.text,
                                          spec.text_hash);
    std::set<std::string> systems;
    for (const RunConfig& run : grid.runs) systems.insert(run.system_name());
    for (const std::string& name : systems) {
      const auto fixed = file->repair_system_data(name, [&] {
        data->make(name);
        data->store(name, file);
      });
      repaired.insert(repaired.end(), fixed.begin(), fixed.end());
    }
  } catch (const std::exception& e) {
    throw cli::UsageError{"phnn sweep: " + std::string(e.what()) +
                          "; nothing changed. Move the file aside: `phnn sweep` then rebuilds "
                          "it from the journals in " + journal_directory(out) +
                          " (runs they lack are trained again)"};
  }
  if (!repaired.empty()) {
    std::cerr << "phnn sweep: " << out << ": damaged, rewritten from the sweep file and its "
              << "data as recorded: " << join(repaired, ", ") << "\n";
  }
}

std::vector<int> recover_from_journals(ResultsFile* results, const std::string& out,
                                       bool created) {
  int skipped = 0;
  const auto journal = replay_journals(out, &skipped);
  const auto ids = results->read_run_ids();
  repair_damaged_rows(results, journal, ids, out);
  std::vector<RunStatus> statuses = results->read_statuses();
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

}  // namespace apps
}  // namespace phnn
