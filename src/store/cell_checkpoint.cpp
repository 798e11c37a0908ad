// src/store/cell_checkpoint.cpp — see include/phnn/store/cell_checkpoint.h.
// Touches only `<results path>.journal/cell-*.state` and their `.writing`
// scratch files.
#include "phnn/store/cell_checkpoint.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "phnn/config/run_config.h"
#include "phnn/store/journal.h"
#include "phnn/store/scratch_file.h"

namespace phnn {
namespace {

constexpr char kHeader[] = "phnn-cell-checkpoint 1\n";

std::string encode(const CellCheckpoint& c) {
  std::string body = kHeader;
  body += "step " + std::to_string(c.step) + "\n";
  body += "key " + std::to_string(c.key.size()) + "\n" + c.key;
  body += "\nstate " + std::to_string(c.state.size()) + "\n" + c.state;
  body += "\nfnv1a64 ";
  return body + hex64(fnv1a64(body)) + "\n";
}

// "<name> <n>\n" then n bytes at *pos; false if the text does not say that.
bool take_field(const std::string& text, const std::string& name, std::size_t* pos,
                std::string* value) {
  const std::string prefix = name + " ";
  if (text.compare(*pos, prefix.size(), prefix) != 0) return false;
  const std::size_t eol = text.find('\n', *pos);
  if (eol == std::string::npos) return false;
  std::size_t n = 0;
  try {
    n = std::stoull(text.substr(*pos + prefix.size(), eol - *pos - prefix.size()));
  } catch (const std::exception&) {
    return false;
  }
  if (n > text.size() - eol - 1) return false;
  *value = text.substr(eol + 1, n);
  *pos = eol + 1 + n;
  return true;
}

bool decode(const std::string& text, CellCheckpoint* out) {
  if (text.compare(0, sizeof(kHeader) - 1, kHeader) != 0) return false;
  std::size_t pos = sizeof(kHeader) - 1;
  CellCheckpoint c;
  const std::size_t eol = text.find('\n', pos);
  if (text.compare(pos, 5, "step ") != 0 || eol == std::string::npos) return false;
  try {
    c.step = std::stoi(text.substr(pos + 5, eol - pos - 5));
  } catch (const std::exception&) {
    return false;
  }
  pos = eol + 1;
  if (!take_field(text, "key", &pos, &c.key) || text.compare(pos, 1, "\n") != 0) return false;
  ++pos;
  if (!take_field(text, "state", &pos, &c.state)) return false;
  const std::string tail = "\nfnv1a64 ";
  if (text.compare(pos, tail.size(), tail) != 0) return false;
  const std::size_t sum_at = pos + tail.size();
  if (text.size() != sum_at + 17 || text.back() != '\n') return false;
  if (text.substr(sum_at, 16) != hex64(fnv1a64(text.substr(0, sum_at)))) return false;
  *out = std::move(c);
  return true;
}

void write_all(int fd, const std::string& bytes, const std::string& where) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(where + ": cannot write: " + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

std::string cell_checkpoint_path(const std::string& results_path, const std::string& key) {
  return journal_directory(results_path) + "/cell-" + hex64(fnv1a64(key)) + ".state";
}

std::string rung_state_path(const std::string& results_path, const std::string& key) {
  return journal_directory(results_path) + "/rung-" + hex64(fnv1a64(key)) + ".state";
}

void write_cell_checkpoint(const std::string& path, const CellCheckpoint& checkpoint) {
  const std::string dir = parent_directory(path);
  if (::mkdir(dir.c_str(), 0755) != 0 && errno != EEXIST) {
    throw std::runtime_error(dir + ": cannot create the journal directory: " +
                             std::strerror(errno));
  }
  struct stat st;
  if (::lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    throw std::runtime_error(dir + ": a symbolic link or not a directory; the training states "
                             "live in the journal directory itself: remove it");
  }
  const std::string scratch = path + ".writing";
  const int fd =
      ::open(scratch.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) throw std::runtime_error(scratch + ": cannot create: " + std::strerror(errno));
  try {
    try {
      write_all(fd, encode(checkpoint), scratch);
    } catch (...) {
      ::close(fd);
      throw;
    }
    if (::close(fd) != 0) throw std::runtime_error(scratch + ": " + std::strerror(errno));
    commit_scratch(scratch, path);
  } catch (...) {
    std::remove(scratch.c_str());
    throw;
  }
}

bool read_cell_checkpoint(const std::string& path, CellCheckpoint* out, std::string* problem) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream text;
  text << in.rdbuf();
  if (decode(text.str(), out)) return true;
  if (problem) *problem = path + ": damaged or torn (checksum or layout wrong)";
  return false;
}

std::vector<std::string> list_cell_checkpoints(const std::string& results_path) {
  const std::string dir = journal_directory(results_path);
  std::vector<std::string> paths;
  DIR* d = ::opendir(dir.c_str());
  if (!d) return paths;
  while (const dirent* entry = ::readdir(d)) {
    const std::string name = entry->d_name;
    const std::string suffix = ".state";
    if (name.rfind("cell-", 0) == 0 && name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      paths.push_back(dir + "/" + name);
    }
  }
  ::closedir(d);
  std::sort(paths.begin(), paths.end());
  return paths;
}

void remove_cell_checkpoint(const std::string& path) { std::remove(path.c_str()); }

}  // namespace phnn
