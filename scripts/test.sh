#!/usr/bin/env bash
# Fresh machine to test results in one command: set-up, build, ctest
# (unit tests and the MPI tests under mpiexec with 1-3 ranks).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
python3 scripts/check_sizes.py || true   # long functions / files: a warning, never a failure
export OMP_NUM_THREADS=1
ctest --test-dir build --output-on-failure --timeout 1500 "$@"
