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

#include "phnn/config/result_columns.h"
#include "phnn/store/journal.h"

namespace phnn {
namespace results_copy {
namespace {
// The result without its clocks (wall times, run times), which differ
// between two trainings of the same run.
RunResult without_clocks(RunResult r) {
  zero_clock_columns(&r);
  r.started_utc.clear();
  r.finished_utc.clear();
  for (TracePoint& p : r.trace) p.elapsed_s = 0.0;
  std::fill(r.checkpoint_train_seconds.begin(), r.checkpoint_train_seconds.end(), 0.0);
  return r;
}
}  // namespace

bool same_result(const RunResult& a, const RunResult& b) {
  return internal::encode_journal_record("x", without_clocks(a), 0) ==
         internal::encode_journal_record("x", without_clocks(b), 0);
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

std::vector<std::pair<int, int>> copy_rows(const ResultsFile& from,
                                           const std::vector<std::pair<int, int>>& rows,
                                           ResultsFile* to) {
  std::vector<std::pair<int, int>> damaged;
  for (const auto& [row, to_row] : rows) {
    if (from.row_damaged(row)) {
      damaged.emplace_back(row, to_row);
      continue;
    }
    to->write_run(to_row, from.read_run(row));  // with its run times
  }
  return damaged;
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

}  // namespace results_copy
}  // namespace phnn
