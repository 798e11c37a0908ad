// src/apps/early_signals.h — SIGTERM and SIGUSR1 (a Slurm stop or a
// preemption notice) are caught from the first instruction of the process,
// before the shared libraries' initializers (LibTorch's take ~1 s), so a
// sweep told to stop while starting stops cleanly (exit 75) instead of dying
// by the signal (143). Other commands get the default action back.
#pragma once

#include <csignal>

namespace phnn {
namespace apps {

/// The stop signal caught before a command took over (0: none).
int early_stop_signal();

/// For commands that do not stop gracefully: the default action again, and
/// a signal caught early is raised now.
void restore_default_stop_signals();

}  // namespace apps
}  // namespace phnn
