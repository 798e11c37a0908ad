// src/sweep/writer_lock.cpp — `<results>.lock`: flock(2) plus the holder's
// name in the file (see include/phnn/sweep/writer_lock.h).
#include "phnn/sweep/writer_lock.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <sstream>
#include <stdexcept>

#include "phnn/common/utc_time.h"

namespace phnn {
namespace {

std::string errno_text() { return std::strerror(errno); }

// The whole file behind `fd` (at most 4 KiB: a lock file is a few lines).
std::string read_fd(int fd) {
  std::string text(4096, '\0');
  const ssize_t n = ::pread(fd, text.data(), text.size(), 0);
  text.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  return text;
}

std::string holder_text(const std::string& sweep_hash) {
  std::ostringstream s;
  s << "host = " << host_name() << "\npid = " << ::getpid() << "\nstarted = " << utc_now()
    << "\nsweep_hash = " << sweep_hash << "\n";
  return s.str();
}

// True unless the process is certainly gone (EPERM: alive, not ours).
bool process_alive(long pid) {
  if (pid <= 0) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

std::string refusal(const std::string& lock, const std::string& text) {
  const LockHolder holder = parse_lock_text(text);
  const std::string who =
      holder.pid > 0 ? holder.describe() : std::string("a process that has not written its name yet");
  const std::string results = lock.substr(0, lock.size() - 5);
  return results + " is being written by another phnn sweep: " + who + " (lock file " + lock +
         "); wait for it to finish, stop it, or pass another --out path";
}

std::string stale_note(const std::string& lock, const std::string& text) {
  const LockHolder holder = parse_lock_text(text);
  std::string why = "its lock was released";
  if (holder.host == host_name() && !process_alive(holder.pid)) why = "its process is gone";
  return "phnn sweep: " + lock + ": taking over a stale lock of " + holder.describe() + " (" +
         why + "); its results are resumed from the file and its journals";
}

bool flock_unsupported(int error) {
  return error == ENOLCK || error == EOPNOTSUPP || error == ENOSYS || error == EINVAL;
}

}  // namespace

std::string LockHolder::describe() const {
  return "pid " + std::to_string(pid) + " on host " + (host.empty() ? "?" : host) + " since " +
         (started.empty() ? "?" : started) + " (sweep hash " +
         (sweep_hash.empty() ? "?" : sweep_hash) + ")";
}

LockHolder parse_lock_text(const std::string& text) {
  LockHolder holder;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto eq = line.find(" = ");
    if (eq == std::string::npos) continue;
    const std::string key = line.substr(0, eq), value = line.substr(eq + 3);
    if (key == "host") holder.host = value;
    if (key == "started") holder.started = value;
    if (key == "sweep_hash") holder.sweep_hash = value;
    if (key == "pid") holder.pid = std::strtol(value.c_str(), nullptr, 10);
  }
  return holder;
}

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0 || buf[0] == '\0') return "unknown";
  return buf;
}

std::string WriterLock::lock_path(const std::string& results_path) {
  return results_path + ".lock";
}

WriterLock::WriterLock(WriterLock&& other) noexcept : path_(std::move(other.path_)), fd_(other.fd_) {
  other.fd_ = -1;
}

WriterLock& WriterLock::operator=(WriterLock&& other) noexcept {
  if (this != &other) {
    release();
    path_ = std::move(other.path_);
    fd_ = other.fd_;
    other.fd_ = -1;
  }
  return *this;
}

WriterLock::~WriterLock() { release(); }

LockOutcome WriterLock::acquire(const std::string& results_path, const std::string& sweep_hash) {
  release();
  const std::string lock = lock_path(results_path);
  // A holder that releases deletes the file: if we locked that deleted
  // inode, the path now names a new file, so try again (bounded).
  for (int attempt = 0; attempt < 10; ++attempt) {
    const int fd = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0664);
    if (fd < 0) {
      const int error = errno;
      struct stat there;
      if (::lstat(lock.c_str(), &there) == 0 && !S_ISREG(there.st_mode)) {
        throw std::runtime_error(lock + ": the writer lock's path is taken by " +
                                 (S_ISDIR(there.st_mode) ? "a directory" : S_ISLNK(there.st_mode)
                                      ? "a symbolic link" : "a FIFO, device or socket") +
                                 "; move it away or pass another --out path");
      }
      throw std::runtime_error(lock + ": cannot create the writer lock: " + std::strerror(error) +
                               (error == EACCES || error == EROFS
                                    ? "; the results directory must be writable" : ""));
    }
    struct stat mine;
    if (::fstat(fd, &mine) != 0 || !S_ISREG(mine.st_mode)) {
      ::close(fd);
      throw std::runtime_error(lock + ": not a regular file; remove it or pass another --out path");
    }
    bool text_only = false;
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      if (error == EWOULDBLOCK) {
        const std::string text = read_fd(fd);
        ::close(fd);
        return {false, refusal(lock, text)};
      }
      if (!flock_unsupported(error)) {
        ::close(fd);
        throw std::runtime_error(lock + ": flock failed: " + std::string(std::strerror(error)));
      }
      text_only = true;
    }
    struct stat named;
    if (::stat(lock.c_str(), &named) != 0 || named.st_ino != mine.st_ino ||
        named.st_dev != mine.st_dev) {
      ::close(fd);
      continue;
    }
    const std::string previous = read_fd(fd);
    LockOutcome outcome{true, ""};
    if (!previous.empty()) {
      const LockHolder holder = parse_lock_text(previous);
      const bool certainly_dead = holder.host == host_name() && !process_alive(holder.pid);
      if (text_only && !certainly_dead) {
        ::close(fd);
        return {false, refusal(lock, previous) +
                           " (this filesystem has no flock, so a holder on another host cannot "
                           "be checked: delete the lock file if that sweep is certainly dead)"};
      }
      outcome.message = stale_note(lock, previous);
    }
    const std::string text = holder_text(sweep_hash);
    if (::ftruncate(fd, 0) != 0 ||
        ::pwrite(fd, text.data(), text.size(), 0) != static_cast<ssize_t>(text.size())) {
      const std::string error = errno_text();
      ::close(fd);
      throw std::runtime_error(lock + ": cannot write the writer lock: " + error);
    }
    ::fsync(fd);
    path_ = lock;
    fd_ = fd;
    return outcome;
  }
  throw std::runtime_error(lock + ": the lock file keeps being replaced; is another sweep "
                                  "starting and stopping on the same output?");
}

void WriterLock::release() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // before close: no one can lock this inode and think it current
  ::close(fd_);
  fd_ = -1;
}

}  // namespace phnn
