// include/phnn/sweep/scheduler.h — shares the cells of a sweep out over MPI
// ranks.
#pragma once

#include <mpi.h>

#include <string>

#include "phnn/common/enum_names.h"

namespace phnn {

/// Dynamic: a shared counter on rank 0 read-and-incremented with MPI-3
/// one-sided MPI_Fetch_and_op, so a free rank takes the next item (items are
/// sorted largest cost first: longest-processing-time-first). Static: item i
/// goes to rank i % size, no communication but the stop flag.
enum class ScheduleMode { kDynamic, kStatic };
inline constexpr EnumNames<ScheduleMode, 2> kScheduleModeNames{
    "schedule mode", {{{ScheduleMode::kDynamic, "dynamic"}, {ScheduleMode::kStatic, "static"}}}};
inline std::string to_string(ScheduleMode mode) { return kScheduleModeNames.name(mode); }

/// A work queue of items 0..n-1 shared by the ranks of `comm`.
///
///   WorkQueue queue(comm, cells.size(), ScheduleMode::kDynamic);
///   for (int i = queue.next(); i >= 0; i = queue.next()) { run(i); queue.mark_done(); }
///   queue.close();  // collective
class WorkQueue {
 public:
  /// Collective. If the window cannot be created (MPI_Win_allocate fails)
  /// the queue falls back to kStatic; mode() tells which one is in use.
  WorkQueue(MPI_Comm comm, int num_items, ScheduleMode mode);
  ~WorkQueue();
  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;

  /// Next item for this rank, -1 when the queue is exhausted.
  int next();
  /// Counts one finished item (for progress on rank 0).
  void mark_done();
  /// Items finished by all ranks so far (exact on rank 0 in dynamic mode;
  /// this rank's own count in static mode).
  int done() const;
  ScheduleMode mode() const { return mode_; }
  /// This rank stops (a signal): next() returns -1 here now and on every
  /// other rank from its next call on (a flag in rank 0's window; without a
  /// window, on this rank only).
  void request_stop();
  /// True once any rank called request_stop() (seen here by now).
  bool stop_requested();
  /// Lets MPI serve the other ranks' requests on this rank's window (an
  /// MPI_Iprobe): call it now and then while busy. Where one-sided
  /// operations need the target to enter MPI (Open MPI's osc/pt2pt over TCP,
  /// as between nodes without RDMA), rank 0 otherwise answers only at its
  /// next item (docs/SLURM.md, measured). Cheap; a no-op without a window.
  void progress() const;
  /// Collective: frees the window. Called by the destructor if needed.
  void close();

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1, num_items_ = 0;
  ScheduleMode mode_;
  MPI_Win window_ = MPI_WIN_NULL;
  // Rank 0's window: [0] = next item, [1] = items done, [2] = stop flag.
  long* counters_ = nullptr;
  int static_next_ = 0, local_done_ = 0;
  bool stop_seen_ = false;
  // Atomic op on counter `counter` of rank 0's window; returns its old value.
  long fetch_and_add(int counter, long value, MPI_Op op) const;
};

}  // namespace phnn
