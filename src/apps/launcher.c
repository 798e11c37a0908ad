/* src/apps/launcher.c — `phnn`: blocks SIGTERM and SIGUSR1, then executes
 * `phnn-main` from the same directory with the same arguments. A blocked
 * signal stays pending across exec, so a stop that arrives while the dynamic
 * loader maps and relocates LibTorch (up to ~0.5 s on a loaded machine) is
 * not lost: phnn-main installs its handlers and unblocks them first thing
 * (apps/early_signals.cpp), and a pending signal then reaches the handler.
 * This program needs only libc, so its own start-up window is a few µs. */
#define _GNU_SOURCE
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

int main(int argc, char** argv) {
  (void)argc;
  sigset_t stops;
  sigemptyset(&stops);
  sigaddset(&stops, SIGTERM);
  sigaddset(&stops, SIGUSR1);
  sigprocmask(SIG_BLOCK, &stops, NULL);
  char path[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 16);
  if (n <= 0) {
    fprintf(stderr, "phnn: cannot find its own executable (/proc/self/exe): %s\n", strerror(errno));
    return 127;
  }
  path[n] = '\0';
  char* slash = strrchr(path, '/');
  strcpy(slash != NULL ? slash + 1 : path, "phnn-main");
  execv(path, argv);
  fprintf(stderr, "phnn: cannot run %s: %s (build the whole project: it is built with phnn)\n",
          path, strerror(errno));
  return 127;
}
