#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for tests of `tadslc eval --shard` job arrays.
#
#   cluster.sh start DIR   writes DIR/slurm.conf, starts munged, slurmctld and slurmd (all state,
#                          logs and sockets in DIR), waits until the node is idle and prints the
#                          environment to use: `eval "$(tests/slurm/cluster.sh start /tmp/c)"`
#   cluster.sh stop DIR    cancels the cluster's jobs and stops the daemons `start` started
#
# Debian 12's slurm-wlm 22.05 and munge (`apt-get install slurm-wlm munge`), run as root:
# SlurmUser=root, proctrack/linuxproc, task/none, no cgroup.conf. munged runs as `munge` on a
# socket of its own (AuthInfo=socket=...), so a system munged or Slurm is left alone; the
# ports are free ones from TAD_SLURM_PORT (default 16817). Every wait has a time limit; a
# start that fails prints the daemons' logs, stops what it started and exits 1.
set -euo pipefail

PATH="$PATH:/usr/sbin:/sbin"

say() { echo "cluster.sh: $*" >&2; }
die() {
  say "$*"
  exit 1
}
usage() { die "usage: cluster.sh start|stop DIR"; }

[ $# -eq 2 ] || usage
cmd=$1
dir=$2
case $dir in
  /*) ;;
  *) dir="$PWD/$dir" ;;
esac
[[ $dir =~ ^[A-Za-z0-9._/+-]+$ ]] || die "DIR must be a path of letters, digits and ._/+- only: $dir"
# munged's socket path must fit in a sockaddr_un (108 bytes)
[ ${#dir} -le 80 ] || die "DIR is too long for munged's socket (80 characters at most): $dir"
conf="$dir/slurm.conf"

# wait_for SECONDS WHAT COMMAND...: run COMMAND until it succeeds, at most SECONDS
wait_for() {
  local limit=$1 what=$2
  shift 2
  local deadline=$((SECONDS + limit))
  until "$@" >/dev/null 2>&1; do
    if [ "$SECONDS" -ge "$deadline" ]; then
      say "timed out after ${limit} s waiting for $what"
      return 1
    fi
    sleep 0.2
  done
}

# the pid in FILE if that process is alive and its command is NAME
live_pid() {
  local file=$1 name=$2 pid
  [ -s "$file" ] || return 1
  pid=$(tr -dc 0-9 <"$file")
  [ -n "$pid" ] && [ -r "/proc/$pid/comm" ] || return 1
  [ "$(cat "/proc/$pid/comm")" = "$name" ] || return 1
  echo "$pid"
}

stop_daemon() {
  local name=$1 file=$2 pid
  pid=$(live_pid "$file" "$name") || return 0
  kill -TERM "$pid" 2>/dev/null || true
  if ! wait_for 15 "$name ($pid) to exit" bash -c "! kill -0 $pid"; then
    say "killing $name ($pid)"
    kill -KILL "$pid" 2>/dev/null || true
  fi
  say "stopped $name ($pid)"
}

stop() {
  if live_pid "$dir/slurmctld.pid" slurmctld >/dev/null && live_pid "$dir/slurmd.pid" slurmd >/dev/null; then
    # jobs first: their processes belong to slurmstepd, which outlives slurmd otherwise
    local jobs
    jobs=$(SLURM_CONF=$conf timeout 10 squeue -h -o %A 2>/dev/null || true)
    if [ -n "$jobs" ]; then
      # shellcheck disable=SC2086
      SLURM_CONF=$conf timeout 10 scancel $jobs || true
      wait_for 30 "the jobs to end" bash -c "[ -z \"\$(SLURM_CONF=$conf squeue -h -o %A)\" ]" || true
    fi
  fi
  stop_daemon slurmd "$dir/slurmd.pid"
  stop_daemon slurmctld "$dir/slurmctld.pid"
  stop_daemon munged "$dir/munge/munged.pid"
}

show_logs() {
  local log
  for log in "$dir/munge/munged.log" "$dir/slurmctld.log" "$dir/slurmd.log"; do
    if [ -f "$log" ]; then
      say "--- last lines of $log"
      tail -n 25 "$log" >&2
    fi
  done
}

port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }

start() {
  [ "$(id -u)" = 0 ] || die "needs root (SlurmUser=root; slurmd runs jobs as their user)"
  local tool
  for tool in munged mungekey slurmctld slurmd sbatch sinfo squeue scancel scontrol runuser; do
    command -v "$tool" >/dev/null || die "$tool not found (apt-get install slurm-wlm munge)"
  done
  id munge >/dev/null 2>&1 || die "no user munge (apt-get install munge)"
  if live_pid "$dir/slurmctld.pid" slurmctld >/dev/null; then
    die "a cluster already runs in $dir: cluster.sh stop $dir"
  fi

  mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
  # a failed start stops what it started
  trap 'status=$?; if [ $status -ne 0 ]; then show_logs; stop; fi' EXIT

  # munge: the machine's key (made if there is none), a daemon of our own
  local key=/etc/munge/munge.key
  if [ ! -s $key ]; then
    say "creating $key"
    mkdir -p /etc/munge
    mungekey --create --keyfile=$key 2>/dev/null || dd if=/dev/urandom of=$key bs=1024 count=1 status=none
    chown munge:munge /etc/munge $key
    chmod 0700 /etc/munge
    chmod 0400 $key
  fi
  chown munge:munge "$dir/munge"
  chmod 0755 "$dir/munge" # the socket's directory: searchable by every user
  local socket="$dir/munge/munge.socket"
  runuser -u munge -- munged --socket="$socket" --key-file=$key --pid-file="$dir/munge/munged.pid" \
    --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed"
  wait_for 15 "munged" bash -c "munge -n -S '$socket' | unmunge -S '$socket'"

  local port=${TAD_SLURM_PORT:-16817} tries=0
  until port_free "$port" && port_free $((port + 1)); do
    port=$((port + 2))
    tries=$((tries + 1))
    [ $tries -lt 50 ] || die "no free port pair from ${TAD_SLURM_PORT:-16817}"
  done
  local host cpus mem
  host=$(hostname -s)
  cpus=$(nproc --all)
  # a little under the machine's memory: slurmd drains a node that has less than it says
  mem=$(awk '/^MemTotal:/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
  cat >"$conf" <<EOF
# written by tests/slurm/cluster.sh: one node, run as root, everything in $dir
ClusterName=tadsl
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
KillWait=5
InactiveLimit=0
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF="$conf"

  slurmctld -f "$conf"
  wait_for 30 "slurmctld" bash -c "scontrol ping | grep -q 'is UP'"
  slurmd -f "$conf"
  wait_for 30 "node $host to be idle" bash -c "[ \"\$(sinfo -h -N -n $host -o %t)\" = idle ]"
  say "node $host idle (slurmctld on port $port): $(sinfo -h -N -o '%N %t %c CPUs %m MB')"
  echo "export SLURM_CONF=$conf"
}

case $cmd in
  start) start ;;
  stop) stop ;;
  *) usage ;;
esac
