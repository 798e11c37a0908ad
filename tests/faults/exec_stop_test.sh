#!/bin/bash
# tests/faults/exec_stop_test.sh PHNN — a SIGTERM that arrives as soon as
# `phnn sweep` has been executed (within ~1 ms: while the launcher is still
# starting) is a clean stop, exit 75, in every one of 30 tries, never death
# by the signal (143).
set -u
phnn=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cat > "$dir/s.toml" <<'TOML'
name = "s"
[training]
steps = 20
eval_every = 10
[grid]
systems = ["harmonic"]
models = ["node-rk2"]
n_train = [25]
seeds = [0]
TOML
launcher=$(readlink -f "$phnn")
bad=0
for i in $(seq 1 30); do
  "$phnn" sweep "$dir/s.toml" --out "$dir/r$i.h5" --quiet > "$dir/log" 2>&1 &
  pid=$!
  # Until the child is the launcher (before that it is this shell's fork,
  # whose SIGTERM would say nothing about phnn), then at once.
  for _ in $(seq 1 2000); do
    [[ $(readlink "/proc/$pid/exe" 2>/dev/null) == "$launcher" ]] && break
  done
  kill -TERM "$pid" 2>/dev/null
  wait "$pid"
  status=$?
  if [[ $status -ne 75 && $status -ne 0 ]]; then
    echo "try $i: exit $status"
    bad=$((bad + 1))
  fi
done
[[ $bad -eq 0 ]] || { echo "FAILED: $bad of 30 stops right after exec did not end cleanly (75)"; exit 1; }
echo "PASSED: 30 stops right after exec, each a clean exit"
