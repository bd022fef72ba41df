#!/usr/bin/env bash
# End to end: `clearway bench` cut into 3 shards by a Slurm job array (benchmarks/slurm/submit.sh) on a
# one-node cluster started here (munged, slurmctld and slurmd from Debian, own config and socket, all
# stopped on exit), merged by a dependent job, and compared with an unsharded run: every field but
# the measured time must be equal. Slurm's daemons need root; without root or without Slurm the same
# shards run through GNU parallel instead, and the test says so.
# Usage: bench_shards_slurm.sh CLEARWAY_BINARY SOURCE_DIR
set -euo pipefail
clearway=$1
source_dir=$2
work=$(mktemp -d /tmp/clearway-slurm-test.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  [ -f "$work/slurm/slurmd.pid" ] && kill "$(cat "$work/slurm/slurmd.pid")" 2>/dev/null || true
  [ -f "$work/slurm/slurmctld.pid" ] && kill "$(cat "$work/slurm/slurmctld.pid")" 2>/dev/null || true
  [ -f "$work/slurm/munged.pid" ] && kill "$(cat "$work/slurm/munged.pid")" 2>/dev/null || true
  sleep 0.5
  rm -rf "$work"
}
trap cleanup EXIT

# The shared data as the C++ tests find it (tests/shared_data.h): $CLEARWAY_SHARED, else ../shared; with
# CI=true it must be there.
shared=${CLEARWAY_SHARED:-$source_dir/../shared}
args=(narrowphase --count 10 --seed 5)
if [ -d "$shared/scenes" ]; then
  args=(narrowphase states --count 8 --subjects hull16,box-capsule,cylinder-cone,box_panda --seed 5 --shared "$shared")
elif [ "${CI:-}" = true ]; then
  echo "shared data not found: $shared/scenes (required because CI=true)" >&2
  exit 1
fi
"$clearway" bench "${args[@]}" --out "$work/all" >/dev/null 2>"$work/all.err" || { cat "$work/all.err"; exit 1; }

start_slurm() {
  local d=$work/slurm host
  host=$(hostname -s)
  mkdir -p "$d/state" "$d/spool"
  local key=/etc/munge/munge.key
  if [ ! -r "$key" ]; then
    key=$d/munge.key
    dd if=/dev/urandom of="$key" bs=1024 count=1 2>/dev/null
    chmod 600 "$key"
  fi
  munged --force --socket="$d/munge.sock" --pid-file="$d/munged.pid" --key-file="$key" \
    --log-file="$d/munged.log" --seed-file="$d/munged.seed" 2>>"$d/munged.err" || return 1
  cat >"$d/slurm.conf" <<CONF
ClusterName=clearwaytest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$d/munge.sock
CredType=cred/munge
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/slurmctld.log
SlurmdLogFile=$d/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$d/slurm.conf
  slurmctld -i 2>>"$d/slurmctld.err" || return 1
  slurmd -N "$host" 2>>"$d/slurmd.err" || return 1
  for _ in $(seq 60); do
    if sinfo -h -o %t 2>/dev/null | grep -q idle; then return 0; fi
    sleep 0.5
  done
  echo "bench_shards_slurm: the node never became idle" >&2
  tail -5 "$d/slurmctld.log" "$d/slurmd.log" >&2 || true
  return 1
}

if [ "$(id -u)" = 0 ] && command -v munged >/dev/null && command -v slurmctld >/dev/null &&
  command -v slurmd >/dev/null && command -v sbatch >/dev/null; then
  start_slurm
  merge_job=$(CLEARWAY="$clearway" bash "$source_dir/benchmarks/slurm/submit.sh" 3 "$work/sharded" "${args[@]}")
  echo "slurm: merge job $merge_job queued after a 3-task array"
  for _ in $(seq 600); do
    [ -z "$(squeue -h -j "$merge_job" 2>/dev/null)" ] && break
    sleep 0.5
  done
  state=$(sacct -n -j "$merge_job" -o State 2>/dev/null | head -1 || true)
  if [ ! -f "$work/sharded/results.csv" ]; then
    echo "bench_shards_slurm: the merge job wrote nothing (state: ${state:-unknown})" >&2
    cat "$work/sharded"/*.log >&2 2>/dev/null || true
    exit 1
  fi
  ls "$work/sharded"/clearway-bench-*.log >/dev/null || { echo "no array task logs" >&2; exit 1; }
  via="Slurm (3 array tasks on a one-node cluster, merge job after them)"
elif command -v parallel >/dev/null; then
  echo "bench_shards_slurm: not root or no Slurm here: the shards run through GNU parallel instead"
  parallel --will-cite -j2 "'$clearway'" bench "${args[@]}" --shard '{}/3' --out "$work/sharded/shard-{}" \
    ::: 0 1 2 >/dev/null
  "$clearway" bench merge --out "$work/sharded" "$work/sharded"/shard-{0,1,2} >/dev/null
  via="GNU parallel (3 shards)"
else
  echo "bench_shards_slurm: neither Slurm (as root) nor GNU parallel is installed (scripts/install-deps.sh installs both)" >&2
  exit 1
fi

strip() { grep -v '^#' "$1" | cut -d, -f8 --complement; }
if ! diff <(strip "$work/all/results.csv") <(strip "$work/sharded/results.csv") >"$work/diff"; then
  echo "bench_shards_slurm: the merged shards differ from the unsharded run:" >&2
  cat "$work/diff" >&2
  exit 1
fi
rows=$(strip "$work/all/results.csv" | tail -n +2 | wc -l)
[ "$rows" -ge 18 ] || { echo "bench_shards_slurm: only $rows rows" >&2; exit 1; }
for f in summary.csv table.txt plots.gp; do
  [ -s "$work/sharded/$f" ] || { echo "bench_shards_slurm: merged $f missing" >&2; exit 1; }
done
echo "bench_shards_slurm: $rows rows, sharded through $via, equal to the unsharded run"
