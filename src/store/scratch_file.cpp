// src/store/scratch_file.cpp — see include/phnn/store/scratch_file.h.
#include "phnn/store/scratch_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

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

void copy_file(const std::string& from, const std::string& to) {
  std::error_code error;
  std::filesystem::copy_file(from, to, error);
  if (error) {
    throw std::runtime_error("cannot copy " + from + " to " + to + ": " + error.message());
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
