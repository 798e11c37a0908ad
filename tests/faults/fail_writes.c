/* tests/faults/fail_writes.c — an LD_PRELOAD shim for fault-injection tests:
 * writes to one file fail as a full disk (ENOSPC) or a broken one (EIO)
 * would make them fail, after a given number of bytes went through.
 *
 *   PHNN_FAIL_PATH   the files: paths ending in one of these texts, separated
 *                    by ':' (required)
 *   PHNN_FAIL_AFTER  bytes written to it by this process before writes fail
 *                    (default 0: the first write fails)
 *   PHNN_FAIL_ERRNO  ENOSPC (default) or EIO
 *   PHNN_FAIL_RANK   only in the MPI process of this rank (OMPI_COMM_WORLD_RANK)
 *
 * write, pwrite, pwrite64, writev and pwritev are intercepted (HDF5's sec2
 * and MPI-IO drivers and the journal use these). Test-only code. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

static long long g_written = 0;

static int active(void) {
  static int state = -1; /* -1: not read yet */
  if (state < 0) {
    const char* rank = getenv("PHNN_FAIL_RANK");
    const char* mine = getenv("OMPI_COMM_WORLD_RANK");
    state = getenv("PHNN_FAIL_PATH") != NULL &&
            (rank == NULL || (mine != NULL && strcmp(rank, mine) == 0));
  }
  return state;
}

/* True (with errno set) if this write to fd must fail. */
static int must_fail(int fd, size_t bytes) {
  if (!active() || bytes == 0) return 0;
  char link[64], path[4096];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 0) return 0;
  path[n] = '\0';
  int match = 0;
  for (const char* suffix = getenv("PHNN_FAIL_PATH"); *suffix != '\0' && !match;) {
    const char* end = strchr(suffix, ':');
    const size_t len = end ? (size_t)(end - suffix) : strlen(suffix);
    match = len > 0 && (size_t)n >= len && strncmp(path + n - len, suffix, len) == 0;
    suffix += len + (end ? 1 : 0);
  }
  if (!match) return 0;
  const char* after = getenv("PHNN_FAIL_AFTER");
  if (g_written + (long long)bytes <= (after ? atoll(after) : 0)) {
    g_written += (long long)bytes;
    return 0;
  }
  const char* code = getenv("PHNN_FAIL_ERRNO");
  errno = (code != NULL && strcmp(code, "EIO") == 0) ? EIO : ENOSPC;
  return 1;
}

static size_t iov_bytes(const struct iovec* iov, int count) {
  size_t total = 0;
  for (int i = 0; i < count; ++i) total += iov[i].iov_len;
  return total;
}

typedef ssize_t (*write_fn)(int, const void*, size_t);
typedef ssize_t (*pwrite_fn)(int, const void*, size_t, off_t);
typedef ssize_t (*writev_fn)(int, const struct iovec*, int);
typedef ssize_t (*pwritev_fn)(int, const struct iovec*, int, off_t);

ssize_t write(int fd, const void* buf, size_t count) {
  static write_fn real = NULL;
  if (!real) real = (write_fn)dlsym(RTLD_NEXT, "write");
  return must_fail(fd, count) ? -1 : real(fd, buf, count);
}

ssize_t pwrite(int fd, const void* buf, size_t count, off_t offset) {
  static pwrite_fn real = NULL;
  if (!real) real = (pwrite_fn)dlsym(RTLD_NEXT, "pwrite");
  return must_fail(fd, count) ? -1 : real(fd, buf, count, offset);
}

ssize_t pwrite64(int fd, const void* buf, size_t count, off_t offset) {
  static pwrite_fn real = NULL;
  if (!real) real = (pwrite_fn)dlsym(RTLD_NEXT, "pwrite64");
  return must_fail(fd, count) ? -1 : real(fd, buf, count, offset);
}

ssize_t writev(int fd, const struct iovec* iov, int count) {
  static writev_fn real = NULL;
  if (!real) real = (writev_fn)dlsym(RTLD_NEXT, "writev");
  return must_fail(fd, iov_bytes(iov, count)) ? -1 : real(fd, iov, count);
}

ssize_t pwritev(int fd, const struct iovec* iov, int count, off_t offset) {
  static pwritev_fn real = NULL;
  if (!real) real = (pwritev_fn)dlsym(RTLD_NEXT, "pwritev");
  return must_fail(fd, iov_bytes(iov, count)) ? -1 : real(fd, iov, count, offset);
}
