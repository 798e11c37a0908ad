#!/usr/bin/env bash
# Proves jobs/phnn-sweep.sbatch on a real Slurm: installs Debian's slurm-wlm
# and munge if needed, starts a one-node slurmctld + slurmd on this machine
# (needs root), submits a small sweep on 2 tasks with sbatch, stops it with
# USR1 once a first run is journaled (what --signal=B:USR1 does before the
# time limit), lets the job requeue itself, requeues it once more by hand
# mid-run (scontrol requeue), waits for it to finish and checks the table.
# Then array mode with PHNN_SHARDS=4: an array task without it refuses; a
# strided array (--array=0-3:2) trains exactly shards 0 and 2; two resubmitted
# single tasks (--array=1, --array=3) train shards 1 and 3; a merge job that
# depends on them; the merged runs must equal the first job's.
#
#   bash jobs/test-slurm.sh            # from the repository root, after scripts/build.sh
#
# It writes /etc/slurm/slurm.conf only if there is none (or it wrote it
# before) and leaves the daemons running; work files go to $WORK
# (default /tmp/phnn-test-slurm).
set -euo pipefail
cd "$(dirname "$0")/.."
REPO=$(pwd)
WORK=${WORK:-/tmp/phnn-test-slurm}
PHNN=${PHNN:-$REPO/build/phnn}
log() { echo "[test-slurm $(date -u +%T)] $*"; }
die() { log "FAILED: $*"; exit 1; }
[[ $(id -u) -eq 0 ]] || die "needs root (installs packages, starts slurmctld/slurmd)"
[[ -x $PHNN ]] || die "$PHNN not built; run scripts/build.sh first"

# --- Slurm and munge -----------------------------------------------------------
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  log "installing slurm-wlm and munge"
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null
fi
if [[ ! -s /etc/munge/munge.key ]]; then
  dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
fi
chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
mkdir -p /run/munge && chown munge:munge /run/munge
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  su -s /bin/sh munge -c /usr/sbin/munged
  sleep 1
fi
munge -n | unmunge | grep -q "STATUS: *Success" || die "munge does not work"

HOST=$(hostname -s)
CONF=/etc/slurm/slurm.conf
MARK="# written by phnn jobs/test-slurm.sh"
if [[ ! -f $CONF ]] || head -1 "$CONF" | grep -qF "$MARK"; then
  mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
  old_conf=$(cat "$CONF" 2>/dev/null || true)
  # The node's memory as Slurm may hand it out (90 % of RAM): the job script
  # asks --mem-per-cpu=2G per task.
  MEM_MB=$(awk '/^MemTotal:/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
  cat > "$CONF" <<CONF
$MARK
ClusterName=phnn-test
SlurmctldHost=$HOST
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmUser=root
SlurmdUser=root
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
ReturnToService=2
JobRequeue=1
MpiDefault=none
NodeName=$HOST CPUs=$(nproc) RealMemory=$MEM_MB State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
  if [[ $(cat "$CONF") != "$old_conf" ]] && pgrep -x 'slurmctld|slurmd' >/dev/null; then
    log "slurm.conf changed: restarting slurmctld and slurmd"
    pkill -x slurmd; pkill -x slurmctld; sleep 2
  fi
else
  log "using the existing $CONF (not written by this script)"
fi
pgrep -x slurmctld >/dev/null || slurmctld
pgrep -x slurmd >/dev/null || slurmd
for _ in $(seq 60); do
  sinfo -h -o %t 2>/dev/null | grep -qE "idle|mix|alloc" && break
  sleep 1
done
sinfo -h -o %t | grep -qE "idle|mix|alloc" || die "the node did not come up: $(sinfo 2>&1)"
log "$(sinfo -V): node $HOST $(sinfo -h -o %t), $(srun --mpi=list 2>&1 | tr '\n' ' ')"

# --- a small sweep: 10 cells of 1 run, ~7 s each --------------------------------
rm -rf "$WORK" && mkdir -p "$WORK"
cat > "$WORK/sweep.toml" <<'TOML'
name = "slurm-test"
[data]
num_validation = 40
num_inference = 3
[training]
steps = 20000
eval_every = 1000
batch_size = 16
[grid]
systems = ["harmonic"]
models = ["node-rk2", "phnn-s-rk2"]
n_train = [25, 26, 27, 28, 29]
seeds = [0]
TOML
OUT=$WORK/results.h5
journaled() { cat "$OUT.journal"/rank-*.log 2>/dev/null | grep -c '^run ' || true; }
job_field() { scontrol show job "$JOB" 2>/dev/null | tr ' ' '\n' | sed -n "s/^$1=//p" | head -1; }
wait_for() {  # wait_for SECONDS DESCRIPTION COMMAND...
  local limit=$1 what=$2; shift 2
  for _ in $(seq "$limit"); do "$@" && return 0; sleep 1; done
  die "timed out waiting for $what (job state $(job_field JobState)); log: $(cat "$WORK"/job-*.log 2>/dev/null)"
}
running_with_new_run() { [[ $(job_field JobState) == RUNNING && $(journaled) -gt $1 ]]; }

JOB=$(cd "$WORK" && PHNN=$PHNN sbatch --parsable --ntasks=2 --time=60 --output="$WORK/job-%j.log" \
      "$REPO/jobs/phnn-sweep.sbatch" "$WORK/sweep.toml" --out "$OUT" --quiet)
log "submitted job $JOB (2 tasks)"
wait_for 300 "a first journaled run" running_with_new_run 0
log "job $JOB running, $(journaled) run(s) journaled: USR1 to the batch script (as --signal=B:USR1 would)"
scancel --batch --signal=USR1 "$JOB"
wait_for 120 "the requeue after USR1" bash -c "[[ \$(scontrol show job $JOB | grep -o 'Restarts=[0-9]*') == Restarts=1 ]]"
before=$(journaled)
log "job $JOB requeued (Restarts=1) with $before run(s) journaled"
wait_for 300 "a run journaled after the requeue" running_with_new_run "$before"
log "$(journaled) run(s) journaled: scontrol requeue $JOB mid-run"
scontrol requeue "$JOB"
wait_for 600 "the job to finish" bash -c "[[ \$(scontrol show job $JOB | grep -o 'JobState=[A-Z]*') == JobState=COMPLETED ]]"
log "job $JOB COMPLETED after $(job_field Restarts) restarts; its log:"
sed 's/^/    /' "$WORK/job-$JOB.log"

# --- the table -----------------------------------------------------------------
check=$("$PHNN" sweep "$WORK/sweep.toml" --out "$OUT" --dry-run >/dev/null && \
        "$PHNN" sweep "$WORK/sweep.toml" --out "$OUT" --quiet 2>&1)
echo "$check" | sed 's/^/    /'
echo "$check" | grep -q "10 finished before, 0 to run" || die "the results file is not complete"
"$PHNN" reduce "$OUT" | sed 's/^/    /'
grep -q "stopped on a signal" "$WORK/job-$JOB.log" || die "the USR1 stop is not in the job log"
grep "finished before" "$WORK/job-$JOB.log" | tail -1 | grep -qE "; [1-9] finished before" ||
  die "the last start had nothing left to do: scontrol requeue did not interrupt the sweep"
log "PASSED: submit -> USR1 -> requeue -> scontrol requeue -> finished table"

# --- array mode: 4 shards as a strided array, then two resubmitted single tasks,
# --- then a merge job that depends on them -----------------------------------
job_state() { scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z]*' | sort -u | tr '\n' ' '; }
array_job() {  # array_job SPEC: one task per shard of PHNN_SHARDS=4
  (cd "$WORK" && PHNN=$PHNN PHNN_SHARDS=4 sbatch --parsable --array="$1" --ntasks=1 --time=60 \
     --output="$WORK/array-%A_%a.log" "$REPO/jobs/phnn-sweep.sbatch" "$WORK/sweep.toml" --quiet)
}
done_state() { [[ $(job_state "$1") == "JobState=COMPLETED " ]]; }
# An array task without PHNN_SHARDS refuses to guess (exit 2, the fix named).
BAD=$(cd "$WORK" && PHNN=$PHNN sbatch --parsable --array=1 --ntasks=1 --time=5 \
      --output="$WORK/bad-%A_%a.log" "$REPO/jobs/phnn-sweep.sbatch" "$WORK/sweep.toml" --quiet)
wait_for 120 "the array task without PHNN_SHARDS" bash -c "[[ \$(scontrol show job $BAD | grep -o 'JobState=[A-Z]*') == JobState=FAILED ]]"
grep -q "set PHNN_SHARDS to the number of shards" "$WORK"/bad-*.log || die "no PHNN_SHARDS message"
STRIDED=$(array_job 0-3:2)
wait_for 600 "the strided array 0-3:2" done_state "$STRIDED"
shards() { ls "$WORK"/results/slurm-test.shard-*-of-4.h5 2>/dev/null | sed 's/.*shard-\([0-9]\)-of-4.h5/\1/' | tr '\n' ' '; }
[[ $(shards) == "0 2 " ]] || die "the strided array 0-3:2 wrote shards '$(shards)', expected '0 2 '"
log "strided array $STRIDED (--array=0-3:2) trained shards 0 and 2 of 4, nothing else"
ONE=$(array_job 1)
THREE=$(array_job 3)
MERGE=$(cd "$WORK" && sbatch --parsable --dependency=afterok:"$ONE":"$THREE" --ntasks=1 --time=10 \
        --output="$WORK/merge-%j.log" --wrap "$PHNN merge $WORK/merged.h5 \
        $(echo "$WORK"/results/slurm-test.shard-{0,1,2,3}-of-4.h5)")
log "resubmitted single tasks $ONE (--array=1) and $THREE (--array=3); merge job $MERGE"
wait_for 600 "the merge job" bash -c "[[ \$(scontrol show job $MERGE | grep -o 'JobState=[A-Z]*') == JobState=COMPLETED ]]"
[[ $(shards) == "0 1 2 3 " ]] || die "shards '$(shards)' after the resubmits, expected '0 1 2 3 '"
for s in 0 1 2 3; do
  grep -q "shard $s/4" "$WORK"/array-*.log || die "no log line of shard $s/4"
done
log "arrays: $(job_state "$STRIDED") $(job_state "$ONE") $(job_state "$THREE"); merge COMPLETED; logs:"
sed 's/^/    /' "$WORK"/array-*.log "$WORK"/merge-*.log
grep -q "4 shards merged: 10 of 10 runs with results" "$WORK"/merge-*.log || die "the merge is incomplete"
mse_column() {  # the run ids and MSEs of a results file, sorted by id
  "$PHNN" reduce "$1" --format csv --per-run |
    awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "mse") c = i; next } { print $1, $c }' | sort
}
[[ -n $(mse_column "$OUT") && $(mse_column "$WORK/merged.h5") == "$(mse_column "$OUT")" ]] ||
  die "the merged shards differ from the single job's results"
"$PHNN" reduce "$WORK/merged.h5" | sed 's/^/    /'
log "PASSED: strided array + resubmitted tasks (PHNN_SHARDS=4) -> merge -> the single job's results, run for run"
