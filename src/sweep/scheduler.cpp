// src/sweep/scheduler.cpp
#include "phnn/sweep/scheduler.h"

namespace phnn {

std::string to_string(ScheduleMode mode) {
  return mode == ScheduleMode::kDynamic ? "dynamic" : "static";
}

WorkQueue::WorkQueue(MPI_Comm comm, int num_items, ScheduleMode mode)
    : comm_(comm), num_items_(num_items), mode_(mode) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  static_next_ = rank_;
  // The decision must be collective: every rank takes part in the allocation.
  int want_dynamic = mode == ScheduleMode::kDynamic ? 1 : 0;
  MPI_Bcast(&want_dynamic, 1, MPI_INT, 0, comm_);
  if (!want_dynamic) {
    mode_ = ScheduleMode::kStatic;
    return;
  }
  MPI_Errhandler previous;
  MPI_Comm_get_errhandler(comm_, &previous);
  MPI_Comm_set_errhandler(comm_, MPI_ERRORS_RETURN);
  const MPI_Aint bytes = rank_ == 0 ? static_cast<MPI_Aint>(2 * sizeof(long)) : 0;
  const int rc = MPI_Win_allocate(bytes, sizeof(long), MPI_INFO_NULL, comm_, &counters_, &window_);
  MPI_Comm_set_errhandler(comm_, previous);
  MPI_Errhandler_free(&previous);
  int ok = rc == MPI_SUCCESS ? 1 : 0, all_ok = 0;
  MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, comm_);
  if (!all_ok) {
    if (rc == MPI_SUCCESS) MPI_Win_free(&window_);
    window_ = MPI_WIN_NULL;
    mode_ = ScheduleMode::kStatic;
    return;
  }
  if (rank_ == 0) {
    MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window_);
    counters_[0] = 0;
    counters_[1] = 0;
    MPI_Win_unlock(0, window_);
  }
  MPI_Barrier(comm_);
  MPI_Win_lock_all(0, window_);
  mode_ = ScheduleMode::kDynamic;
}

WorkQueue::~WorkQueue() {
  // close() is collective; a destructor running during stack unwinding on one
  // rank only must not block, so it frees nothing if close() was not called.
}

int WorkQueue::next() {
  if (mode_ == ScheduleMode::kStatic) {
    if (static_next_ >= num_items_) return -1;
    const int item = static_next_;
    static_next_ += size_;
    return item;
  }
  const long one = 1;
  long item = 0;
  MPI_Fetch_and_op(&one, &item, MPI_LONG, 0, 0, MPI_SUM, window_);
  MPI_Win_flush(0, window_);
  return item < num_items_ ? static_cast<int>(item) : -1;
}

void WorkQueue::mark_done() {
  ++local_done_;
  if (mode_ == ScheduleMode::kStatic) return;
  const long one = 1;
  long previous = 0;
  MPI_Fetch_and_op(&one, &previous, MPI_LONG, 0, 1, MPI_SUM, window_);
  MPI_Win_flush(0, window_);
}

int WorkQueue::done() const {
  if (mode_ == ScheduleMode::kStatic || window_ == MPI_WIN_NULL) return local_done_;
  const long zero = 0;
  long value = 0;
  MPI_Fetch_and_op(&zero, &value, MPI_LONG, 0, 1, MPI_NO_OP, window_);
  MPI_Win_flush(0, window_);
  return static_cast<int>(value);
}

void WorkQueue::close() {
  if (window_ != MPI_WIN_NULL) {
    MPI_Win_unlock_all(window_);
    MPI_Win_free(&window_);
    window_ = MPI_WIN_NULL;
  }
}

}  // namespace phnn
