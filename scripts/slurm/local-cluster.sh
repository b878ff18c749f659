#!/usr/bin/env bash
# A single-node Slurm "cluster" on this machine (Debian's slurm-wlm and munge), so that the
# project's job-array sweep can be submitted with sbatch and run for real. Not for production
# clusters: no accounting, no cgroups, SlurmUser=root, one node, one partition ("local").
#
#   scripts/slurm/local-cluster.sh start    install if missing, configure, start, wait for idle
#   scripts/slurm/local-cluster.sh stop     stop slurmd, slurmctld and munged (config is kept)
#   scripts/slurm/local-cluster.sh status   sinfo and squeue
#
# Must run as root. The daemons are started directly (no systemd needed).
set -euo pipefail

CONF_DIR=/etc/slurm
CONF="$CONF_DIR/slurm.conf"
MARK="# written by scripts/slurm/local-cluster.sh"
STATE_DIR=/var/spool/slurmctld
SPOOL_DIR=/var/spool/slurmd
LOG_DIR=/var/log/slurm-local
RUN_DIR=/run/slurm-local
MUNGE_PID=/run/munge/munged.pid
START_TIMEOUT=${START_TIMEOUT:-60}
NODE=$(hostname -s)

say() { echo "local-cluster: $*"; }
die() { echo "local-cluster: error: $*" >&2; exit 1; }

pid_alive() { local pid; pid=$(cat "$1" 2>/dev/null) && [[ -n $pid ]] && kill -0 "$pid" 2>/dev/null; }

install_packages() {
  command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v munged >/dev/null && return
  say "installing slurm-wlm and munge (apt-get)"
  DEBIAN_FRONTEND=noninteractive apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y slurm-wlm munge
}

start_munge() {
  install -d -o munge -g munge -m 0700 /etc/munge /var/lib/munge /var/log/munge
  install -d -o munge -g munge -m 0755 /run/munge
  if [[ ! -s /etc/munge/munge.key ]]; then
    say "creating munge key /etc/munge/munge.key"
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
  fi
  chown munge:munge /etc/munge/munge.key && chmod 0400 /etc/munge/munge.key
  pid_alive "$MUNGE_PID" && return
  say "starting munged"
  runuser -u munge -- munged
  munge -n | unmunge >/dev/null || die "munge does not work; see /var/log/munge/munged.log"
}

check_config_ours() {
  if [[ -e $CONF ]] && ! grep -qxF "$MARK" "$CONF"; then
    die "$CONF exists and was not written by this script; refusing to replace it (move it away first)"
  fi
}

write_config() {
  local hw cpus mem
  # slurmd -C reports the hardware as Slurm sees it; fall back to nproc and /proc/meminfo.
  hw=$(slurmd -C 2>/dev/null | head -n1 || true)
  cpus=$(sed -n 's/.* CPUs=\([0-9]*\).*/\1/p' <<<"$hw")
  mem=$(sed -n 's/.* RealMemory=\([0-9]*\).*/\1/p' <<<"$hw")
  [[ -n $cpus ]] || cpus=$(nproc)
  [[ -n $mem ]] || mem=$(( $(awk '/^MemTotal:/ {print $2}' /proc/meminfo) / 1024 ))
  install -d -m 0755 "$CONF_DIR" "$STATE_DIR" "$SPOOL_DIR" "$LOG_DIR" "$RUN_DIR"
  # CPUs only (no socket/core/thread layout) with CR_CPU: every CPU is one schedulable unit,
  # so array tasks with --cpus-per-task=1 share the node one CPU each.
  cat >"$CONF" <<EOF
$MARK
# Single-node Slurm for running the project's sweep locally; not a production config.
ClusterName=local
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
MpiDefault=none
MailProg=/bin/true
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
# A job whose dependency can never be satisfied (afterok on a failed job) is cancelled.
DependencyParameters=kill_invalid_depend
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/filetxt
JobCompLoc=$LOG_DIR/jobcomp.log
StateSaveLocation=$STATE_DIR
SlurmdSpoolDir=$SPOOL_DIR
SlurmctldPidFile=$RUN_DIR/slurmctld.pid
SlurmdPidFile=$RUN_DIR/slurmd.pid
SlurmctldLogFile=$LOG_DIR/slurmctld.log
SlurmdLogFile=$LOG_DIR/slurmd.log
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
  say "wrote $CONF (node $NODE: CPUs=$cpus RealMemory=${mem}M)"
}

node_state() { sinfo -h -N -n "$NODE" -o '%t' 2>/dev/null | head -n1 || true; }
slurmd_since() { scontrol show node "$NODE" 2>/dev/null | sed -n 's/.*SlurmdStartTime=\([^ ]*\).*/\1/p'; }

# Waits until the node is usable; $1: earliest acceptable SlurmdStartTime (so that a state
# recovered from an earlier run does not pass for a registered slurmd).
wait_idle() {
  local since=$1 waited=0 state
  while (( waited < START_TIMEOUT )); do
    state=$(node_state)
    case $state in
      idle|mix|alloc) local t; t=$(slurmd_since)
        pid_alive "$RUN_DIR/slurmd.pid" && [[ $t == [0-9]* && ! $t < $since ]] && return 0 ;;
      down*|drain*|drng*) scontrol update NodeName="$NODE" State=RESUME 2>/dev/null || true ;;
    esac
    sleep 1; waited=$((waited + 1))
  done
  echo "local-cluster: error: node $NODE not idle after ${START_TIMEOUT}s (state: '${state:-no answer}')" >&2
  for f in "$LOG_DIR/slurmctld.log" "$LOG_DIR/slurmd.log" /var/log/munge/munged.log; do
    if [[ -e $f ]]; then echo "--- tail $f" >&2; tail -n 20 "$f" >&2; fi
  done
  exit 1
}

running() { pid_alive "$MUNGE_PID" && pid_alive "$RUN_DIR/slurmctld.pid" && pid_alive "$RUN_DIR/slurmd.pid"; }

cmd_start() {
  [[ $(id -u) -eq 0 ]] || die "must run as root"
  if running && [[ -n $(node_state) ]]; then
    say "already running"; sinfo; return 0
  fi
  check_config_ours; install_packages; start_munge; write_config
  local t0=$SECONDS since
  since=$(date +%Y-%m-%dT%H:%M:%S)
  pid_alive "$RUN_DIR/slurmctld.pid" || { say "starting slurmctld"; slurmctld; }
  if pid_alive "$RUN_DIR/slurmd.pid"; then since=""; else say "starting slurmd"; slurmd; fi
  wait_idle "$since"
  say "up after $((SECONDS - t0))s (partition 'local' is the default)"; sinfo
}

stop_pidfile() {
  local name=$1 pidfile=$2
  if pid_alive "$pidfile"; then
    say "stopping $name"
    kill "$(cat "$pidfile")" 2>/dev/null || true
    for _ in $(seq 50); do pid_alive "$pidfile" || break; sleep 0.2; done
    if pid_alive "$pidfile"; then kill -9 "$(cat "$pidfile")" 2>/dev/null || true; fi
  else # no pid file: live (not zombie) processes of that exact name
    local pids; mapfile -t pids < <(ps -C "$name" -o pid=,stat= | awk '$2 !~ /^Z/ {print $1}')
    if ((${#pids[@]})); then say "stopping $name (no pid file)"; kill "${pids[@]}" 2>/dev/null || true; fi
  fi
  rm -f "$pidfile"
}

cmd_stop() {
  [[ $(id -u) -eq 0 ]] || die "must run as root"
  stop_pidfile slurmd "$RUN_DIR/slurmd.pid"
  stop_pidfile slurmctld "$RUN_DIR/slurmctld.pid"
  stop_pidfile munged "$MUNGE_PID"
  say "stopped (config left in $CONF)"
}

cmd_status() {
  pid_alive "$RUN_DIR/slurmctld.pid" || { say "slurmctld is not running"; return 0; }
  sinfo; squeue
}

case ${1:-} in
  start) cmd_start ;;
  stop) cmd_stop ;;
  status) cmd_status ;;
  *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
