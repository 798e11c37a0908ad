#!/usr/bin/env bash
# Runs bench/bench_training side by side under the project's set-up
# (OpenBLAS behind libblas.so.3 + jemalloc) and Debian's defaults
# (reference BLAS, glibc malloc). One thread, float64. Results: docs/BENCHMARKS.md.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build --target bench_training
BENCH=build/bench_training
REPEATS=${REPEATS:-3}
JEMALLOC=$(ls /usr/lib/x86_64-linux-gnu/libjemalloc.so.2)
REFBLAS=/usr/lib/x86_64-linux-gnu/blas
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
echo "## tuned: OpenBLAS + jemalloc"
LD_PRELOAD=$JEMALLOC $BENCH baseline "$REPEATS"
LD_PRELOAD=$JEMALLOC $BENCH stacked "$REPEATS"
echo "## Debian defaults: reference BLAS + glibc malloc"
LD_LIBRARY_PATH=$REFBLAS $BENCH baseline "$REPEATS"
LD_LIBRARY_PATH=$REFBLAS $BENCH stacked "${REPEATS_DEFAULTS:-1}"
if [[ ${FULL_CELL:-0} == 1 ]]; then
  LD_PRELOAD=$JEMALLOC $BENCH cell
fi
