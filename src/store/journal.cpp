// src/store/journal.cpp — the per-rank journal files: append a record and
// fsync it, replay the latest record of every run, delete old journals.
// The record format: journal_record.cpp.
#include "phnn/store/journal.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <vector>

namespace phnn {
namespace {

std::string errno_text() { return std::strerror(errno); }

std::string log_path(const std::string& results_path, int rank) {
  return journal_directory(results_path) + "/rank-" + std::to_string(rank) + ".log";
}

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void write_all(int fd, const std::string& text, const std::string& where) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      throw std::runtime_error(where + ": write failed: " + errno_text() +
                               "; is the disk full?");
    }
    done += static_cast<std::size_t>(n);
  }
}

void fsync_or_throw(int fd, const std::string& where) {
  while (::fsync(fd) != 0) {
    if (errno == EINTR) continue;
    throw std::runtime_error(where + ": fsync failed: " + errno_text() +
                             "; the record may not be on disk");
  }
}

// Best effort: makes a newly created log's directory entry durable.
void fsync_directory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

// The whole log `file`, opened without following a symbolic link.
std::string read_log(const std::string& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) {
    const bool link = errno == ELOOP;
    throw std::runtime_error(file + (link ? ": a symbolic link where a journal log must be; "
                                            "remove it (phnn never reads or writes through one)"
                                          : ": cannot read the journal: " + errno_text()));
  }
  std::string text;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const std::string error = errno_text();
      ::close(fd);
      throw std::runtime_error(file + ": cannot read the journal: " + error);
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return text;
}

// rank-<r>.log files of a journal directory with their rank, sorted by rank.
// A journal directory that is a symbolic link or not a directory throws.
std::vector<std::pair<int, std::string>> list_logs(const std::string& results_path) {
  std::vector<std::pair<int, std::string>> logs;
  const std::string problem = journal_directory_problem(results_path);
  if (!problem.empty()) throw std::runtime_error(problem);
  const std::string dir = journal_directory(results_path);
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) {
    if (errno == ENOENT) return logs;
    throw std::runtime_error(dir + ": cannot list the journal directory: " + errno_text());
  }
  while (const dirent* entry = ::readdir(d)) {
    const std::string name = entry->d_name;
    const std::string prefix = "rank-", suffix = ".log";
    if (name.size() <= prefix.size() + suffix.size() || name.compare(0, 5, prefix) != 0 ||
        name.compare(name.size() - 4, 4, suffix) != 0) {
      continue;
    }
    const std::string digits = name.substr(5, name.size() - 9);
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    logs.emplace_back(std::stoi(digits), dir + "/" + name);
  }
  ::closedir(d);
  std::sort(logs.begin(), logs.end());
  return logs;
}

}  // namespace

std::string journal_directory(const std::string& results_path) {
  return results_path + ".journal";
}

std::string journal_directory_problem(const std::string& results_path) {
  const std::string dir = journal_directory(results_path);
  struct stat st;
  if (::lstat(dir.c_str(), &st) != 0 || S_ISDIR(st.st_mode)) return "";
  if (S_ISLNK(st.st_mode)) {
    return dir + ": a symbolic link, but the journal of " + results_path +
           " must be a directory of its own (phnn never writes through a link); remove the "
           "link or pass another --out path";
  }
  return dir + ": not a directory, but the journal of " + results_path +
         " must live there; move it away or pass another --out path";
}

void ensure_journal_directory(const std::string& results_path, const std::string& where) {
  const std::string dir = journal_directory(results_path);
  if (::mkdir(dir.c_str(), 0755) != 0 && errno != EEXIST) {
    throw std::runtime_error(where + ": cannot create the journal directory: " + errno_text() +
                             "; is the output directory writable?");
  }
  const std::string problem = journal_directory_problem(results_path);
  if (!problem.empty()) throw std::runtime_error(where + ": " + problem);
}

Journal::Journal(const std::string& results_path, int rank)
    : path_(log_path(results_path, rank)), rank_(rank) {
  const std::string where = "[rank " + std::to_string(rank) + "] " + path_;
  const std::string dir = journal_directory(results_path);
  ensure_journal_directory(results_path, where);
  struct stat before {};
  const bool existed = ::lstat(path_.c_str(), &before) == 0;
  fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0) {
    if (errno == ELOOP) {
      throw std::runtime_error(where + ": a symbolic link where this rank's journal must be; "
                               "remove it (phnn never writes through one)");
    }
    throw std::runtime_error(where + ": cannot open the journal: " + errno_text());
  }
  struct stat opened;
  if (::fstat(fd_, &opened) != 0 || !S_ISREG(opened.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error(where + ": not a regular file; move it away");
  }
  if (!existed) fsync_directory(dir);
  // A torn last line (no newline) gets its newline now, so the next record
  // starts a line of its own.
  const off_t size = ::lseek(fd_, 0, SEEK_END);
  char last = '\n';
  if (size > 0 && ::pread(fd_, &last, 1, size - 1) == 1 && last != '\n') {
    write_all(fd_, "\n", where);
    fsync_or_throw(fd_, where);
  }
}

Journal::Journal(Journal&& other) noexcept
    : path_(std::move(other.path_)), rank_(other.rank_), fd_(other.fd_) {
  other.fd_ = -1;
}

Journal& Journal::operator=(Journal&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    rank_ = other.rank_;
    fd_ = other.fd_;
    other.fd_ = -1;
  }
  return *this;
}

Journal::~Journal() {
  if (fd_ >= 0) ::close(fd_);
}

void Journal::append(const std::string& run_id, const RunResult& result) {
  const std::string where = "[rank " + std::to_string(rank_) + "] " + path_;
  if (fd_ < 0) throw std::runtime_error(where + ": append to a moved-from Journal");
  // One write() of the whole line: O_APPEND keeps it contiguous; a crash can
  // only tear the end of it, which the checksum detects.
  write_all(fd_, internal::encode_journal_record(run_id, result, now_ns()) + "\n", where);
  fsync_or_throw(fd_, where);
}

std::map<std::string, RunResult> replay_journals(const std::string& results_path,
                                                 int* skipped_lines) {
  struct Latest {
    std::tuple<std::int64_t, int, std::size_t> order;  // time, rank, line
    RunResult result;
  };
  std::map<std::string, Latest> latest;
  int skipped = 0;
  for (const auto& [rank, file] : list_logs(results_path)) {
    std::istringstream in(read_log(file));
    std::string line;
    std::size_t line_number = 0;
    // getline also returns a last line without its newline (a torn record):
    // it is kept only if its checksum holds.
    while (std::getline(in, line)) {
      ++line_number;
      if (line.empty()) continue;
      std::string id;
      RunResult result;
      std::int64_t time_ns = 0;
      if (!internal::decode_journal_record(line, &id, &result, &time_ns)) {
        ++skipped;
        continue;
      }
      const auto order = std::make_tuple(time_ns, rank, line_number);
      auto it = latest.find(id);
      if (it == latest.end() || it->second.order < order) {
        latest[id] = Latest{order, std::move(result)};
      }
    }
  }
  if (skipped_lines) *skipped_lines = skipped;
  std::map<std::string, RunResult> out;
  for (auto& [id, entry] : latest) out.emplace(id, std::move(entry.result));
  return out;
}

void remove_journals(const std::string& results_path) {
  const std::string dir = journal_directory(results_path);
  struct stat st;
  if (::lstat(dir.c_str(), &st) == 0 && !S_ISDIR(st.st_mode)) return;  // not ours to empty
  for (const auto& log : list_logs(results_path)) {
    if (::unlink(log.second.c_str()) != 0 && errno != ENOENT) {
      throw std::runtime_error(log.second + ": cannot delete the old journal: " +
                               errno_text());
    }
  }
  ::rmdir(dir.c_str());  // fails harmlessly if missing or not empty
}

}  // namespace phnn
