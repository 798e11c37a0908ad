#!/usr/bin/env bash
# The orchestrator's own cost per work item (docs/BENCHMARKS.md "Per-item
# overhead"): sweeps of N = 100 and 400 one-run cells of a tiny NODE-RK2 + CN
# (20 steps, N_train 8; the cells differ in lambda, so one data set serves
# them all) on 2 ranks, REPEATS times each. Per run: wall time and the sum
# of the runs' own wall_time_s (training, validation and inference of the
# cell). The marginal cost per item is
#   (2 x d(wall) - d(sum of run times)) / d(N),
# core time outside the runs' own work: the shared counter, journal append
# with fsync, the HDF5 row, checksums, logging; each sweep's --timings line
# (stderr) says where an item's time goes.
#   bash bench/orchestrator_overhead.sh        (REPEATS=3, ~30 s)
set -euo pipefail
cd "$(dirname "$0")/.."
PHNN=${PHNN:-build/phnn}
REPEATS=${REPEATS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
MPIRUN=(mpirun -np 2)
[[ $(id -u) == 0 ]] && MPIRUN+=(--allow-run-as-root --oversubscribe)
for n in 100 400; do
  python3 - "$n" "$work/s$n.toml" <<'PY'
import sys
n, path = int(sys.argv[1]), sys.argv[2]
lambdas = ", ".join("%.6g" % (1e-6 * 1.02 ** k) for k in range(n))
open(path, "w").write(f"""name = "overhead{n}"
[data]
num_validation = 8
num_inference = 1
[training]
steps = 20
eval_every = 20
[grid]
systems = ["harmonic"]
models = ["node-rk2"]
n_train = [8]
regularizers = ["cn"]
lambdas = [{lambdas}]
seeds = [0]
""")
PY
  for ((r = 0; r < REPEATS; r++)); do
    rm -rf "$work/o$n.h5"*
    start=$(date +%s.%N)
    OMP_NUM_THREADS=1 "${MPIRUN[@]}" "$PHNN" sweep "$work/s$n.toml" --out "$work/o$n.h5" --timings \
      > "$work/log"
    end=$(date +%s.%N)
    "$PHNN" reduce "$work/o$n.h5" --per-run > "$work/runs.csv"
    python3 - "$n" "$start" "$end" "$work/runs.csv" <<'PY'
import csv, sys
n, start, end, path = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
runs = sum(float(row["wall_time_s"]) for row in csv.DictReader(open(path)))
print(f"{n} {end - start:.3f} {runs:.3f}")
PY
    grep "time per item" "$work/log" | sed 's/^phnn sweep: /  /' >&2
  done
done | python3 -c '
import statistics, sys
rows = [line.split() for line in sys.stdin]
by = {}
for n, wall, runs in rows:
    by.setdefault(int(n), []).append((float(wall), float(runs)))
for n, v in sorted(by.items()):
    walls = ", ".join("%.2f" % w for w, _ in v)
    times = ", ".join("%.2f" % r for _, r in v)
    print(f"N = {n}: wall {walls} s; runs {times} s")
(n0, a), (n1, b) = sorted(by.items())
wall = statistics.median(w for w, _ in b) - statistics.median(w for w, _ in a)
runs = statistics.median(r for _, r in b) - statistics.median(r for _, r in a)
print(f"per item: {(2 * wall - runs) / (n1 - n0) * 1e3:.1f} ms of core time outside the runs")'
