#!/usr/bin/env bash
# Peak resident memory and wall time of `phnn import` (docs/BENCHMARKS.md
# "Memory of `phnn import`"), two binaries side by side: for each of
# ROUNDS rounds, each split (trajectories, blocks) and each binary in turn,
# `/usr/bin/time` of one import of CSV; then the process alone (a CSV of
# four trajectories) the same way. Prints every run and the medians, and
# the size of each data-set file written (the files of both binaries are
# compared with h5dump).
#   bash bench/import_memory.sh OLD_PHNN NEW_PHNN BIG.csv
#   (BIG.csv: bench/make_import_csv.py BIG.csv --trajectories 100000 --samples 40 --digits 17)
set -euo pipefail
cd "$(dirname "$0")/.."
old=$1 new=$2 csv=$3
ROUNDS=${ROUNDS:-3}
system=sweeps/systems/pendulum.toml
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf 'trajectory,t,q,p,u\n' > "$work/tiny.csv"
for id in 0 1 2 3; do
  for k in 0 1 2; do printf '%d,%d.0e-1,1,0,0\n' "$id" "$k" >> "$work/tiny.csv"; done
done
declare -A args=(
  [trajectories]="--split trajectories --num-validation 2000 --num-inference 100"
  [blocks]="--split blocks"
  [alone]="--split trajectories --num-validation 1 --num-inference 1"
)
run() {  # run NAME BINARY CASE: one import, "case binary KB s" to the log
  local input=$csv
  [[ $3 == alone ]] && input=$work/tiny.csv
  rm -f "$work/$1.h5"
  /usr/bin/time -f "%M %e" -o "$work/time" "$2" import "$input" --system "$system" ${args[$3]} \
    --out "$work/$1.h5" > /dev/null
  echo "$3 $1 $(cat "$work/time")" | tee -a "$work/log"
}
for round in $(seq "$ROUNDS"); do
  for split in trajectories blocks; do
    run old "$old" "$split"
    run new "$new" "$split"
    h5dump "$work/old.h5" | sed 1d > "$work/old.dump"
    h5dump "$work/new.h5" | sed 1d > "$work/new.dump"
    cmp -s "$work/old.dump" "$work/new.dump" || { echo "$split: the files differ"; exit 1; }
    echo "$split: data-set file of $(stat -c %s "$work/new.h5") bytes, the same from both" >> "$work/sizes"
  done
done
for round in $(seq "$ROUNDS"); do
  run old "$old" alone
  run new "$new" alone
done
sort -u "$work/sizes"
python3 - "$work/log" <<'PY'
import statistics, sys
runs = {}
for line in open(sys.argv[1]):
    case, binary, kb, s = line.split()
    runs.setdefault((case, binary), []).append((int(kb), float(s)))
for (case, binary), r in sorted(runs.items()):
    kb = statistics.median(k for k, _ in r)  # /usr/bin/time's KB are KiB
    print("median %-12s %-3s %8d KB = %7.1f MB %6.2f s" % (case, binary, kb, kb * 1.024e-3,
                                                          statistics.median(s for _, s in r)))
PY
