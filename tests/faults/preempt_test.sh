#!/bin/bash
# tests/faults/preempt_test.sh CASE PHNN MPIEXEC... — a cell stopped or
# killed in the middle of its training goes on from its saved training state
# (phnn sweep --checkpoint-every) and every run ends bitwise as in an
# uninterrupted sweep.
#   kill9:  kill -9 of both ranks (and mpirun) mid-cell; the rerun goes on
#           from the last state, repeating less than one interval of training.
#   signal: SIGUSR1 to both ranks mid-cell: exit 75 within seconds (the
#           state is saved at once, the cell is not finished first); the
#           rerun goes on from the step the signal stopped.
set -u
case_name=$1 phnn=$2
shift 2
mpiexec=("$@")
here=$(cd "$(dirname "$0")" && pwd)
dir=$(mktemp -d)
trap 'pkill -KILL -f "$dir/p.toml" 2>/dev/null; rm -rf "$dir"' EXIT
fail() { echo "FAILED ($case_name): $*"; tail -30 "$dir/log" 2>/dev/null; exit 1; }
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1

# Two items (one seed each, one per rank) of ~7 s each on this machine.
cat > "$dir/p.toml" <<'TOML'
name = "preempt"
[training]
steps = 15000
eval_every = 500
checkpoints = [5000, 15000]
[grid]
systems = ["harmonic"]
models = ["phnn-jr-rk2"]
sizes = ["small"]
n_train = [100]
seeds = "0-1"
TOML
interval=0.5
sweep() {  # OUT [options]
  local out=$1
  shift
  timeout -k 5 300 "${mpiexec[@]}" "$phnn" sweep "$dir/p.toml" --out "$out" --max-group-size 1 \
    --checkpoint-every "$interval" "$@" > "$dir/log" 2>&1
}
per_run() { "$phnn" reduce "$1" --per-run --format csv > "$2" || fail "reduce $1"; }

sweep "$dir/ref.h5" --checkpoint-every 0 || fail "the reference sweep failed"
per_run "$dir/ref.h5" "$dir/ref.csv"

sweep "$dir/r.h5" & job=$!
# Wait for both items' states past step ~5000 (a budget checkpoint behind them).
states() { ls "$dir"/r.h5.journal/cell-*.state 2>/dev/null; }
step_of() { sed -n 2p "$1" | cut -d' ' -f2; }
ready=0
for _ in $(seq 1 600); do
  n=0
  for f in $(states); do [[ $(step_of "$f") -gt 5500 ]] && n=$((n + 1)); done
  [[ $n -eq 2 ]] && { ready=1; break; }
  sleep 0.05
done
[[ $ready -eq 1 ]] || fail "no training states past step 5500 appeared"
case $case_name in
  kill9)
    pkill -KILL -f "$dir/p.toml"
    killed_at=$(date +%s.%N)
    wait "$job"
    # Training that the rerun repeats: from each state's save to the kill.
    lag=$(for f in $(states); do echo "$killed_at - $(stat -c %.9Y "$f")" | bc; done | sort -g | tail -1)
    saved=$(for f in $(states); do step_of "$f"; done | sort -n | head -1)
    awk -v l="$lag" -v i="$interval" 'BEGIN { exit !(l < i + 0.25) }' ||
      fail "the last state was ${lag}s old at the kill (interval ${interval}s)" ;;
  signal)
    begin=$(date +%s.%N)
    for p in $(pgrep -f "$phnn sweep $dir/p.toml"); do
      [[ $(ps -o comm= -p "$p") == phnn* ]] && kill -USR1 "$p"
    done
    wait "$job"; status=$?
    took=$(echo "$(date +%s.%N) - $begin" | bc)
    [[ $status -eq 75 ]] || fail "exit $status after SIGUSR1, expected 75"
    awk -v t="$took" 'BEGIN { exit !(t < 4) }' || fail "stopping took ${took}s: the cells were finished first?"
    grep -q "stopped after step" "$dir/log" || fail "no 'stopped after step' line"
    saved=$(for f in $(states); do step_of "$f"; done | sort -n | head -1)
    lag=0 ;;
  *) fail "unknown case" ;;
esac
[[ $(states | wc -l) -eq 2 ]] || fail "expected 2 saved states, found $(states | wc -l)"
[[ $saved -lt 15000 ]] || fail "the cells had finished (state at step $saved)"
sweep "$dir/r.h5" || fail "the resumed sweep failed"
[[ $(grep -c "going on after step" "$dir/log") -eq 2 ]] || fail "the rerun did not go on from both states"
grep -q "2 done, 0 diverged, 0 failed, 0 pending of 2" "$dir/log" || fail "the rerun did not finish"
[[ -z $(states) ]] || fail "states left behind after the items finished"
per_run "$dir/r.h5" "$dir/r.csv"
python3 "$here/compare_runs.py" "$dir/ref.csv" "$dir/r.csv" || fail "runs differ from the uninterrupted sweep"
echo "PASSED ($case_name): went on after step >= $saved of 15000; state ${lag}s old at the stop; runs bitwise equal"
