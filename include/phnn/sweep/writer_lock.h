// include/phnn/sweep/writer_lock.h — the single-writer guard of a results
// file: `<results>.lock`, held with flock(2) for the whole sweep by rank 0.
#pragma once

#include <string>

namespace phnn {

/// Who holds (or last held) a lock file: its text, one `key = value` a line.
struct LockHolder {
  std::string host;
  long pid = 0;
  /// UTC, ISO 8601 ("2024-05-01T12:00:00Z").
  std::string started;
  std::string sweep_hash;

  /// "pid 1234 on host node07 since 2024-05-01T12:00:00Z (sweep hash 1a2b...)".
  std::string describe() const;
};

/// What WriterLock::acquire found.
struct LockOutcome {
  /// True if this process now holds the lock.
  bool acquired = false;
  /// acquired: "" or a note that a stale lock was taken over;
  /// otherwise the refusal, naming the holder and what to do.
  std::string message;
};

/// An exclusive, advisory lock on `<results path>.lock`. acquire() creates
/// the file, takes flock(LOCK_EX | LOCK_NB) on it and writes this process's
/// LockHolder into it; the lock lasts until release() or the destructor
/// (which delete the file) or the death of the process (the kernel drops the
/// flock; the file stays, naming its last holder, and the next acquire takes
/// it over with a note). A second WriterLock on the same path, in this or
/// any other process, fails at once with a message naming the holder.
///
/// Filesystems without flock (ENOLCK, EOPNOTSUPP) fall back to the file's
/// text: a holder on this host whose process is gone is stale and taken
/// over; any other holder is refused with the advice to delete the file if
/// it is certainly dead.
///
/// Usage (rank 0 only; broadcast the outcome so no rank waits):
///
///   WriterLock lock;
///   const LockOutcome outcome = lock.acquire("results/paper.h5", hash);
///   if (!outcome.acquired) fail(outcome.message);
class WriterLock {
 public:
  WriterLock() = default;
  WriterLock(WriterLock&& other) noexcept;
  WriterLock& operator=(WriterLock&& other) noexcept;
  WriterLock(const WriterLock&) = delete;
  WriterLock& operator=(const WriterLock&) = delete;
  ~WriterLock();

  /// `<results_path>.lock`.
  static std::string lock_path(const std::string& results_path);

  /// Takes the lock of `results_path` for a sweep of `sweep_hash`. Never
  /// blocks. Throws std::runtime_error naming the lock file if it cannot be
  /// created or written (e.g. read-only directory).
  LockOutcome acquire(const std::string& results_path, const std::string& sweep_hash);

  /// Deletes the lock file and drops the lock. Idempotent.
  void release();

  bool held() const { return fd_ >= 0; }

 private:
  std::string path_;
  int fd_ = -1;
};

/// Parses a lock file's text (missing keys stay empty / 0).
LockHolder parse_lock_text(const std::string& text);

/// This machine's host name (gethostname), "unknown" if it has none.
std::string host_name();

}  // namespace phnn
