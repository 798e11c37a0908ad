// src/apps/sweep_report.cpp — see sweep_report.h.
#include "apps/sweep_report.h"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <vector>

#include "phnn/common/utc_time.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"

namespace phnn {
namespace apps {

std::string format_duration(double seconds) {
  char buf[64];
  if (seconds < 120) std::snprintf(buf, sizeof buf, "%.0f s", seconds);
  else if (seconds < 7200) std::snprintf(buf, sizeof buf, "%.1f min", seconds / 60);
  else std::snprintf(buf, sizeof buf, "%.1f h", seconds / 3600);
  return buf;
}

ProgressLine::ProgressLine(const std::vector<WorkItem>& work, int ranks, bool static_share)
    : static_share_(static_share) {
  cost_.push_back(0.0);
  runs_.push_back(0);
  for (std::size_t i = 0; i < work.size(); i += static_share ? static_cast<std::size_t>(ranks) : 1) {
    cost_.push_back(cost_.back() + work[i].estimated_cost_s);
    runs_.push_back(runs_.back() + static_cast<long>(work[i].runs.size()));
  }
}

void ProgressLine::print(int items_done, double elapsed_s) const {
  const std::size_t n = cost_.size() - 1;
  const std::size_t done = std::min<std::size_t>(static_cast<std::size_t>(items_done), n);
  const double minutes = elapsed_s / 60.0;
  std::string eta = "--";
  if (done > 0 && done < n && cost_[done] > 0.0) {
    eta = format_duration(elapsed_s * (cost_[n] - cost_[done]) / cost_[done]);
  }
  std::printf("[progress] items %zu/%zu%s  %.1f runs/min  elapsed %s  ETA %s  (%s)\n", done, n,
              static_share_ ? " (rank 0's share, static scheduling)" : "",
              minutes > 0 ? static_cast<double>(runs_[done]) / minutes : 0.0,
              format_duration(elapsed_s).c_str(), eta.c_str(), utc_now().c_str());
  std::fflush(stdout);
}

std::string describe(const RunConfig& run) {
  std::ostringstream s;
  s << run.system_name() << " " << model_label(run.model, run.integrator) << " "
    << to_string(run.size) << " n_train=" << run.n_train << " reg=" << to_string(run.regularizer);
  return s.str();
}

void print_plan(const SweepSpec& spec, const Grid& grid, const Shard& shard,
                int runs_done_before, int runs_to_do, const WorkPlan& plan, int size,
                ScheduleMode mode, const std::string& out) {
  std::cout << "phnn sweep: " << spec.name << ": " << grid.runs.size() << " runs in "
            << grid.cells.size() << " cells; "
            << (shard.count > 1 ? "shard " + std::to_string(shard.index) + "/" +
                                      std::to_string(shard.count) + ": "
                                : std::string())
            << runs_done_before << " finished before, " << runs_to_do << " to run in "
            << plan.items.size() << " items (" << plan.cells << " cells, " << plan.split_cells
            << " split) on " << size << " rank" << (size > 1 ? "s" : "") << " ("
            << to_string(mode) << " scheduling) -> " << out << std::endl;
}

void print_item(const std::string& prefix, const std::string& text) {
  // Each rank's line with its time: logs of long sweeps read as a timeline.
  std::printf("%s%s  (%s)\n", prefix.c_str(), text.c_str(), utc_now().c_str());
  std::fflush(stdout);
}

void print_summary(const std::string& out, int total_runs, double seconds, StopReason stop,
                   const Shard& shard, const std::string& adaptive_line) {
  const ResultsFile summary = ResultsFile::open_read_only(out);
  int counts[4] = {0, 0, 0, 0};
  for (RunStatus s : summary.read_statuses()) ++counts[static_cast<int>(s)];
  std::printf("phnn sweep: %d runs trained in %s; %s now holds %d done, %d diverged, %d failed, "
              "%d pending of %d\n",
              total_runs, format_duration(seconds).c_str(), out.c_str(), counts[1], counts[2],
              counts[3], counts[0], summary.num_runs());
  if (stop == StopReason::kError) {
    // A full journal does not stop the row (record_item): the file may
    // hold runs the journals lack, so name both, with the file's count.
    std::printf("phnn sweep: stopped by the error above; every finished run is in %s (%d "
                "finished there) or in the journals (%s); fix the cause (free space?) and run the "
                "same command again to resume\n",
                out.c_str(), counts[1] + counts[2] + counts[3], journal_directory(out).c_str());
  } else if (stop == StopReason::kSignal) {
    std::printf("phnn sweep: stopped on a signal; run the same command again to resume\n");
  } else if (shard.count > 1) {
    std::printf("phnn sweep: shard %d/%d done (the pending runs are other shards'); when every "
                "shard is done: phnn merge OUT SHARD...\n",
                shard.index, shard.count);
  } else if (!adaptive_line.empty()) {
    std::printf("phnn sweep: %s%s\n", adaptive_line.c_str(),
                counts[3] > 0 ? "; run the same command again with --retry-failed to retry "
                                "the failed runs" : "");
  } else if (counts[0] > 0 || counts[3] > 0) {
    std::printf("phnn sweep: runs remain; run the same command again%s\n",
                counts[3] > 0 ? " with --retry-failed to retry the failed ones" : "");
  }
}

}  // namespace apps
}  // namespace phnn
