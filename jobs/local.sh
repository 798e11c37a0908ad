#!/usr/bin/env bash
# Runs a sweep on N local cores, then prints its tables.
#   jobs/local.sh [SWEEP_FILE] [RANKS] [extra phnn sweep options...]
# Defaults: sweeps/demo.toml on 2 ranks, results in results/<sweep name>.h5
# (override with OUT=path). Re-running the same command resumes.
set -euo pipefail
cd "$(dirname "$0")/.."
SWEEP=${1:-sweeps/demo.toml}
RANKS=${2:-2}
shift $(( $# > 2 ? 2 : $# ))
PHNN=${PHNN:-build/phnn}
if [[ ! -x $PHNN ]]; then
  echo "jobs/local.sh: $PHNN not built; run scripts/build.sh first" >&2
  exit 1
fi
# One LibTorch / BLAS thread per rank: two ranks x two threads on two cores
# measured 3-4x slower.
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
MPI_FLAGS=(--oversubscribe --bind-to none)
if [[ $(id -u) -eq 0 ]]; then MPI_FLAGS+=(--allow-run-as-root); fi
OUT=${OUT:-results/$(basename "$SWEEP" .toml).h5}
mpirun "${MPI_FLAGS[@]}" -np "$RANKS" "$PHNN" sweep "$SWEEP" --out "$OUT" --threads 1 "$@"
"$PHNN" reduce "$OUT"
