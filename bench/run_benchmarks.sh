#!/usr/bin/env bash
# The numbers of docs/BENCHMARKS.md, on this machine: one thread, float64,
# the project's set-up (OpenBLAS behind libblas.so.3, jemalloc preloaded).
#   bash bench/run_benchmarks.sh            # ~15 min
#   REPEATS=5 bash bench/run_benchmarks.sh
#   WORK_PRECISION=0 bash bench/run_benchmarks.sh   # without the integrator work-precision part
# Every row is a median of REPEATS runs; rows that compare two things
# interleave them run by run in the same process or loop.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build --target bench_training
BENCH=build/bench_training
REPEATS=${REPEATS:-3}
JEMALLOC=$(ls /usr/lib/x86_64-linux-gnu/libjemalloc.so.2 2>/dev/null || true)
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
run() { LD_PRELOAD=$JEMALLOC "$BENCH" "$@"; }

# µs per member-step of `run` (E = 10, batch 64) from T(long) - T(short).
member_step_us() {  # MODEL INTEGRATOR REG SIZE SHORT LONG
  local a b
  a=$(run run "$1" "$2" "$3" "$5" "$4" | cut -d' ' -f1)
  b=$(run run "$1" "$2" "$3" "$6" "$4" | cut -d' ' -f1)
  python3 -c "print(round(($b - $a) / (($6 - $5) * 10) * 1e6))"
}
median() { python3 -c "import statistics,sys; print(round(statistics.median(map(float, sys.argv[1:]))))" "$@"; }

echo "## fused vs reference networks, small, E = 10 (interleaved)"
run compare "$REPEATS" small

echo "## E = 1 and E = 10, every small model (fused)"
run stacked "$REPEATS"

echo "## sizes, E = 10, fused, µs per member-step"
for size in medium large; do
  for model in "node rk2" "phnn-s rk2" "phnn-s dg" "phnn-jr rk2" "phnn-jr dg"; do
    if [[ $size == large && $model != "phnn-jr rk2" ]]; then continue; fi
    samples=()
    for ((r = 0; r < REPEATS; r++)); do samples+=("$(member_step_us $model none $size 50 300)"); done
    echo "| $size | $model | $(median "${samples[@]}") |"
  done
done

echo "## a small cell's evaluation + inference (2 validations, 102 rollouts x 500 steps), s"
for model in "phnn-jr" "phnn-s"; do
  for integrator in rk2 dg; do
    samples=()
    for ((r = 0; r < REPEATS; r++)); do samples+=("$(run inference $model $integrator | cut -d' ' -f1)"); done
    echo "| $model | $integrator | $(python3 -c "import statistics,sys; print(statistics.median(map(float, sys.argv[1:])))" "${samples[@]}") |"
  done
done

echo "## anchor: plain PyTorch eager vs the stacked step"
/usr/bin/python3 bench/pytorch_step.py --repeats "$REPEATS" --check

if [[ ${FULL_CELL:-0} == 1 ]]; then run cell; fi

if [[ ${WORK_PRECISION:-1} == 0 ]]; then exit 0; fi  # WORK_PRECISION=0: training benchmarks only
echo "## integrator work-precision (true systems; CSV + PNG into docs/figures/)"
cmake --build build --target work_precision
build/work_precision --trajectories 10 --repeats 5 > docs/figures/work_precision.csv
/usr/bin/python3 analysis/plot_work_precision.py docs/figures/work_precision.csv docs/figures
