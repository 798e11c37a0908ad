// src/sweep/scheduler.cpp — WorkQueue (phnn/sweep/scheduler.h): the MPI-3
// shared counter that hands out work items, with the stop flag.
#include "phnn/sweep/scheduler.h"

#include "sweep/rank0_window.h"

namespace phnn {

WorkQueue::WorkQueue(MPI_Comm comm, int num_items, ScheduleMode mode)
    : comm_(comm), num_items_(num_items), mode_(mode) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  static_next_ = rank_;
  // The decision must be collective: every rank takes part in the allocation.
  // The window is made in static mode too: it carries the stop flag.
  int want_dynamic = mode == ScheduleMode::kDynamic ? 1 : 0;
  MPI_Bcast(&want_dynamic, 1, MPI_INT, 0, comm_);
  mode_ = ScheduleMode::kStatic;
  // Rank 0's window: [0] = next item, [1] = items done, [2] = stop flag.
  window_ = allocate_rank0_window(comm_, 3, &counters_);
  if (window_ == MPI_WIN_NULL) return;
  if (want_dynamic) mode_ = ScheduleMode::kDynamic;
}

WorkQueue::~WorkQueue() {
  // close() is collective; a destructor running during stack unwinding on one
  // rank only must not block, so it frees nothing if close() was not called.
}

long WorkQueue::fetch_and_add(int counter, long value, MPI_Op op) const {
  long previous = 0;
  MPI_Fetch_and_op(&value, &previous, MPI_LONG, 0, counter, op, window_);
  MPI_Win_flush(0, window_);
  return previous;
}

int WorkQueue::next() {
  if (stop_requested()) return -1;
  if (mode_ == ScheduleMode::kStatic) {
    if (static_next_ >= num_items_) return -1;
    const int item = static_next_;
    static_next_ += size_;
    return item;
  }
  const long item = fetch_and_add(0, 1, MPI_SUM);
  return item < num_items_ ? static_cast<int>(item) : -1;
}

void WorkQueue::request_stop() {
  stop_seen_ = true;
  if (window_ != MPI_WIN_NULL) fetch_and_add(2, 1, MPI_REPLACE);
}

bool WorkQueue::stop_requested() {
  if (!stop_seen_ && window_ != MPI_WIN_NULL) stop_seen_ = fetch_and_add(2, 0, MPI_NO_OP) != 0;
  return stop_seen_;
}

void WorkQueue::progress() const {
  if (window_ == MPI_WIN_NULL) return;
  int flag = 0;
  MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm_, &flag, MPI_STATUS_IGNORE);
}

void WorkQueue::mark_done() {
  ++local_done_;
  if (mode_ == ScheduleMode::kDynamic) fetch_and_add(1, 1, MPI_SUM);
}

int WorkQueue::done() const {
  if (mode_ == ScheduleMode::kStatic) return local_done_;
  return static_cast<int>(fetch_and_add(1, 0, MPI_NO_OP));
}

void WorkQueue::close() { free_rank0_window(&window_); }

}  // namespace phnn
