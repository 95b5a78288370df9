#!/usr/bin/env bash
# A real single-node Slurm cluster for `tyndall sweep --executor slurm` (issue 36): starts munged, slurmctld and slurmd
# on localhost with a minimal slurm.conf in a scratch folder (no systemd), submits a small sweep, waits for its gather
# job, and checks its CSV against the same sweep run by the local executor (identical metrics for identical seeds).
# Then a sweep whose tasks fail: the gather job must not run. Stops the daemons it started, by their pids.
#   tests/slurm/slurm-sweep.sh TYNDALL SCRATCH SOURCE_DIR
# Exit 0: passed; 1: failed; 77: skipped (the daemons are not installed or cannot start; the reason is printed).
set -euo pipefail
tyndall=$1
scratch=$2
source_dir=$3

skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAILED: $*"; exit 1; }
for program in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
    command -v "$program" >/dev/null ||
        skip "$program is not installed (slurm-wlm and munge are in packaging/debian-packages.txt: run packaging/install-deps.sh)"
done

rm -rf "$scratch"
mkdir -p "$scratch/state" "$scratch/spool"
pids=()  # of the daemons this run started, read from their pid files as soon as they are written
remember() {  # daemon
    for _ in $(seq 50); do
        if [[ -s "$scratch/$1.pid" ]]; then pids+=("$(cat "$scratch/$1.pid")"); return 0; fi
        sleep 0.1
    done
    skip "$1 wrote no pid file: $(tail -n 3 "$scratch/$1.log" 2>/dev/null)"
}
cleanup() {
    [[ ${#pids[@]} -gt 0 ]] || return 0
    kill "${pids[@]}" 2>/dev/null || true
    for _ in $(seq 50); do  # wait for them to go, so that the next run finds the ports free
        kill -0 "${pids[@]}" 2>/dev/null || return 0
        sleep 0.1
    done
    kill -9 "${pids[@]}" 2>/dev/null || true
}
trap cleanup EXIT

# munge: a key of our own and a socket in the scratch folder.
mungekey --create --keyfile="$scratch/munge.key" >/dev/null 2>&1 || skip "mungekey could not create a key"
chmod 600 "$scratch/munge.key"
munged --force --socket="$scratch/munge.sock" --key-file="$scratch/munge.key" --pid-file="$scratch/munged.pid" \
    --log-file="$scratch/munged.log" --seed-file="$scratch/munged.seed" ||
    skip "munged did not start: $(tail -n 3 "$scratch/munged.log" 2>/dev/null)"
remember munged

# Slurm: this host as the controller and the only node, on ports of this run.
host=$(hostname -s)
port=$((20000 + $$ % 20000))
cpus=$(nproc)
cat >"$scratch/slurm.conf" <<CONF
ClusterName=tyndall-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$scratch/munge.sock
CryptoType=crypto/munge
SlurmUser=$(id -un)
StateSaveLocation=$scratch/state
SlurmdSpoolDir=$scratch/spool
SlurmctldPidFile=$scratch/slurmctld.pid
SlurmdPidFile=$scratch/slurmd.pid
SlurmctldLogFile=$scratch/slurmctld.log
SlurmdLogFile=$scratch/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=1
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$scratch/slurm.conf
slurmctld -f "$SLURM_CONF" || skip "slurmctld did not start: $(tail -n 3 "$scratch/slurmctld.log" 2>/dev/null)"
remember slurmctld
slurmd -f "$SLURM_CONF" || skip "slurmd did not start: $(tail -n 3 "$scratch/slurmd.log" 2>/dev/null)"
remember slurmd
for _ in $(seq 100); do
    [[ "$(sinfo -h -o %T 2>/dev/null)" == idle ]] && break
    sleep 0.2
done
[[ "$(sinfo -h -o %T 2>/dev/null)" == idle ]] ||
    skip "the node did not come up: $(sinfo 2>&1 | tail -n 2); $(tail -n 3 "$scratch/slurmd.log" 2>/dev/null)"
echo "Slurm is up: $(sinfo -h -o '%P %D %T %C')"

# Waits until the queue is empty (at most five minutes).
wait_queue() {
    for _ in $(seq 1500); do
        [[ -z "$(squeue -h 2>/dev/null)" ]] && return 0
        sleep 0.2
    done
    squeue
    fail "the jobs did not finish in five minutes"
}

cat >"$scratch/test.sweep.json" <<SPEC
{"tyndallSweep": 1, "name": "slurm test", "project": "$source_dir/projects/ltsd/fig10-nodes.json", "size": "32x24",
 "views": ["N 8 equiangular", "volume-ris"], "grid": {"media[fog].phase.g": [-0.5, 0.4]},
 "seeds": [1, 2], "spp": 1, "reference": {"spp": 32, "shards": 2}}
SPEC

# 1. The sweep on Slurm: an array of 12 tasks, at most 2 at a time, and the gather job after it.
"$tyndall" sweep "$scratch/test.sweep.json" --out "$scratch/slurm" --executor slurm --max-running 2 \
    --cpus-per-task 1 | tee "$scratch/submit.log"
grep -q "submitted 12 task(s) as Slurm array job" "$scratch/submit.log" || fail "the sweep was not submitted"
wait_queue
"$tyndall" sweep --status "$scratch/slurm" | tee "$scratch/status.log"
grep -q "12 done, 0 running, 0 failed" "$scratch/status.log" || fail "not every task is done"
[[ -f "$scratch/slurm/results.csv" ]] || fail "the gather job wrote no results.csv: $(cat "$scratch"/slurm/logs/slurm-gather-*.out 2>&1)"

echo "the Slurm sweep took $SECONDS s since the start"
# 2. The same sweep here; the metrics (every column but the render time) must be identical.
"$tyndall" sweep "$scratch/test.sweep.json" --out "$scratch/local" --jobs 2 >/dev/null
metrics() {  # results.csv without its renderTime column
    python3 -c '
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, name in enumerate(rows[0]) if name != "renderTime"]
for row in rows: print(",".join(row[i] for i in keep))' "$1"
}
diff <(metrics "$scratch/slurm/results.csv") <(metrics "$scratch/local/results.csv") ||
    fail "the Slurm sweep's metrics differ from the local sweep's"
echo "Slurm and local sweeps agree on $(($(wc -l <"$scratch/local/results.csv") - 1)) renders"

# 3. Failing tasks: the project breaks after the sweep was planned. Every task fails (exit 2, in its log); the gather
#    job, which depends on all of them succeeding, must not run.
cp "$source_dir/projects/ltsd/fig10-nodes.json" "$scratch/broken.json"
sed "s|$source_dir/projects/ltsd/fig10-nodes.json|$scratch/broken.json|" "$scratch/test.sweep.json" >"$scratch/broken.sweep.json"
"$tyndall" sweep "$scratch/broken.sweep.json" --out "$scratch/broken" --executor slurm --no-submit >/dev/null
echo '{"tyndall": 1, "camera": ' >"$scratch/broken.json"
array=$(sbatch --parsable "$scratch/broken/slurm/array.sh")
sbatch --parsable --dependency="afterok:$array" --kill-on-invalid-dep=yes "$scratch/broken/slurm/gather.sh" >/dev/null
wait_queue
"$tyndall" sweep --status "$scratch/broken" | tee "$scratch/broken-status.log"
grep -q "0 done, 0 running, 12 failed" "$scratch/broken-status.log" || fail "the broken sweep's tasks are not failed"
grep -q "logs/" "$scratch/broken-status.log" || fail "the status names no logs"
[[ ! -e "$scratch/broken/results.csv" ]] || fail "the gather job ran although its tasks failed"
compgen -G "$scratch/broken/logs/slurm-gather-*.out" >/dev/null && fail "the gather job ran although its tasks failed"
echo "PASSED"
