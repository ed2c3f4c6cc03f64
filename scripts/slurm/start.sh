#!/usr/bin/env bash
# Start a one-node SLURM cluster on this host: munged, slurmctld and slurmd, all private to
# one state directory (own munge key and socket, own ports), as root, without systemd.
#
#   scripts/slurm/start.sh [DIR]     # DIR defaults to $VNRRT_SLURM_DIR or /tmp/vnrrt-slurm
#   export SLURM_CONF=DIR/slurm.conf # what it prints last: sinfo, sbatch and submitit read it
#   scripts/slurm/stop.sh [DIR]
#
# Needs Debian's slurm-wlm and munge (`.ci/slurm-setup` installs them). The node is
# `localhost` with every core of this host (nproc), in the default partition `debug`.
set -euo pipefail

dir=$(realpath -m "${1:-${VNRRT_SLURM_DIR:-/tmp/vnrrt-slurm}}")
timeout_s=${VNRRT_SLURM_TIMEOUT:-60}
for exe in munged mungekey slurmctld slurmd sinfo; do
    command -v "$exe" >/dev/null || { echo "$exe not found: run .ci/slurm-setup" >&2; exit 1; }
done
if [[ -f $dir/slurmctld.pid ]] && kill -0 "$(cat "$dir/slurmctld.pid")" 2>/dev/null; then
    echo "a cluster is already running in $dir (stop it with scripts/slurm/stop.sh $dir)" >&2
    exit 1
fi

if ((${#dir} > 80)); then  # unix socket paths are limited to 108 bytes
    echo "state directory path too long for munge's socket: $dir" >&2
    exit 1
fi

# Two distinct free ports (both sockets are open while they are picked).
read -r ctld_port slurmd_port < <(python3 -c '
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks:
    s.bind(("127.0.0.1", 0))
print(*(s.getsockname()[1] for s in socks))')

mkdir -p "$dir"/{munge,state,spool,log}
chmod 0700 "$dir/munge"
key=$dir/munge/munge.key
[[ -f $key ]] || mungekey --create --keyfile="$key"
chmod 0600 "$key"

cpus=$(nproc)
mem_mb=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
cat >"$dir/slurm.conf" <<CONF
# Written by scripts/slurm/start.sh: a one-node cluster private to $dir.
ClusterName=vnrrt
SlurmctldHost=$(hostname -s)(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
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
SwitchType=switch/none
MailProg=/bin/true
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
ReturnToService=2
SchedulerType=sched/backfill
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=localhost NodeAddr=127.0.0.1 NodeHostname=localhost CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
echo 'CgroupPlugin=autodetect' >"$dir/cgroup.conf"
export SLURM_CONF=$dir/slurm.conf

# From here on, a failure stops whatever was started.
trap '"$(dirname "$0")/stop.sh" "$dir"' ERR
munged --force --socket="$dir/munge/munge.socket" --key-file="$key" \
    --pid-file="$dir/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/seed"
slurmctld -c -f "$SLURM_CONF"  # -c: no state from an earlier run
slurmd -N localhost -f "$SLURM_CONF"

for ((i = 0; i < timeout_s; i++)); do
    state=$(sinfo -h -n localhost -o %T 2>/dev/null || true)
    if [[ $state == idle ]]; then
        echo "export SLURM_CONF=$SLURM_CONF"
        exit 0
    fi
    sleep 1
done
echo "node not idle after ${timeout_s}s (state: ${state:-none}); logs in $dir/log" >&2
tail -n 20 "$dir"/log/*.log >&2 || true
"$(dirname "$0")/stop.sh" "$dir"
exit 1
