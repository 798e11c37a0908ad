#!/bin/bash
# tests/faults/adaptive_test.sh PHNN MPIEXEC NP_FLAG PREFLAGS... — an adaptive
# sweep ([adaptive]) ends with the same runs, bitwise, on 1, 2 and 3 ranks and
# after a kill -9 in the middle of a round: each round is decided from the
# finished results of the rounds before it, never from timing or scheduling.
set -u
phnn=$1 mpiexec=$2 np_flag=$3
shift 3
preflags=("$@")
here=$(cd "$(dirname "$0")" && pwd)
dir=$(mktemp -d)
trap 'pkill -KILL -f "$dir/" 2>/dev/null; rm -rf "$dir"' EXIT
fail() { echo "FAILED: $*"; tail -30 "$dir/log" 2>/dev/null; exit 1; }
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1

# Two models that differ only in the integrator of a barely trained network:
# their seeds' errors interleave, so the column ties and both cells get more
# seeds every round, up to max_seeds (5 + 3 + 3 + 1 = 12 per cell); NODE's
# errors lie ~3x above theirs (intervals apart), so it keeps its 5 seeds: 29
# of the 36 runs, a set the decisions choose.
cat > "$dir/a.toml" <<'TOML'
name = "adaptive-test"
[data]
num_inference = 8
[training]
steps = 300
eval_every = 100
[grid]
systems = ["harmonic"]
models = ["phnn-jr-rk2", "phnn-jr-rk4", "node-rk2"]
n_train = [25]
seeds = "0-4"
[adaptive]
max_seeds = 12
batch = 3
rule = "column-best"
TOML
sweep() {  # NP OUT
  timeout -k 5 400 "$mpiexec" "$np_flag" "$1" "${preflags[@]}" "$phnn" sweep "$dir/a.toml" \
    --out "$2" --max-group-size 2 > "$dir/log" 2>&1
}
per_run() { "$phnn" reduce "$1" --per-run > "$2" || fail "reduce $1"; }

sweep 1 "$dir/np1.h5" || fail "the 1-rank sweep failed"
grep -q "adaptive round 1:" "$dir/log" || fail "no second round: the test's cells did not tie"
grep -q "adaptive sweep complete after round 3: 29 runs of at most 36" "$dir/log" ||
  fail "expected 3 rounds after round 0 and 29 runs"
per_run "$dir/np1.h5" "$dir/np1.csv"
"$phnn" reduce "$dir/np1.h5" > "$dir/table.md" || fail "reduce of the adaptive file"
grep -q "complete after round 3; 29 runs asked for.*after round 0, 1, ...: 2, 2, 2\." "$dir/table.md" ||
  fail "reduce does not say where the sweep stands and how it grew"
# --round K: the sweep as it stood after round K (round 0: 3 cells x 5 seeds).
rows() { "$phnn" reduce "$dir/np1.h5" --per-run --round "$1" | tail -n +2 | wc -l; }
[[ $(rows 0) -eq 15 && $(rows 1) -eq 21 && $(rows 3) -eq 29 ]] ||
  fail "reduce --per-run --round 0/1/3 gave $(rows 0)/$(rows 1)/$(rows 3) runs, expected 15/21/29"
"$phnn" reduce "$dir/np1.h5" --round 0 | grep -q "up to round 0" || fail "reduce --round 0"
# --rule: another [adaptive] table replayed on the file's runs gives what a
# sweep with that table trains, bitwise. max_seeds 8 asks for a subset of
# np1.h5's runs (5 + 3 per tied cell: 21); max_seeds 15 asks in round 3 for
# seeds 11-13 of both tied cells, of which the file lacks 12 and 13: named
# and counted as pending.
sed 's/^max_seeds = 12/max_seeds = 8/; s/^name = .*/name = "adaptive-test-8"/' "$dir/a.toml" > "$dir/b.toml"
"$phnn" reduce "$dir/np1.h5" --per-run --rule "$dir/b.toml" > "$dir/replay8.csv" ||
  fail "reduce --rule b.toml"
timeout -k 5 400 "$mpiexec" "$np_flag" 1 "${preflags[@]}" "$phnn" sweep "$dir/b.toml" \
  --out "$dir/b8.h5" --max-group-size 2 > "$dir/log" 2>&1 || fail "the max_seeds 8 sweep failed"
per_run "$dir/b8.h5" "$dir/b8.csv"
[[ $(tail -n +2 "$dir/b8.csv" | wc -l) -eq 21 ]] || fail "the max_seeds 8 sweep did not train 21 runs"
python3 "$here/compare_runs.py" "$dir/b8.csv" "$dir/replay8.csv" ||
  fail "reduce --rule differs from the sweep it replays"
sed 's/^max_seeds = 12/max_seeds = 15/' "$dir/a.toml" > "$dir/c.toml"
"$phnn" reduce "$dir/np1.h5" --per-run --rule "$dir/c.toml" > "$dir/replay15.csv" 2> "$dir/err" ||
  fail "reduce --rule c.toml"
grep -q "its round 3 needs 4 runs that .* has not finished (4 of them not in it at all: [0-9a-f]\{16\}, " "$dir/err" ||
  fail "reduce --rule does not name the runs the file lacks: $(cat "$dir/err")"
[[ $(grep -c ",pending,.*,not in $dir/np1.h5\$" "$dir/replay15.csv") -eq 4 ]] ||
  fail "the lacking runs are not pending rows saying so"
# grow = "one" end to end: a sweep of the comparisons rule on a copy of
# np1.h5 trains only the runs it lacks and ends with the runs of the same
# sweep from scratch, bitwise. RK2 and RK4 tie and NODE is resolved, so each
# round names one cell (the cheaper RK2 first, RK4 once RK2 is at the cap).
sed '/^\[adaptive\]/,$d' "$dir/a.toml" > "$dir/d.toml"
cat >> "$dir/d.toml" <<'TOML'
[adaptive]
max_seeds = 12
batch = 3
rule = "comparisons"
grow = "one"
comparisons = [["harmonic/phnn-jr-rk2/25/small/none", "harmonic/phnn-jr-rk4/25/small/none"],
               ["harmonic/phnn-jr-rk2+phnn-jr-rk4/25/small/none", "harmonic/node-rk2/25/small/none"]]
TOML
cp "$dir/np1.h5" "$dir/dcopy.h5"
timeout -k 5 400 "$mpiexec" "$np_flag" 1 "${preflags[@]}" "$phnn" sweep "$dir/d.toml" \
  --out "$dir/dcopy.h5" --max-group-size 2 > "$dir/log" 2>&1 || fail "the grow-one sweep on a copy failed"
per_run "$dir/dcopy.h5" "$dir/dcopy.csv"
timeout -k 5 400 "$mpiexec" "$np_flag" 1 "${preflags[@]}" "$phnn" sweep "$dir/d.toml" \
  --out "$dir/d.h5" --max-group-size 2 > "$dir/log" 2>&1 || fail "the grow-one sweep failed"
grep -q "adaptive round 1: .*(1 cell" "$dir/log" || fail "grow = one named more than one cell in round 0"
per_run "$dir/d.h5" "$dir/d.csv"
python3 "$here/compare_runs.py" "$dir/d.csv" "$dir/dcopy.csv" ||
  fail "the grow-one sweep continued on a copy differs from the same sweep from scratch"
"$phnn" reduce "$dir/np1.h5" --rule "$here/../../sweeps/paper.toml" > /dev/null 2> "$dir/err" &&
  fail "reduce --rule accepted a sweep without [adaptive]"
grep -q "no \[adaptive\] table" "$dir/err" || fail "no clear error for a rule without [adaptive]"

for np in 2 3; do
  sweep "$np" "$dir/np$np.h5" || fail "the $np-rank sweep failed"
  per_run "$dir/np$np.h5" "$dir/np$np.csv"
  python3 "$here/compare_runs.py" "$dir/np1.csv" "$dir/np$np.csv" || fail "$np ranks differ from 1"
done

# Speculation: on 3 ranks with whole-cell items (NODE-RK2's is the fastest),
# ranks left idle while a round drains train the next seeds of the cells the
# round grows ("ahead" items); at 2 000 steps most are stopped when the round
# ends, their state saved, and go on from it when the next round asks for
# them. The runs asked for stay those of 1 rank, bitwise; runs trained ahead
# and never asked for are said. (Which ahead items a rank gets to, and where
# they stop, depends on timing; the runs asked for must not.)
sed 's/^steps = 300/steps = 2000/; s/^eval_every = 100/eval_every = 500/' "$dir/a.toml" > "$dir/long.toml"
long() {  # NP OUT FLAGS...
  local np=$1 out=$2
  shift 2
  timeout -k 5 400 "$mpiexec" "$np_flag" "$np" "${preflags[@]}" "$phnn" sweep "$dir/long.toml" \
    --out "$out" "$@" > "$dir/log" 2>&1
}
long 1 "$dir/long1.h5" --max-group-size 2 || fail "the 1-rank 2 000-step sweep failed"
per_run "$dir/long1.h5" "$dir/long1.csv"
long 3 "$dir/ahead.h5" --max-group-size 5 || fail "the 3-rank sweep with ahead items failed"
grep -q "^\[rank [0-9]/3\] ahead [0-9]*/[0-9]*: " "$dir/log" || fail "no rank trained ahead of a round"
echo "ahead items: $(grep -c " ahead [0-9]*/[0-9]*: " "$dir/log") started, $(grep -c " ahead .* stopped after step" "$dir/log") stopped at a round's end"
per_run "$dir/ahead.h5" "$dir/ahead.csv"
python3 "$here/compare_runs.py" "$dir/long1.csv" "$dir/ahead.csv" || fail "speculation changed the runs asked for"
if grep -q "are seeds no round asked for ([1-9]" "$dir/log"; then
  "$phnn" reduce "$dir/ahead.h5" | grep -q "finished runs no round asked for (trained ahead" ||
    fail "reduce does not say that runs trained ahead are left out"
fi
ls "$dir/ahead.h5.journal"/cell-*.state > /dev/null 2>&1 &&
  fail "states of items trained ahead of the last round were left behind"
long 3 "$dir/noahead.h5" --max-group-size 5 --no-speculation || fail "--no-speculation"
grep -q " ahead [0-9]*/" "$dir/log" && fail "--no-speculation trained ahead"

# Speculation under the comparisons rule: two independent pairs (RK2 against
# RK4 at N_train 25 and at 100) grow every round, NODE's pair is resolved.
# An idle rank trains only seeds the next round is certain to ask for (a
# pair whose cells have all finished the round names them already), so on
# 3 ranks items run ahead, the runs equal 1 rank's bitwise, and no finished
# run trained ahead is left unasked.
sed '/^\[adaptive\]/,$d' "$dir/long.toml" > "$dir/pairs.toml"
cat >> "$dir/pairs.toml" <<'TOML'
[study.I]
n_train = [25, 100]
[adaptive]
max_seeds = 12
batch = 3
rule = "comparisons"
comparisons = [["harmonic/phnn-jr-rk2/25/small/none", "harmonic/phnn-jr-rk4/25/small/none"],
               ["harmonic/phnn-jr-rk2/100/small/none", "harmonic/phnn-jr-rk4/100/small/none"],
               ["harmonic/node-rk2/25/small/none", "harmonic/node-rk2/100/small/none"]]
TOML
pairs() {  # NP OUT
  timeout -k 5 400 "$mpiexec" "$np_flag" "$1" "${preflags[@]}" "$phnn" sweep "$dir/pairs.toml" \
    --out "$2" --max-group-size 5 > "$dir/log" 2>&1
}
pairs 1 "$dir/pairs1.h5" || fail "the 1-rank comparisons sweep failed"
per_run "$dir/pairs1.h5" "$dir/pairs1.csv"
# reduce --named: the cells the comparisons named after round 0 are the cells round 1 grew.
grew=$(sed -n 's/.*adaptive round 1: .*(\([0-9]*\) cells\{0,1\} got.*/\1/p' "$dir/log")
named=$("$phnn" reduce "$dir/pairs1.h5" --round 0 --named | tail -n +2 | cut -d, -f3 | sort -u | wc -l)
[[ -n $grew && $named -eq $grew ]] || fail "reduce --named lists $named cells after round 0, round 1 grew '$grew'"
"$phnn" reduce "$dir/np1.h5" --named > /dev/null 2> "$dir/err" && fail "reduce --named accepted a column-best sweep"
grep -q "not an adaptive sweep of the comparisons rule" "$dir/err" || fail "no clear error for --named: $(cat "$dir/err")"
ahead=0  # whether a pair finishes first is timing: up to 3 tries, every one checked
for try in 1 2 3; do
  rm -rf "$dir/pairs3.h5" "$dir/pairs3.h5.journal"
  pairs 3 "$dir/pairs3.h5" || fail "the 3-rank comparisons sweep with ahead items failed"
  grep -q "trained ahead while a round drained" "$dir/log" &&
    fail "a run trained ahead under the comparisons rule was never asked for"
  per_run "$dir/pairs3.h5" "$dir/pairs3.csv"
  python3 "$here/compare_runs.py" "$dir/pairs1.csv" "$dir/pairs3.csv" ||
    fail "speculation under the comparisons rule changed the runs asked for"
  grep -q "^\[rank [0-9]/3\] ahead [0-9]*/[0-9]*: " "$dir/log" && { ahead=1; break; }
done
[[ $ahead -eq 1 ]] || fail "no rank trained ahead under the comparisons rule in 3 tries"

# kill -9 of every rank once round 1 has finished runs of its own (round 0
# is 9 items of at most 2 seeds).
: > "$dir/log"  # no line of the run before may be read as this one's
sweep 2 "$dir/k.h5" & job=$!
for _ in $(seq 1 1200); do
  grep -q "adaptive round 1:" "$dir/log" 2>/dev/null && [[ $(grep -c "done in" "$dir/log") -ge 10 ]] && break
  sleep 0.05
done
grep -q "adaptive round 1:" "$dir/log" || fail "round 1 never started"
pkill -KILL -f "$dir/a.toml"
wait "$job"
grep -q "adaptive sweep complete" "$dir/log" && fail "the sweep ended before the kill"
sweep 2 "$dir/k.h5" || fail "the resumed sweep failed"
per_run "$dir/k.h5" "$dir/k.csv"
python3 "$here/compare_runs.py" "$dir/np1.csv" "$dir/k.csv" || fail "the killed and resumed sweep differs"
echo "PASSED: 1, 2, 3 ranks, runs trained ahead (column-best and comparisons) and a kill -9 mid-round give the same runs bitwise"
