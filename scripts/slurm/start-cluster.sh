#!/usr/bin/env bash
# Starts a one-node Slurm cluster on this machine, for trying and testing the sbatch scripts:
# munged, slurmctld and slurmd, started by hand (no systemd), everything they keep (key, socket,
# state, spool, logs, slurm.conf) under DIR. Needs root (or sudo) and Debian's slurm-wlm and
# munge (scripts/install-deps.sh installs them).
#
# Usage: bash scripts/slurm/start-cluster.sh DIR
# Then:  export SLURM_CONF=DIR/slurm.conf  (sbatch, squeue, sinfo use it)
# Stop:  bash scripts/slurm/stop-cluster.sh DIR
#
# The node is this machine under its real host name, with the CPUs and memory `slurmd -C`
# finds; the daemons listen on free ports picked at random (never the default 6817/6818), so
# a Slurm already on the machine is left alone. Exits non-zero with one sentence saying why
# when the cluster does not come up within the timeout (RAYTREE_SLURM_TIMEOUT, 90 s);
# whatever it started is stopped again then.
set -euo pipefail

dir="${1:?usage: start-cluster.sh DIR (a new or empty folder)}"
timeout="${RAYTREE_SLURM_TIMEOUT:-90}"
here="$(cd "$(dirname "$0")" && pwd)"

fail() {
  echo "start-cluster: $*" >&2
  for log in munged.log slurmctld.log slurmd.log; do
    if [ -s "$dir/$log" ]; then
      echo "---- last lines of $dir/$log" >&2
      tail -n 15 "$dir/$log" >&2
    fi
  done
  bash "$here/stop-cluster.sh" "$dir" >/dev/null 2>&1 || true
  exit 1
}

SUDO=""
if [ "$(id -u)" != 0 ]; then
  if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    SUDO="sudo -n"
  else
    echo "start-cluster: the Slurm daemons must run as root, and this user ($(id -un)) is not root and has no password-less sudo" >&2
    exit 1
  fi
fi
for tool in munged slurmctld slurmd sinfo sbatch squeue scontrol; do
  command -v "$tool" >/dev/null 2>&1 || PATH="$PATH:/usr/sbin:/sbin"
  command -v "$tool" >/dev/null 2>&1 ||
    { echo "start-cluster: $tool is not installed; run scripts/install-deps.sh (Debian packages slurm-wlm and munge)" >&2; exit 1; }
done

mkdir -p "$dir"
dir="$(cd "$dir" && pwd)"
if [ -e "$dir/slurm.conf" ]; then
  echo "start-cluster: $dir already holds a cluster (slurm.conf); stop it with stop-cluster.sh or use a new folder" >&2
  exit 1
fi
# munged refuses folders that others may write to; others may pass through (the socket).
chmod 0711 "$dir"
mkdir -p "$dir/state" "$dir/spool"

# A port nobody listens on (bash's /dev/tcp connect fails on a free port).
free_port() {
  local p
  for _ in $(seq 1 50); do
    p=$((20000 + RANDOM % 30000))
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then
      echo "$p"
      return 0
    fi
  done
  return 1
}
ctld_port="$(free_port)" || fail "no free TCP port found for slurmctld"
slurmd_port="$(free_port)" || fail "no free TCP port found for slurmd"
[ "$ctld_port" != "$slurmd_port" ] || slurmd_port=$((ctld_port + 1))

# The node as slurmd sees it: host name, CPUs, sockets, cores, threads, memory.
node_line="$(slurmd -C 2>/dev/null | grep '^NodeName=' || true)"
[ -n "$node_line" ] || fail "slurmd -C did not describe this machine"
node="$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' <<<"$node_line")"
mem="$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$node_line")"
# A little under the memory found, so a later, slightly smaller reading never drains the node.
mem=$((mem > 200 ? mem - 100 : mem))
node_line="$(sed "s/RealMemory=[0-9]*/RealMemory=$mem/" <<<"$node_line")"

# munge: a fresh key and a socket of our own.
dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 status=none
chmod 0400 "$dir/munge.key"
$SUDO munged --foreground --force --key-file="$dir/munge.key" --socket="$dir/munge.sock" \
  --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munged.seed" \
  </dev/null >>"$dir/munged.log" 2>&1 &
echo $! >"$dir/munged.launcher.pid"

cat >"$dir/slurm.conf" <<EOF
# A one-node test cluster made by scripts/slurm/start-cluster.sh.
ClusterName=raytree
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.sock
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
SlurmdTimeout=60
InactiveLimit=0
KillWait=5
MinJobAge=30
$node_line NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=main Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
chmod 0644 "$dir/slurm.conf"

deadline=$((SECONDS + timeout))
until [ -S "$dir/munge.sock" ]; do
  [ $SECONDS -lt $deadline ] || fail "munged did not open its socket within ${timeout} s"
  kill -0 "$(cat "$dir/munged.launcher.pid")" 2>/dev/null || fail "munged exited at start"
  sleep 0.2
done

export SLURM_CONF="$dir/slurm.conf"
$SUDO env SLURM_CONF="$SLURM_CONF" slurmctld -D -f "$SLURM_CONF" </dev/null >>"$dir/slurmctld.log" 2>&1 &
echo $! >"$dir/slurmctld.launcher.pid"
$SUDO env SLURM_CONF="$SLURM_CONF" slurmd -D -f "$SLURM_CONF" -N "$node" </dev/null >>"$dir/slurmd.log" 2>&1 &
echo $! >"$dir/slurmd.launcher.pid"

# Up when the node is idle in the partition.
state=""
while :; do
  for d in slurmctld slurmd; do
    kill -0 "$(cat "$dir/$d.launcher.pid")" 2>/dev/null || fail "$d exited at start"
  done
  state="$(sinfo -h -n "$node" -o '%T' 2>/dev/null | head -n 1 || true)"
  [ "$state" = idle ] && break
  [ $SECONDS -lt $deadline ] ||
    fail "node $node did not become idle within ${timeout} s (state: ${state:-no answer from slurmctld})"
  sleep 0.5
done
echo "SLURM_CONF=$SLURM_CONF"
cpus="$(sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' <<<"$node_line")"
echo "cluster up: node $node with $cpus CPUs and $mem MB; slurmctld on port $ctld_port, slurmd on port $slurmd_port"
