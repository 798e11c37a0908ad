// src/apps/early_signals.cpp — see early_signals.h. The handler is installed
// from the executable's .preinit_array, which the dynamic loader runs before
// any shared library's initializer (System V ABI, DT_PREINIT_ARRAY); before
// that, the launcher's blocked mask holds the signals.
#include "apps/early_signals.h"

#include <signal.h>

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

}  // namespace

int early_stop_signal() { return g_early_signal; }

void restore_default_stop_signals() {
  std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGUSR1, SIG_DFL);
  if (g_early_signal != 0) std::raise(g_early_signal);
}

}  // namespace apps
}  // namespace phnn
