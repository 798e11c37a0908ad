#!/usr/bin/env bash
# The cost of a [search] against its full grid, side by side (docs/BENCHMARKS.md
# "Search against the full grid"): sweeps/examples/search-pendulum.toml and
# search-pendulum-full.toml on 2 local ranks, alternated REPEATS times, each
# into a fresh results file. Per sweep: wall time, and the training core-
# seconds (analysis/search_check.py: per configuration and seed, the run time
# of the last rung it reached). Needs results/pendulum-measured.h5 (the
# commands at the top of sweeps/examples/pendulum-measured.toml).
#   bash bench/search_cost.sh        (REPEATS=2, ~13 min)
set -euo pipefail
cd "$(dirname "$0")/.."
PHNN=${PHNN:-build/phnn}
REPEATS=${REPEATS:-2}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
MPIRUN=(mpirun -np 2)
[[ $(id -u) == 0 ]] && MPIRUN+=(--allow-run-as-root --oversubscribe)
export OMP_NUM_THREADS=1
for ((r = 0; r < REPEATS; r++)); do
  for kind in search search-full; do
    file=sweeps/examples/${kind/search/search-pendulum}.toml
    start=$(date +%s.%N)
    "${MPIRUN[@]}" "$PHNN" sweep "$file" --out "$work/$kind-$r.h5" --quiet > /dev/null
    end=$(date +%s.%N)
    echo "$kind $r wall $(python3 -c "print(f'{$end - $start:.1f}')") s"
  done
  PHNN=$PHNN /usr/bin/python3 analysis/search_check.py "$work/search-$r.h5" "$work/search-full-$r.h5" |
    grep "core-seconds"
done
