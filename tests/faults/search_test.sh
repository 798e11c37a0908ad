#!/bin/bash
# tests/faults/search_test.sh PHNN MPIEXEC NP_FLAG PREFLAGS... — a search
# sweep ([search], successive halving) asks for the same runs and ends with
# the same results, bitwise, on 1, 2 and 3 ranks and after a kill -9 in the
# middle of a rung; its runs that went on from a rung's saved state equal the
# same runs trained straight through by a plain sweep (same run ids).
set -u
phnn=$1 mpiexec=$2 np_flag=$3
shift 3
preflags=("$@")
here=$(cd "$(dirname "$0")" && pwd)
dir=$(mktemp -d)
trap 'pkill -KILL -f "$dir/" 2>/dev/null; rm -rf "$dir"' EXIT
fail() { echo "FAILED: $*"; tail -30 "$dir/log" 2>/dev/null; exit 1; }
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1

# 2 models x 2 learning rates = 4 configurations of 3 seeds; eta 2 keeps 2
# after 100 steps and 1 after 200: 12 + 6 + 3 = 21 of the 36 runs.
cat > "$dir/s.toml" <<'TOML'
name = "search-test"
[data]
num_inference = 8
[training]
eval_every = 100
[grid]
systems = ["harmonic"]
models = ["phnn-jr-rk2", "node-rk2"]
n_train = [25]
seeds = "0-2"
[search]
rungs = [100, 200, 300]
eta = 2
learning_rate = [1e-3, 3e-3]
TOML
sweep() {  # NP OUT
  timeout -k 5 400 "$mpiexec" "$np_flag" "$1" "${preflags[@]}" "$phnn" sweep "$dir/s.toml" \
    --out "$2" > "$dir/log" 2>&1
}
per_run() { "$phnn" reduce "$1" --per-run > "$2" || fail "reduce $1"; }

sweep 1 "$dir/np1.h5" || fail "the 1-rank sweep failed"
grep -q "search complete after rung 2: 21 runs of at most 36" "$dir/log" ||
  fail "expected 3 rungs and 21 runs"
[[ $(grep -c "going on after step" "$dir/log") -eq 3 ]] ||
  fail "the 3 items of rungs 1 and 2 did not go on from the rung before's state"
per_run "$dir/np1.h5" "$dir/np1.csv"
[[ $(tail -n +2 "$dir/np1.csv" | wc -l) -eq 21 ]] || fail "reduce --per-run lists other than 21 runs"
"$phnn" reduce "$dir/np1.h5" > "$dir/table.md" || fail "reduce of the search file"
grep -q "Rung 1 (200 steps): 2 configurations" "$dir/table.md" &&
  grep -q "^Best: \*\*" "$dir/table.md" || fail "reduce does not show the rungs and the best"

# The rung-2 runs, trained from rung 1's states, against the same runs
# (same ids) of plain sweeps of 300 steps.
best=$(grep "^Best:" "$dir/table.md")
model=$([[ $best == *PHNN-JR-RK2* ]] && echo phnn-jr-rk2 || echo node-rk2)
rate=$([[ $best == *learning_rate=0.001* ]] && echo 1e-3 || echo 3e-3)
sed -e '/^\[search\]/,$d' -e "s/^eval_every = 100/eval_every = 100\nsteps = 300\nlearning_rate = $rate/" \
    -e "s/^models = .*/models = [\"$model\"]/" "$dir/s.toml" > "$dir/plain.toml"
timeout -k 5 400 "$mpiexec" "$np_flag" 1 "${preflags[@]}" "$phnn" sweep "$dir/plain.toml" \
  --out "$dir/plain.h5" > "$dir/log" 2>&1 || fail "the plain sweep failed"
per_run "$dir/plain.h5" "$dir/plain.csv"
python3 - "$dir/np1.csv" "$dir/rung2.csv" <<'PY' || fail "cannot select the rung-2 runs"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], newline="")))
kept = [r for r in rows if r["steps"] == "300"]
assert len(kept) == 3, len(kept)
# The rungs before ran without inference ("inference=skipped" in their ids:
# a column of this file alone, empty at the last rung).
assert all(r["inference"] == "skipped" for r in rows if r["steps"] != "300")
assert all(r.pop("inference") == "" for r in kept)
with open(sys.argv[2], "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=kept[0].keys())
    w.writeheader()
    w.writerows(kept)
PY
python3 "$here/compare_runs.py" "$dir/rung2.csv" "$dir/plain.csv" ||
  fail "runs that went on from a rung's state differ from the same runs trained straight through"

for np in 2 3; do
  sweep "$np" "$dir/np$np.h5" || fail "the $np-rank sweep failed"
  per_run "$dir/np$np.h5" "$dir/np$np.csv"
  python3 "$here/compare_runs.py" "$dir/np1.csv" "$dir/np$np.csv" || fail "$np ranks differ from 1"
done

# Two groups (the study on two systems) of 4 configurations on 3 ranks: a
# group whose rung is done keeps its best while the other still trains, so
# idle ranks train its survivors' next rung ahead; the runs equal 1 rank's.
sed -e 's/^systems = .*/systems = ["harmonic", "self-sustained"]/' -e 's/^rungs = .*/rungs = [400, 800, 1600]/' \
    -e 's/^name = .*/name = "search-groups"/' "$dir/s.toml" > "$dir/g.toml"
groups() {  # NP OUT
  timeout -k 5 400 "$mpiexec" "$np_flag" "$1" "${preflags[@]}" "$phnn" sweep "$dir/g.toml" \
    --out "$2" > "$dir/log" 2>&1
}
groups 1 "$dir/g1.h5" || fail "the 1-rank two-group search failed"
per_run "$dir/g1.h5" "$dir/g1.csv"
ahead=0  # whether a group finishes first is timing: up to 3 tries, every one bitwise equal
for try in 1 2 3; do
  rm -rf "$dir/g3.h5" "$dir/g3.h5.journal"
  groups 3 "$dir/g3.h5" || fail "the 3-rank two-group search failed"
  per_run "$dir/g3.h5" "$dir/g3.csv"
  python3 "$here/compare_runs.py" "$dir/g1.csv" "$dir/g3.csv" || fail "training rungs ahead changed the runs"
  grep -q "^\[rank [0-9]/3\] ahead [0-9]*/[0-9]*: " "$dir/log" && { ahead=1; break; }
done
[[ $ahead -eq 1 ]] || fail "no rank trained a rung ahead in 3 tries"

# kill -9 of every rank once rung 1 has started.
: > "$dir/log"  # no line of the run before may be read as this one's
sweep 2 "$dir/k.h5" & job=$!
for _ in $(seq 1 1200); do
  grep -q "search rung 1 " "$dir/log" 2>/dev/null && break
  sleep 0.05
done
grep -q "search rung 1 " "$dir/log" || fail "rung 1 never started"
pkill -KILL -f "$dir/s.toml"
wait "$job"
grep -q "search complete" "$dir/log" && fail "the sweep ended before the kill"
sweep 2 "$dir/k.h5" || fail "the resumed sweep failed"
per_run "$dir/k.h5" "$dir/k.csv"
python3 "$here/compare_runs.py" "$dir/np1.csv" "$dir/k.csv" || fail "the killed and resumed sweep differs"
echo "PASSED: 1, 2, 3 ranks, rungs trained ahead and a kill -9 mid-rung give the same runs bitwise; rungs equal straight training"
