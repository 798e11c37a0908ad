// src/sweep/results_copy.cpp — see src/sweep/results_copy.h.
#include "results_copy.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "phnn/store/journal.h"

namespace phnn {
namespace results_copy {
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

std::string parent_directory(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

bool same_result(const RunResult& a, const RunResult& b) {
  return internal::encode_journal_record("x", a, 0) == internal::encode_journal_record("x", b, 0);
}

ResultsLayout wider_layout(const ResultsLayout& a, const ResultsLayout& b) {
  ResultsLayout layout;
  layout.num_inference = std::max(a.num_inference, b.num_inference);
  layout.trace_points = std::max(a.trace_points, b.trace_points);
  layout.figure_points = std::max(a.figure_points, b.figure_points);
  layout.figure_states = std::max(a.figure_states, b.figure_states);
  layout.checkpoints = std::max(a.checkpoints, b.checkpoints);
  layout.weights = a.weights || b.weights;
  return layout;
}

void copy_sessions(const ResultsFile& from, ResultsFile* to) {
  for (Provenance session : from.read_sessions()) {
    std::string finished;
    auto it = std::find_if(session.begin(), session.end(),
                           [](const auto& kv) { return kv.first == "finished"; });
    if (it != session.end()) {
      finished = it->second;
      session.erase(it);
    }
    to->begin_session(session);
    if (!finished.empty()) to->end_session(finished);
  }
}

void copy_rows(const ResultsFile& from, const std::vector<std::pair<int, int>>& rows,
               ResultsFile* to) {
  const bool times = from.has_run_times();
  const std::vector<std::string> started = times ? from.read_started_utc() : std::vector<std::string>();
  const std::vector<std::string> finished = times ? from.read_finished_utc() : std::vector<std::string>();
  for (const auto& [row, to_row] : rows) {
    if (times) to->write_run_times(to_row, started[row], finished[row]);
    to->write_run(to_row, from.read_run(row));
  }
}

std::vector<std::string> joined_studies(const Grid& grid) {
  std::vector<std::string> joined;
  for (const auto& studies : grid.run_studies) {
    std::string text;
    for (const std::string& s : studies) text += (text.empty() ? "" : ",") + s;
    joined.push_back(text);
  }
  return joined;
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

void commit_scratch(const std::string& scratch, const std::string& out) {
  fsync_path(scratch, O_RDWR);
  if (std::rename(scratch.c_str(), out.c_str()) != 0) {
    throw std::runtime_error(scratch + ": cannot rename it to " + out + ": " + errno_text());
  }
  fsync_path(parent_directory(out), O_RDONLY);
}

}  // namespace results_copy
}  // namespace phnn
