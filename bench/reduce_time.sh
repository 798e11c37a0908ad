#!/usr/bin/env bash
# `phnn reduce` wall time, two binaries side by side (docs/BENCHMARKS.md
# "The reducer"): for each mode (tables, --comparisons, --stat iqm) the two
# run alternately REPEATS times on one results file; prints each run, the
# medians and their ratio, and fails if the two binaries' outputs differ.
#   bash bench/reduce_time.sh FILE OLD_PHNN [NEW_PHNN]   (REPEATS=3)
set -euo pipefail
cd "$(dirname "$0")/.."
if (($# < 2)); then
  echo "usage: bench/reduce_time.sh FILE OLD_PHNN [NEW_PHNN]" >&2
  exit 2
fi
file=$1 old=$2 new=${3:-build/phnn}
REPEATS=${REPEATS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1
for mode in "" "--comparisons" "--stat iqm"; do
  for ((r = 0; r < REPEATS; r++)); do
    for side in old new; do
      bin=${!side}
      start=$(date +%s.%N)
      # shellcheck disable=SC2086  # mode is one or two words
      "$bin" reduce "$file" $mode > "$work/$side.out"
      end=$(date +%s.%N)
      label=${mode:-tables}
      echo "$side ${label// /_} $r $(python3 -c "print(f'{$end - $start:.2f}')")" | tee -a "$work/times"
    done
    cmp -s "$work/old.out" "$work/new.out" || { echo "outputs differ: ${mode:-tables}" >&2; exit 1; }
  done
done
python3 - "$work/times" <<'PY'
import statistics, sys
t = {}
for line in open(sys.argv[1]):
    side, mode, _, sec = line.split()
    t.setdefault(mode, {}).setdefault(side, []).append(float(sec))
for mode, s in t.items():
    o, n = statistics.median(s["old"]), statistics.median(s["new"])
    print(f"{mode}: old {o:.1f} s, new {n:.1f} s (medians of {len(s['old'])}), ratio {o / n:.1f}x")
PY
