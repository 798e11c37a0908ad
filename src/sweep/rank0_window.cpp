// src/sweep/rank0_window.cpp — allocate_rank0_window and free_rank0_window
// (sweep/rank0_window.h).
#include "sweep/rank0_window.h"

#include <cstring>

namespace phnn {

MPI_Win allocate_rank0_window(MPI_Comm comm, MPI_Aint longs, long** base) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Win window = MPI_WIN_NULL;
  MPI_Errhandler previous;
  MPI_Comm_get_errhandler(comm, &previous);
  MPI_Comm_set_errhandler(comm, MPI_ERRORS_RETURN);
  const MPI_Aint bytes = rank == 0 ? longs * static_cast<MPI_Aint>(sizeof(long)) : 0;
  const int rc = MPI_Win_allocate(bytes, sizeof(long), MPI_INFO_NULL, comm, base, &window);
  MPI_Comm_set_errhandler(comm, previous);
  MPI_Errhandler_free(&previous);
  int ok = rc == MPI_SUCCESS ? 1 : 0, all_ok = 0;
  MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, comm);
  if (!all_ok) {
    if (rc == MPI_SUCCESS) MPI_Win_free(&window);
    return MPI_WIN_NULL;
  }
  if (rank == 0) {
    MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, window);
    std::memset(*base, 0, static_cast<std::size_t>(longs) * sizeof(long));
    MPI_Win_unlock(0, window);
  }
  MPI_Barrier(comm);
  MPI_Win_lock_all(0, window);
  return window;
}

void free_rank0_window(MPI_Win* window) {
  if (*window == MPI_WIN_NULL) return;
  MPI_Win_unlock_all(*window);
  MPI_Win_free(window);  // sets MPI_WIN_NULL
}

}  // namespace phnn
