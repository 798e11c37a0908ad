#!/bin/bash
# jobs/local.sh stops gracefully on SIGTERM (and Ctrl-C): the first signal
# becomes a SIGUSR1 to mpirun, every rank finishes its cell, the script exits
# 75 after printing the partial table; the same command then resumes and
# completes every run. (Plain SIGTERM to mpirun kills the ranks after 1 s.)
#   tests/jobs/local_stop_test.sh PHNN_BINARY
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
phnn=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cat > "$dir/stop.toml" <<'TOML'
name = "stop"
[data]
num_validation = 40
num_inference = 3
[training]
steps = 20000
[grid]
systems = ["duffing"]
models = ["phnn-s-rk2", "node-rk2", "phnn-jr-rk2"]
n_train = [25]
seeds = [0, 1]
TOML
fail() { echo "FAILED: $*"; cat "$dir/log" 2>/dev/null; exit 1; }
run() { OUT="$dir/stop.h5" PHNN="$phnn" timeout -k 5 240 bash "$root/jobs/local.sh" "$dir/stop.toml" 2 > "$dir/log" 2>&1; }
run & pid=$!
# Signal once the sweep is under way (its journal exists).
for _ in $(seq 1 300); do [[ -d $dir/stop.h5.journal ]] && break; sleep 0.1; done
sleep 1
kill -TERM $(pgrep -f "^bash $root/jobs/local.sh $dir/stop.toml") 2>/dev/null
wait "$pid"; status=$?
[[ $status -eq 75 ]] || fail "first run exited $status, expected 75 (graceful stop)"
grep -q "stopping: each rank saves its current cell" "$dir/log" || fail "no stop message"
grep -q "run the same command again to resume" "$dir/log" || fail "no resume hint"
grep -q "pending of 6 runs" "$dir/log" || fail "no partial table"
run; status=$?
[[ $status -eq 0 ]] || fail "resume exited $status"
grep -q "6 done, 0 diverged, 0 failed, 0 pending of 6 runs" "$dir/log" || fail "resume did not finish every run"
echo "PASSED: SIGTERM -> graceful stop (75) -> resume -> 6/6 done"
