// src/sweep/rank0_window.h — one MPI-3 window of longs on rank 0 of a
// communicator, in a passive-target epoch on every rank (private to
// src/sweep: WorkQueue's counters, RoundBoard's outcomes and claims).
#pragma once

#include <mpi.h>

namespace phnn {

/// Collective. Allocates `longs` zeroed longs on rank 0 (none elsewhere),
/// opens MPI_Win_lock_all on every rank and returns the window, *base being
/// rank 0's memory; MPI_WIN_NULL on every rank if the allocation failed on
/// any (the caller goes on without it). Free it with free_rank0_window.
MPI_Win allocate_rank0_window(MPI_Comm comm, MPI_Aint longs, long** base);

/// Collective: ends the epoch and frees *window (MPI_WIN_NULL after; a
/// null window is left as it is).
void free_rank0_window(MPI_Win* window);

}  // namespace phnn
