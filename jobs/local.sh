#!/usr/bin/env bash
# Runs a sweep on N local cores, then prints its tables.
#   jobs/local.sh [SWEEP_FILE] [RANKS] [extra phnn sweep options...]
# Defaults: the repository's sweeps/demo.toml on 2 ranks, results in
# results/<sweep file name>.h5 under the current directory (override with
# OUT=path). Paths are taken from where you run it, so it works from your own
# study directory too. Re-running the same command resumes.
set -euo pipefail
REPO=$(cd "$(dirname "$0")/.." && pwd)
SWEEP=${1:-$REPO/sweeps/demo.toml}
RANKS=${2:-2}
shift $(( $# > 2 ? 2 : $# ))
PHNN=${PHNN:-$REPO/build/phnn}
if [[ ! -x $PHNN ]]; then
  echo "jobs/local.sh: $PHNN not built; run scripts/build.sh first" >&2
  exit 1
fi
if [[ ! -f $SWEEP ]]; then
  echo "jobs/local.sh: $SWEEP: no such sweep file (from $(pwd)); give its path, e.g." \
       "jobs/local.sh sweeps/demo.toml 2" >&2
  exit 2
fi
# One LibTorch / BLAS thread per rank: two ranks x two threads on two cores
# measured 3-4x slower.
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
MPI_FLAGS=(--oversubscribe --bind-to none)
if [[ $(id -u) -eq 0 ]]; then MPI_FLAGS+=(--allow-run-as-root); fi
OUT=${OUT:-results/$(basename "$SWEEP" .toml).h5}
# Ctrl-C or SIGTERM stops the sweep gracefully: Open MPI's mpirun cannot
# forward SIGTERM/SIGINT (it kills the ranks after 1 s) but forwards SIGUSR1,
# on which every rank saves its cell's training state and phnn exits 75. So mpirun
# runs in its own process group (set -m: the terminal's Ctrl-C reaches only
# this script) and the first INT/TERM becomes a USR1 to it; a second one
# kills it (finished runs are never lost: they are in the journals).
set -m
mpirun "${MPI_FLAGS[@]}" -np "$RANKS" "$PHNN" sweep "$SWEEP" --out "$OUT" --threads 1 "$@" &
MPIRUN_PID=$!
set +m
SIGNALS=0
on_signal() {
  SIGNALS=$((SIGNALS + 1))
  if (( SIGNALS == 1 )); then
    echo "jobs/local.sh: stopping: each rank saves its current cell's state (signal again to kill)" >&2
    kill -USR1 "$MPIRUN_PID" 2>/dev/null || true
  else
    echo "jobs/local.sh: killing the sweep; rerun the same command to resume" >&2
    kill -TERM "$MPIRUN_PID" 2>/dev/null || true
  fi
}
trap on_signal INT TERM
STATUS=0
while :; do
  if wait "$MPIRUN_PID"; then STATUS=0; else STATUS=$?; fi
  kill -0 "$MPIRUN_PID" 2>/dev/null || break  # still running: wait was interrupted by a signal
done
trap - INT TERM
if (( STATUS == 75 )); then
  echo "jobs/local.sh: stopped before the end; run the same command again to resume" >&2
fi
if [[ -f $OUT ]]; then "$PHNN" reduce "$OUT"; fi
exit "$STATUS"
