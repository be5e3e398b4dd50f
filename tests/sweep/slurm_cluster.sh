#!/bin/bash
# A one-node Slurm cluster on this machine, for the sweep tests: munged, slurmctld and slurmd from
# Debian's munge and slurm-wlm, configured in a folder of their own (no file outside it is touched,
# nothing listens beyond 127.0.0.1's two ports).
#   source tests/sweep/slurm_cluster.sh; slurm_start DIR CPUS || exit 77; ...; slurm_stop DIR
# slurm_start exports SLURM_CONF and prints why when a daemon cannot start (returns 1).

# Two free ports on 127.0.0.1, found by one process holding both sockets at once (so they differ).
slurm_free_ports() {
  python3 -c 'import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])'
}

slurm_start() {
  local dir=$1 cpus=${2:-2} node mem
  node=$(hostname -s)
  # The node as this machine is (slurmd refuses to register a node smaller than it is configured).
  [ "$cpus" -le "$(nproc)" ] || cpus=$(nproc)
  mem=$(( $(awk '/^MemTotal:/ { print $2 }' /proc/meminfo) / 1024 / 2 ))
  for tool in munged slurmctld slurmd sbatch squeue scontrol; do
    command -v "$tool" > /dev/null || { echo "slurm_start: $tool is not installed (scripts/install_deps.sh)"; return 1; }
  done
  mkdir -p "$dir"/{munge,state,spool,log}
  chmod 711 "$dir/munge"
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
  chmod 600 "$dir/munge/munge.key"
  if ! munged --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
      --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/seed" --force; then
    echo "slurm_start: munged did not start: $(tail -n 3 "$dir/munge/munged.log" 2>/dev/null)"; return 1
  fi
  local ports ctl_port dport
  ports=$(slurm_free_ports) || { echo "slurm_start: no free port"; return 1; }
  read -r ctl_port dport <<< "$ports"
  cat > "$dir/slurm.conf" <<CONF
ClusterName=mbotsweep
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctl_port
SlurmdPort=$dport
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
# Slurm's high-throughput settings: by default a finished batch task's CPUs are given to the next one
# up to 3 s later (batch_sched_delay), which a sweep of 1-second jobs would mostly spend waiting.
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
JobRequeue=1
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=sweep Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -f "$SLURM_CONF" || { echo "slurm_start: slurmctld did not start: $(tail -n 3 "$dir/log/slurmctld.log")"; return 1; }
  slurmd -f "$SLURM_CONF" || { echo "slurm_start: slurmd did not start: $(tail -n 3 "$dir/log/slurmd.log")"; return 1; }
  local i
  for i in $(seq 1 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -q '^idle'; then return 0; fi
    sleep 0.5
  done
  echo "slurm_start: the node never became idle: $(sinfo 2>&1 | tail -n 2); $(tail -n 3 "$dir/log/slurmd.log")"
  return 1
}

slurm_stop() {
  local dir=$1 f i
  [ -f "$dir/slurm.conf" ] && SLURM_CONF="$dir/slurm.conf" scancel --full --quiet --partition=sweep 2> /dev/null
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -f "$f" ] && kill "$(cat "$f")" 2> /dev/null
  done
  for i in $(seq 1 20); do  # until the daemons are gone (at most 10 s)
    local alive=0
    for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
      [ -f "$f" ] && kill -0 "$(cat "$f")" 2> /dev/null && alive=1
    done
    [ $alive = 0 ] && break
    sleep 0.5
  done
  return 0
}
