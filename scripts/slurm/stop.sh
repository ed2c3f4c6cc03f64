#!/usr/bin/env bash
# Stop the cluster that scripts/slurm/start.sh started in DIR: slurmd, slurmctld, munged, by
# the process ids in their pid files. Idempotent; DIR is kept (logs) unless --purge is given.
#
#   scripts/slurm/stop.sh [DIR] [--purge]
set -uo pipefail

purge=0
args=()
for a in "$@"; do
    if [[ $a == --purge ]]; then purge=1; else args+=("$a"); fi
done
dir=$(realpath -m "${args[0]:-${VNRRT_SLURM_DIR:-/tmp/vnrrt-slurm}}")

# Cancel this cluster's jobs first, so that no job step outlives the daemons.
if [[ -f $dir/slurm.conf && -f $dir/slurmctld.pid ]] && kill -0 "$(cat "$dir/slurmctld.pid")" 2>/dev/null; then
    export SLURM_CONF=$dir/slurm.conf
    scancel --full --user="$(id -un)" 2>/dev/null || true
    for _ in $(seq 50); do
        [[ -z $(squeue -h -o %i 2>/dev/null) ]] && break
        sleep 0.2
    done
fi
# SIGTERM all three at once (each takes about 2 s to exit), SIGKILL what is left after 10 s.
pids=()
for daemon in slurmd slurmctld munged; do
    pid=$(cat "$dir/$daemon.pid" 2>/dev/null || true)
    if [[ $pid =~ ^[0-9]+$ ]] && kill -0 "$pid" 2>/dev/null; then
        kill "$pid" && pids+=("$pid")
    fi
    rm -f "$dir/$daemon.pid"
done
for _ in $(seq 100); do
    alive=()
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive+=("$pid"); done
    ((${#alive[@]})) || break
    sleep 0.1
done
for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && kill -9 "$pid"; done
if ((purge)); then rm -rf "$dir"; fi
