#!/usr/bin/env bash
# Submits scripts/slurm/array.sbatch and its dependent merge.sbatch to a one-node
# Slurm cluster started here for the test (munged, slurmctld and slurmd on private
# sockets, ports and folders), and checks that the merged output is one process's
# bytes. Exits 77 (ctest: skipped) where that cluster cannot run: slurm-wlm or munge
# missing, not root, or daemons that do not come up.
#
#   tests/slurm_one_node.sh OOCSIMP_CLI SOURCE_DIR
set -uo pipefail
cli="$1"
source_dir="$2"
skip() {
  echo "slurm_one_node: skipped: $1"
  exit 77
}
for b in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$b" >/dev/null || skip "$b is missing (Debian's slurm-wlm and munge)"
done
[ "$(id -u)" = 0 ] || skip "the daemons need root here"

d=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  [ -f "$d/munged.pid" ] && kill "$(cat "$d/munged.pid")" 2>/dev/null
  sleep 0.5
  rm -rf "$d"
}
trap cleanup EXIT

host=$(hostname -s)
port=$((20000 + RANDOM % 20000))
mkdir -p "$d/ctld" "$d/spool" "$d/work"
head -c 1024 /dev/urandom >"$d/munge.key"
chmod 400 "$d/munge.key"
munged --force --key-file="$d/munge.key" --socket="$d/munge.sock" --pid-file="$d/munged.pid" \
  --log-file="$d/munged.log" --seed-file="$d/munged.seed" 2>"$d/munged.err" || skip "munged did not start: $(cat "$d/munged.err")"
cat >"$d/slurm.conf" <<EOF
ClusterName=oocsimptest
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$d/munge.sock
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
ReturnToService=2
SlurmUser=root
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmdSpoolDir=$d/spool
StateSaveLocation=$d/ctld
SlurmctldLogFile=$d/slurmctld.log
SlurmdLogFile=$d/slurmd.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
NodeName=$host CPUs=$(nproc) RealMemory=2000 State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$d/slurm.conf"
slurmctld -D -f "$SLURM_CONF" >"$d/ctld.out" 2>&1 &
pids+=($!)
sleep 1
slurmd -D -f "$SLURM_CONF" >"$d/slurmd.out" 2>&1 &
pids+=($!)
up=0
for _ in $(seq 1 40); do
  if sinfo -h -o %t 2>/dev/null | grep -q idle; then up=1; break; fi
  sleep 0.5
done
[ "$up" = 1 ] || skip "the one-node cluster did not come up: $(tail -2 "$d/slurmctld.log" "$d/slurmd.log" 2>/dev/null | tr '\n' ' ')"

"$cli" generate --tris 200000 --quiet -o "$d/in.ply" || exit 1
"$cli" simplify "$d/in.ply" -o "$d/one.ply" --method uniform --grid 200 --quiet || exit 1
export OOCSIMP="$cli" OPTIONS="--method uniform --grid 200" TMP="$d"
cd "$d"
array=$(sbatch --parsable --cpus-per-task=1 --mem=200M --array=0-2 "$source_dir/scripts/slurm/array.sbatch" \
  "$d/in.ply" "$d/work" 3) || { echo "slurm_one_node: sbatch of the array failed"; exit 1; }
merge=$(sbatch --parsable --cpus-per-task=1 --mem=500M --dependency=afterok:"$array" \
  "$source_dir/scripts/slurm/merge.sbatch" "$d/work" "$d/out.ply") || { echo "slurm_one_node: sbatch of the merge failed"; exit 1; }
for _ in $(seq 1 240); do
  [ -z "$(squeue -h -j "$array,$merge" 2>/dev/null)" ] && break
  sleep 0.5
done
if ! cmp -s "$d/one.ply" "$d/out.ply"; then
  echo "slurm_one_node: the array job and its merge did not give one process's bytes"
  tail -n 5 "$d"/oocsimp-*.log 2>/dev/null
  exit 1
fi
echo "slurm_one_node: array job $array (3 parts) and merge job $merge gave one process's bytes"
