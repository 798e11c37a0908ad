// include/phnn/store/journal.h — per-rank append-only record of finished
// runs: the source of truth for recovering a sweep (the results file is
// rebuilt from it on resume).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "phnn/config/run_result.h"

namespace phnn {

/// Appends one line per finished run to `<results path>.journal/rank-<r>.log`
/// and fsyncs it before append() returns, so a run that append() reported is
/// never lost, whatever happens to the process or to the HDF5 file later.
///
/// Line format (docs/RESULTS_FORMAT.md, "Journal"):
///
///   run <id> v=1 time=<ns> status=done message=... mse=0x1.8p-7 ...
///       ... fnv1a64=<16 hex digits>\n
///
/// doubles as C99 hex floats (%a; NaN as nan, -nan or nan_<IEEE bits in hex>)
/// so replay is bit-exact, strings percent-encoded, and the checksum is the
/// FNV-1a 64 of everything before " fnv1a64=". A line torn by a crash fails
/// the checksum and is skipped by replay_journals().
///
/// Usage (one Journal per rank):
///
///   Journal journal(out_path, rank);
///   journal.append(config.id(), result);   // then ResultsFile::write_run
class Journal {
 public:
  /// Creates the journal directory if needed and opens this rank's log for
  /// appending (O_NOFOLLOW: a log or directory that is a symbolic link is
  /// refused, never written through). If the log ends in a torn line (a crash mid-append), a
  /// newline is added so that fragment stays one skipped line and does not
  /// swallow the next record. Throws std::runtime_error naming the file.
  Journal(const std::string& results_path, int rank);
  Journal(Journal&& other) noexcept;
  Journal& operator=(Journal&& other) noexcept;
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;
  ~Journal();

  /// Appends one record and fsyncs it. Throws std::runtime_error (with the
  /// rank and the file) if the write or the fsync fails.
  void append(const std::string& run_id, const RunResult& result);

  /// The log file of this rank.
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int rank_ = 0;
  int fd_ = -1;
};

/// `<results path>.journal`, the directory that holds the rank-<r>.log files.
std::string journal_directory(const std::string& results_path);

/// Why the journal directory of `results_path` cannot be used ("" if it can,
/// or is missing): it is a symbolic link (never followed: records would land
/// in whatever it points to) or not a directory. Names the path and the fix.
std::string journal_directory_problem(const std::string& results_path);

/// Creates the journal directory if missing; throws std::runtime_error
/// (prefixed by `where`) with journal_directory_problem() if it is a
/// symbolic link or not a directory, or if it cannot be created.
void ensure_journal_directory(const std::string& results_path, const std::string& where);

/// Reads every rank-*.log under journal_directory(results_path), whatever the
/// rank count that wrote them, and returns the latest record of each run id
/// (the greatest time=; on equal times the higher rank, then the later line).
/// Torn or corrupt lines are skipped and counted in *skipped_lines. A missing
/// directory is an empty journal. Throws std::runtime_error if a log exists
/// but cannot be read, or if the directory or a log is a symbolic link.
std::map<std::string, RunResult> replay_journals(
    const std::string& results_path, int* skipped_lines = nullptr);

/// Deletes the rank-*.log files of `results_path` and then the directory if
/// it is empty: for a fresh start whose results must not come from an earlier
/// job (ResultsFile::create does not call it). Call it on one rank before any
/// rank constructs its Journal. Never throws for a missing directory.
void remove_journals(const std::string& results_path);

namespace internal {

/// One journal line without its trailing newline (exposed for tests).
std::string encode_journal_record(const std::string& run_id,
                                  const RunResult& result,
                                  std::int64_t time_ns);
/// Parses a line written by encode_journal_record (with or without the
/// newline); false if it is torn, corrupt or fails its checksum.
bool decode_journal_record(const std::string& line, std::string* run_id,
                           RunResult* result, std::int64_t* time_ns);

}  // namespace internal
}  // namespace phnn
