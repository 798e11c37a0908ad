// src/apps/early_signals.cpp — see early_signals.h. The early handler is installed
// from the executable's .preinit_array, which the dynamic loader runs before
// any shared library's initializer (System V ABI, DT_PREINIT_ARRAY); before
// that, the launcher's blocked mask holds the signals.
#include "apps/early_signals.h"

#include <signal.h>
#include <unistd.h>

#include <cstring>

namespace phnn {
namespace apps {
namespace {

volatile std::sig_atomic_t g_early_signal = 0;

extern "C" void record_early_signal(int signal) { g_early_signal = signal; }

// Handlers first, then unblock: the launcher (src/apps/launcher.c) execs us
// with both signals blocked, so one sent while the loader ran is pending and
// arrives here.
extern "C" void install_early_handlers(int, char**, char**) {
  std::signal(SIGTERM, record_early_signal);
  std::signal(SIGUSR1, record_early_signal);
  sigset_t stops;
  sigemptyset(&stops);
  sigaddset(&stops, SIGTERM);
  sigaddset(&stops, SIGUSR1);
  sigprocmask(SIG_UNBLOCK, &stops, nullptr);
}

__attribute__((section(".preinit_array"), used)) void (*const kPreinit)(int, char**, char**) =
    install_early_handlers;

volatile std::sig_atomic_t g_in_setup = 0;
volatile std::sig_atomic_t* g_stop_flag = nullptr;
int g_setup_status = 0;
const char* g_setup_message = "";

// Async-signal-safe: write(2) and _exit(2) only.
extern "C" void sweep_stop(int signal) {
  if (g_in_setup != 0) {
    const ssize_t ignored = ::write(STDERR_FILENO, g_setup_message, std::strlen(g_setup_message));
    (void)ignored;
    ::_exit(g_setup_status);
  }
  *g_stop_flag = signal;
}

}  // namespace

void begin_setup_stops(volatile std::sig_atomic_t* flag, int status, const char* message) {
  g_stop_flag = flag;
  g_setup_status = status;
  g_setup_message = message;
  g_in_setup = 1;
  std::signal(SIGTERM, sweep_stop);
  std::signal(SIGUSR1, sweep_stop);
  if (g_early_signal != 0) sweep_stop(g_early_signal);
}

void end_setup_stops() { g_in_setup = 0; }

void restore_default_stop_signals() {
  std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGUSR1, SIG_DFL);
  if (g_early_signal != 0) std::raise(g_early_signal);
}

}  // namespace apps
}  // namespace phnn
