#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, in a folder of its own: to try the Snakemake profile
# (pipelines/slurm/) before a real cluster, and for the Slurm test (tests/e2e/slurm_test.cc).
#
#   pipelines/slurm/local-cluster.sh start <dir>    # then: export SLURM_CONF=<dir>/slurm.conf
#   pipelines/slurm/local-cluster.sh status <dir>
#   pipelines/slurm/local-cluster.sh stop <dir>
#
# Needs root and Debian's slurm-wlm (slurmctld, slurmd, slurm-client) and munge packages. start
# writes into <dir> (created; it must be new or a stopped cluster's): its own munge key and
# munged socket, slurm.conf for this machine (the node as `slurmd -C` sees it: its hostname, CPUs
# and memory; cons_tres with CR_Core_Memory, so that a job's CPUs and memory are allocated, and
# OverMemoryKill, so that a job using more memory than it asked for is killed; process tracking
# and task plugins that need neither systemd nor cgroups; jobs' completion records in
# <dir>/log/jobcomp.txt, read by `sacct -c`), the state, spool, log and pid files, on two free
# unprivileged ports. It starts munged, slurmctld and slurmd and waits (at most
# LUMISLAB_CLUSTER_TIMEOUT seconds, default 30) for the node to be idle (LUMISLAB_CLUSTER_CPUS=N
# announces N CPUs instead of the machine's, for jobs that mostly wait); on failure it stops
# what it started, prints the logs' last lines and exits 1. stop cancels the jobs, ends the
# daemons by their pid files and checks that no process started for the cluster is left (every
# one carries LUMISLAB_CLUSTER=<dir> in its environment): exit 1 if one is. status prints the
# node and the queue (exit 1 when the cluster is not running). Exit 3: not root, or a command
# of those packages missing.
set -euo pipefail
usage() {
  sed -n '2,/^set /{ /^#/ s/^# \{0,1\}//p; }' "$0" >&2
  exit 2
}
[ $# = 2 ] || usage
action="$1"
[ "$action" != start ] || mkdir -p "$2"
[ -d "$2" ] || { echo "local-cluster: no cluster in $2 (no such folder)" >&2; exit 1; }
dir="$(cd "$2" && pwd)"
timeout="${LUMISLAB_CLUSTER_TIMEOUT:-30}"
conf="$dir/slurm.conf"
export SLURM_CONF="$conf"

# Every daemon of the cluster is started with LUMISLAB_CLUSTER=<dir> in its environment (slurmd
# passes it on to slurmstepd): stop finds what the pid files miss. This script has none.
unset LUMISLAB_CLUSTER
marked() { env LUMISLAB_CLUSTER="$dir" "$@"; }

say() { echo "local-cluster: $*" >&2; }

# The pids of this cluster's processes (the marker in /proc/<pid>/environ).
cluster_pids() {
  grep -lzxF "LUMISLAB_CLUSTER=$dir" /proc/[0-9]*/environ 2>/dev/null |
    sed 's|^/proc/\([0-9]*\)/environ$|\1|' || true
}

# until <seconds> <what> <command...>: runs the command until it succeeds, at most that long.
until_ok() {
  local limit="$1" what="$2" end
  shift 2
  end=$((SECONDS + limit))
  until "$@" >/dev/null 2>&1; do
    if [ $SECONDS -ge $end ]; then
      say "$what: not after ${limit} s"
      return 1
    fi
    sleep 0.1
  done
}

# A TCP port nobody listens on, in the unprivileged range, not the one given.
free_port() {
  local p
  while :; do
    p=$((20000 + RANDOM % 20000))
    [ "$p" != "${1:-}" ] || continue
    ss -Htln "sport = :$p" | grep -q . || { echo "$p"; return; }
  done
}

# end <pidfile> <name>: SIGTERM, then SIGKILL after 10 s, by the pid in the file.
end_daemon() {
  local pid
  [ -s "$1" ] || return 0
  pid="$(cat "$1")"
  # Only a process of this cluster (a stale pid file may name another's by now).
  if grep -qzxF "LUMISLAB_CLUSTER=$dir" "/proc/$pid/environ" 2>/dev/null; then
    kill -TERM "$pid" 2>/dev/null || true
    until_ok 10 "$2 (pid $pid) to end" bash -c "! kill -0 $pid" ||
      kill -KILL "$pid" 2>/dev/null || true
  fi
  rm -f "$1"
}

stop() {
  if [ -f "$conf" ] && [ -s "$dir/run/slurmctld.pid" ]; then
    scancel --full --quiet --user="$(id -un)" >/dev/null 2>&1 || true
    # shellcheck disable=SC2016  # expanded by the inner shell, at each try
    until_ok 15 "the jobs to end" bash -c '[ -z "$(squeue -h -o %i 2>/dev/null)" ]' || true
  fi
  # Both at once: each may take seconds to save its state.
  end_daemon "$dir/run/slurmd.pid" slurmd &
  end_daemon "$dir/run/slurmctld.pid" slurmctld &
  wait
  end_daemon "$dir/munge/munged.pid" munged
  # What the pid files do not name: a job step's slurmstepd and the job's processes.
  local left p
  left="$(cluster_pids)"
  for p in $left; do kill -KILL "$p" 2>/dev/null || true; done
  [ -z "$left" ] || sleep 0.5
  left="$(cluster_pids)"
  if [ -n "$left" ]; then
    say "still running after stop: $(echo "$left" | paste -sd' ')"
    return 1
  fi
  say "stopped ($dir)"
}

status() {
  local pid=""
  [ ! -s "$dir/run/slurmctld.pid" ] || pid="$(cat "$dir/run/slurmctld.pid")"
  if [ -z "$pid" ] || ! kill -0 "$pid" 2>/dev/null; then
    say "not running ($dir)"
    return 1
  fi
  sinfo -N -o '%N %T %c %m' && squeue -o '%i %j %T %C %m %l %M'
}

start() {
  local cmd
  for cmd in munged munge slurmctld slurmd sbatch sinfo scontrol; do
    command -v "$cmd" >/dev/null 2>&1 || PATH="$PATH:/usr/sbin" command -v "$cmd" >/dev/null ||
      { say "$cmd not found: install Debian's slurm-wlm and munge (scripts/setup.sh)"; exit 3; }
  done
  PATH="$PATH:/usr/sbin"
  [ "$(id -u)" = 0 ] || { say "needs root (slurmd runs jobs as their users)"; exit 3; }
  if [ -n "$(cluster_pids)" ]; then
    say "a cluster is already running in $dir (stop it first)"
    exit 1
  fi
  rm -rf "$dir/munge" "$dir/state" "$dir/spool" "$dir/log" "$dir/run"
  mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log" "$dir/run"
  chmod 700 "$dir/munge"

  # munge: a key of its own and its own socket, so that it neither needs nor disturbs the
  # machine's munged.
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
  chmod 400 "$dir/munge/munge.key"
  local sock="$dir/munge/munge.sock"
  marked munged --socket="$sock" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
    --seed-file="$dir/munge/munged.seed" --force
  until_ok "$timeout" "munged to answer" bash -c "munge -s x -S '$sock' | unmunge -S '$sock'" ||
    { stop || true; exit 1; }

  # The node as slurmd sees this machine: NodeName (hostname), CPUs, sockets, cores, memory.
  local node name ctld_port slurmd_port
  node="$(slurmd -C | head -n 1)"
  local overrides=""
  if [ -n "${LUMISLAB_CLUSTER_CPUS:-}" ]; then
    # More CPUs than there are (jobs that mostly wait, as a test's tiny ones): slurmd accepts
    # a node larger than the machine with config_overrides.
    node="$(sed -E "s/ CPUs=[0-9]+/ CPUs=$LUMISLAB_CLUSTER_CPUS/;
      s/ (Boards|SocketsPerBoard|CoresPerSocket|ThreadsPerCore)=[0-9]+//g" <<<"$node")"
    overrides="SlurmdParameters=config_overrides"
  fi
  name="$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' <<<"$node")"
  [ -n "$name" ] || { say "slurmd -C: no NodeName in: $node"; stop || true; exit 1; }
  ctld_port="$(free_port)"
  slurmd_port="$(free_port "$ctld_port")"
  cat >"$conf" <<EOF
# A one-node cluster for trying the lumislab Slurm profile (pipelines/slurm/local-cluster.sh).
ClusterName=lumislab
SlurmctldHost=$name(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
# No systemd, no cgroups (a container): processes tracked by their parents, tasks not bound.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
# Jobs get cores and memory: a job's --cpus-per-task and --mem are allocated, and a job using
# more memory than it asked for is killed (the gatherer samples every second).
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
JobAcctGatherType=jobacct_gather/linux
JobAcctGatherFrequency=task=1
JobAcctGatherParams=OverMemoryKill
# No accounting database: completion records in a file, for sacct -c.
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/log/jobcomp.txt
ReturnToService=2
MinJobAge=600
KillWait=5
SchedulerType=sched/backfill
$overrides
$node
PartitionName=local Nodes=$name Default=YES MaxTime=INFINITE State=UP
EOF
  # The node's memory is what slurmd -C reported; UpTime is not a slurm.conf key.
  sed -i '/^NodeName=/ s/ UpTime=[^ ]*//' "$conf"

  marked slurmctld -f "$conf" -c -i
  until_ok "$timeout" "slurmctld to answer" scontrol ping ||
    { tail -n 20 "$dir/log/slurmctld.log" >&2 || true; stop || true; exit 1; }
  marked slurmd -f "$conf"
  until_ok "$timeout" "node $name to be idle" \
    bash -c "sinfo -h -N -n '$name' -o %T | grep -qx idle" || {
    tail -n 20 "$dir/log/slurmctld.log" "$dir/log/slurmd.log" >&2 || true
    stop || true
    exit 1
  }
  say "running in $dir: node $(sinfo -h -N -o '%N, %c CPUs, %m MB, %T'); export SLURM_CONF=$conf"
}

case "$action" in
  start) start ;;
  stop) stop ;;
  status) status ;;
  *) usage ;;
esac
