#!/bin/bash
# tests/faults/fault_test.sh CASE PHNN SHIM MPIEXEC... — one fault injected
# into a 2-rank sweep: the sweep must end (no hang), non-zero, with the
# system's reason on stderr, leave no half-made file, and the same command
# without the fault must then finish every run with exactly the results of a
# sweep that saw no fault (no finished run lost or changed).
#   CASE: create-eio | row-eio | journal-eio | journal-enospc | disk-full-create |
#         disk-full-journal | disk-full-resume | file-size-limit | read-only-dir
# Exit 77 (skipped) where the case needs what this machine lacks (a tmpfs
# mount for the disk-full cases).
set -u
case_name=$1 phnn=$2 shim=$3
shift 3
mpiexec=("$@")
here=$(cd "$(dirname "$0")" && pwd)
dir=$(mktemp -d)
mounted=""
cleanup() { [[ -n $mounted ]] && umount "$mounted"; rm -rf "$dir"; }
trap cleanup EXIT
fail() { echo "FAILED ($case_name): $*"; cat "$dir/log" 2>/dev/null | head -40; exit 1; }

cat > "$dir/fault.toml" <<'TOML'
name = "fault"
[training]
steps = 20
eval_every = 10
[grid]
systems = ["harmonic", "duffing"]
models = ["phnn-jr-rk2", "node-rk2"]
sizes = ["small"]
n_train = [25]
seeds = "0-5"
TOML

sweep() {  # sweep OUT [env...]: the sweep on 2 ranks, bounded in time
  local out=$1
  shift
  timeout -k 5 180 env "$@" "${mpiexec[@]}" "${rank_prefix[@]}" "$phnn" sweep "$dir/fault.toml" \
    --out "$out" "${quiet[@]}"
}
quiet=(--quiet)
rank_prefix=()
per_run() { "$phnn" reduce --per-run --format csv "$1"; }

sweep "$dir/ref/r.h5" > "$dir/log" 2>&1 || fail "the fault-free reference sweep failed"
per_run "$dir/ref/r.h5" > "$dir/ref.csv" || fail "reduce of the reference failed"
h5_kb=$(( $(stat -c %s "$dir/ref/r.h5") / 1024 ))
journal_kb=$(du -sk "$dir/ref/r.h5.journal" | cut -f1)

out_dir=$dir/out
mkdir -p "$out_dir"
# mpiexec starts the local ranks with its own environment.
preload=(LD_PRELOAD="$shim")
case $case_name in
  create-eio)
    reason="Input/output error"
    faulty=("${preload[@]}" "PHNN_FAIL_PATH=.creating:/r.h5" PHNN_FAIL_ERRNO=EIO) ;;
  row-eio)
    reason="Input/output error"
    faulty=("${preload[@]}" PHNN_FAIL_PATH=/r.h5 PHNN_FAIL_ERRNO=EIO PHNN_FAIL_RANK=1) ;;
  journal-eio)
    reason="Input/output error"
    faulty=("${preload[@]}" PHNN_FAIL_PATH=rank-1.log PHNN_FAIL_ERRNO=EIO PHNN_FAIL_RANK=1) ;;
  journal-enospc)
    reason="No space left on device"
    faulty=("${preload[@]}" PHNN_FAIL_PATH=rank-0.log PHNN_FAIL_AFTER=$(( journal_kb * 1024 / 4 ))) ;;
  read-only-dir)
    reason="Read-only file system"
    [[ $(id -u) -eq 0 ]] || { echo "SKIPPED: mounting a tmpfs needs root"; exit 77; }
    mount -t tmpfs -o size=1m,ro tmpfs "$out_dir" 2>/dev/null ||
      { echo "SKIPPED: cannot mount a tmpfs here"; exit 77; }
    mounted=$out_dir
    faulty=() ;;
  disk-full-create|disk-full-journal|disk-full-resume)
    reason="No space left on device"
    [[ $(id -u) -eq 0 ]] || { echo "SKIPPED: mounting a tmpfs needs root"; exit 77; }
    case $case_name in
      disk-full-create) size=$(( h5_kb / 2 )) ;;
      disk-full-journal) size=$(( h5_kb + journal_kb / 2 )) ;;
      disk-full-resume) size=$(( h5_kb + journal_kb + h5_kb / 2 )) ;;  # no room for the copy
    esac
    mount -t tmpfs -o size=${size}k tmpfs "$out_dir" 2>/dev/null ||
      { echo "SKIPPED: cannot mount a tmpfs here"; exit 77; }
    mounted=$out_dir
    # A finished file to resume: the resume's copy of it fills the disk.
    [[ $case_name == disk-full-resume ]] && cp -a "$dir/ref/r.h5" "$dir/ref/r.h5.journal" "$out_dir/"
    faulty=() ;;
  file-size-limit)
    reason="File too large"
    faulty=() ;;
  *) fail "unknown case" ;;
esac

# The faulty sweep lists its items: every run of an item it started was
# trained (a stop waits for the item in hand) and must survive the fault.
quiet=()
if [[ $case_name == file-size-limit ]]; then
  # ulimit -f (1024-byte blocks) on the ranks only (mpiexec's own files must
  # not hit it); the limit falls inside the journal.
  rank_prefix=(bash -c "ulimit -f $(( journal_kb / 8 )) && exec \"\$@\"" limit)
  sweep "$out_dir/r.h5" > "$dir/log" 2>&1
  status=$?
  rank_prefix=()
else
  sweep "$out_dir/r.h5" "${faulty[@]}" > "$dir/log" 2>&1
  status=$?
fi
case $status in
  0) fail "the sweep passed the fault without a word (exit 0)" ;;
  124|137) fail "the sweep hung (killed by timeout)" ;;
  1) ;;
  *) fail "the sweep exited $status, expected 1 (a clean error)" ;;
esac
grep -q "$reason" "$dir/log" || fail "no \"$reason\" in the error output"
grep -q "Input/output error" "$dir/log" && [[ $reason != "Input/output error" ]] &&
  fail "EIO reported for a fault that is not one"
if grep -q "stopped by the error above" "$dir/log"; then  # the file may hold runs the journals lack
  grep -qE "every finished run is in .*r\.h5 \([0-9]+ finished there\) or in the journals" \
    "$dir/log" || fail "the stop message does not name the results file's finished runs"
fi
grep -q "\.creating\.creating\|\.updating\.creating" "$dir/log" && fail "a scratch name of a scratch name"
trained=$(grep -oE "item [0-9]+/[0-9]+: .*, [0-9]+ seeds?$" "$dir/log" | grep -oE "[0-9]+ seeds?$" |
          awk '{n += $1} END {print n + 0}')
quiet=(--quiet)
leftovers=$(ls -A "$out_dir" | grep -E '\.(creating|updating)' || true)
[[ -z $leftovers ]] || fail "half-made files left behind: $leftovers"

# The same command without the fault (off the full tmpfs: a copy).
cp -a "$out_dir" "$dir/resume"
[[ -n $mounted ]] && { umount "$mounted"; mounted=""; }
sweep "$dir/resume/r.h5" > "$dir/log" 2>&1 || fail "the resumed sweep failed"
kept=$(grep -oE "; [0-9]+ finished before" "$dir/log" | grep -oE "[0-9]+")
(( ${kept:-0} >= trained )) ||
  fail "the faulty sweep trained $trained runs, only ${kept:-0} were kept (file or journal)"
grep -q "24 done, 0 diverged, 0 failed, 0 pending of 24" "$dir/log" || fail "the resume did not finish every run"
per_run "$dir/resume/r.h5" > "$dir/resume.csv" || fail "reduce of the resumed file failed"
python3 "$here/compare_runs.py" "$dir/ref.csv" "$dir/resume.csv" > "$dir/log" 2>&1 ||
  fail "results differ from the fault-free sweep"
echo "PASSED ($case_name): clean error ($reason), $trained trained runs all kept, nothing half-made," \
     "resume = fault-free results"
