#!/usr/bin/env bash
# Stops the one-node cluster that start-cluster.sh started in DIR: cancels its jobs, stops
# slurmd, slurmctld and munged by the process ids recorded in DIR (nothing else), waits for
# them to end (SIGKILL after 15 s), then removes DIR unless KEEP=1.
#
# Usage: bash scripts/slurm/stop-cluster.sh DIR
set -uo pipefail

dir="${1:?usage: stop-cluster.sh DIR}"
[ -d "$dir" ] || exit 0
SUDO=""
if [ "$(id -u)" != 0 ] && command -v sudo >/dev/null 2>&1; then SUDO="sudo -n"; fi
PATH="$PATH:/usr/sbin:/sbin"

if [ -f "$dir/slurm.conf" ]; then
  export SLURM_CONF="$dir/slurm.conf"
  timeout 10 scancel --quiet --full --user "$(id -un)" >/dev/null 2>&1 || true
fi

# The launcher ids are the daemons' own (they ran in the foreground); the pid files the
# daemons wrote are a second source, for a daemon that forked. The launcher's command is
# checked against the daemon's name so a reused id is never signalled.
pids=()
for d in slurmd slurmctld munged; do
  for f in "$dir/$d.launcher.pid" "$dir/$d.pid"; do
    [ -s "$f" ] || continue
    pid="$(cat "$f")"
    [[ "$pid" =~ ^[0-9]+$ ]] || continue
    comm="$(cat "/proc/$pid/comm" 2>/dev/null || true)"
    case "$comm" in
      "$d" | sudo | env) pids+=("$pid") ;;
    esac
  done
done

for pid in "${pids[@]}"; do $SUDO kill -TERM "$pid" 2>/dev/null || true; done
deadline=$((SECONDS + 15))
for pid in "${pids[@]}"; do
  while kill -0 "$pid" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.2; done
  if kill -0 "$pid" 2>/dev/null; then $SUDO kill -KILL "$pid" 2>/dev/null || true; fi
done

if [ "${KEEP:-0}" != 1 ]; then
  $SUDO rm -rf "$dir"
fi
exit 0
