// src/store/scratch_file.cpp — see include/phnn/store/scratch_file.h.
#include "phnn/store/scratch_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace phnn {
namespace {

std::string errno_text() { return std::strerror(errno); }

void fsync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) throw std::runtime_error(path + ": cannot open to sync: " + errno_text());
  const int status = ::fsync(fd);
  ::close(fd);
  if (status != 0 && flags != O_RDONLY) {  // directories: best effort
    throw std::runtime_error(path + ": fsync failed: " + errno_text());
  }
}

}  // namespace

std::string parent_directory(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string scratch_path(const std::string& out, const std::string& suffix) {
  const std::string path = out + "." + suffix;
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return path;
  char head[4] = {};
  std::ifstream in(path, std::ios::binary);
  const bool hdf5 = in.read(head, 4) && std::memcmp(head, "\x89HDF", 4) == 0;
  if (!S_ISREG(st.st_mode) || (st.st_size > 0 && !hdf5)) {
    throw std::runtime_error(path + ": exists and is not a results file phnn left behind; move "
                             "it away (phnn writes a results file there before renaming it)");
  }
  if (std::remove(path.c_str()) != 0) {
    throw std::runtime_error(path + ": cannot remove a leftover of an earlier run: " +
                             errno_text());
  }
  return path;
}

// A plain read/write loop: std::filesystem::copy_file reports a short
// sendfile (a full disk) as EIO, which hides the cause.
void copy_file(const std::string& from, const std::string& to) {
  const std::string what = "cannot copy " + from + " to " + to + ": ";
  const int in = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) throw std::runtime_error(what + errno_text());
  struct stat st;
  const mode_t mode = ::fstat(in, &st) == 0 ? (st.st_mode & 0777) : 0644;
  const int out = ::open(to.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
  if (out < 0) {
    const std::string error = errno_text();
    ::close(in);
    throw std::runtime_error(what + error);
  }
  std::string error;
  std::vector<char> buffer(1 << 20);
  for (;;) {
    const ssize_t n = ::read(in, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n < 0) error = errno_text();
      break;
    }
    for (ssize_t done = 0; done < n && error.empty();) {
      const ssize_t w = ::write(out, buffer.data() + done, static_cast<std::size_t>(n - done));
      if (w < 0 && errno == EINTR) continue;
      if (w < 0) error = errno_text();
      if (w > 0) done += w;
    }
    if (!error.empty()) break;
  }
  ::close(in);
  if (::close(out) != 0 && error.empty()) error = errno_text();
  if (!error.empty()) {
    ::unlink(to.c_str());
    throw std::runtime_error(what + error + (error == std::strerror(ENOSPC) ? "; free space "
                                             "(a resume copies the file once)" : ""));
  }
}

void commit_scratch(const std::string& scratch, const std::string& out) {
  fsync_path(scratch, O_RDWR);
  if (std::rename(scratch.c_str(), out.c_str()) != 0) {
    throw std::runtime_error(scratch + ": cannot rename it to " + out + ": " + errno_text());
  }
  fsync_path(parent_directory(out), O_RDONLY);
}

}  // namespace phnn
