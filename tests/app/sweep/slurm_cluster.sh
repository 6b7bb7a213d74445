#!/usr/bin/env bash
# A one-node SLURM cluster on localhost for the tests (Debian slurm-wlm + munge), everything in one
# temporary directory: its own munge key and socket, slurm.conf (proctrack/linuxproc, task/none, no
# cgroups, accounting off), state, spool and logs, on ports of its own. Source this file, then
#   slurm_cluster_start DIR   # starts munged, slurmctld and slurmd; exports SLURM_CONF; waits until the node is idle
#   slurm_cluster_stop DIR    # stops the three daemons (by the pids they wrote) and leaves DIR for the logs
# slurm_cluster_available says whether the binaries are installed (scripts/install-deps.sh installs them).

slurm_cluster_available() {
  command -v munged >/dev/null && command -v slurmctld >/dev/null && command -v slurmd >/dev/null &&
    command -v sbatch >/dev/null && command -v squeue >/dev/null && command -v scancel >/dev/null
}

slurm_cluster_start() {
  local d="$1"
  mkdir -p "$d"/munge "$d"/state "$d"/spool "$d"/log
  chmod 700 "$d"/munge
  dd if=/dev/urandom of="$d"/munge/munge.key bs=1024 count=1 status=none
  chmod 400 "$d"/munge/munge.key
  # munged refuses to run as root without --force (it is a test daemon here, with its own key).
  munged --force --socket="$d"/munge/munge.sock --key-file="$d"/munge/munge.key \
    --pid-file="$d"/munge/munged.pid --log-file="$d"/log/munged.log --seed-file="$d"/munge/seed || return 1
  # Ports of this cluster: from the pid, so that two test runs on one machine do not meet.
  local base=$((20000 + ($$ % 2000) * 4))
  local cpus; cpus=$(nproc)
  local user; user=$(id -un)
  cat > "$d"/slurm.conf <<CONF
ClusterName=pneufemtest
SlurmctldHost=localhost
SlurmctldPort=$base
SlurmdPort=$((base + 1))
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$d/munge/munge.sock
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool/%n
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/log/slurmctld.log
SlurmdLogFile=$d/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
SlurmctldTimeout=30
SlurmdTimeout=30
MinJobAge=300
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$d"/slurm.conf
  slurmctld -f "$d"/slurm.conf -i || return 1
  slurmd -f "$d"/slurm.conf -N localhost || return 1
  local i
  for i in $(seq 1 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qx idle; then return 0; fi
    sleep 0.5
  done
  echo "slurm_cluster_start: the node did not become idle in 30 s; logs in $d/log" >&2
  sinfo >&2 || true
  return 1
}

slurm_cluster_stop() {
  local d="$1" f i pid
  # The jobs first (a job step left behind would outlive its slurmd), then the daemons, each
  # waited for, by the pids they wrote.
  if [ -n "${SLURM_CONF:-}" ]; then
    scancel --quiet --user="$(id -un)" 2>/dev/null || true
    for i in $(seq 1 40); do
      [ -z "$(squeue -h -o %A 2>/dev/null)" ] && break
      sleep 0.5
    done
  fi
  for f in "$d"/slurmd.pid "$d"/slurmctld.pid "$d"/munge/munged.pid; do
    [ -s "$f" ] || continue
    pid=$(cat "$f")
    kill "$pid" 2>/dev/null || continue
    for i in $(seq 1 40); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.25
    done
  done
}
