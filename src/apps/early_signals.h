// src/apps/early_signals.h — SIGTERM and SIGUSR1 (a Slurm stop or a
// preemption notice) are caught from the first instruction of the process,
// before the shared libraries' initializers (LibTorch's take ~1 s), so a
// sweep told to stop while starting stops cleanly (exit 75) instead of dying
// by the signal (143). Other commands get the default action back.
#pragma once

#include <csignal>

namespace phnn {
namespace apps {

/// For commands that do not stop gracefully: the default action again, and
/// a signal caught early is raised now.
void restore_default_stop_signals();

/// `phnn sweep`'s stop handlers, in two phases. Until end_setup_stops(),
/// while the sweep only reads and computes (sweep file, system files and
/// their symbolic work, the plan; no lock taken, nothing written), a
/// SIGTERM/SIGUSR1 ends the process at once: `message` to stderr, then
/// _exit(`status`), since nothing is lost (a stop caught before this call
/// does the same now). Under mpirun the other ranks are ended by it (a rank
/// exited non-zero) and the job's status is `status`. After
/// end_setup_stops() a signal only sets *flag (the graceful stop: the cell
/// in hand saves its state, the file is closed).
void begin_setup_stops(volatile std::sig_atomic_t* flag, int status, const char* message);
void end_setup_stops();

}  // namespace apps
}  // namespace phnn
