#!/usr/bin/env bash
# slurm-single-node.sh: a throw-away single-node Slurm cluster in one folder, for the farm test
# (hull_farm_test HullFarm.SlurmJobArray) and for trying studio-hull-farm.sh on a workstation.
# Everything lives under DIR: a fresh munge key and munged socket, slurm.conf (this host as the
# controller and the only node, every CPU, one default partition "studio"), state, spool, logs
# and pid files. No systemd, no cgroups (proctrack/linuxproc, task/none), no accounting. The
# daemons run as the calling user; slurmd must run as root to start jobs as the submitting user,
# so `start` needs root (Debian: apt-get install slurm-wlm munge).
#
#   slurm-single-node.sh start DIR [PORT]   write DIR/slurm.conf, start munged, slurmctld, slurmd;
#                                           wait until the node is idle (60 s at most); prints
#                                           SLURM_CONF=DIR/slurm.conf
#   slurm-single-node.sh stop DIR           stop the daemons started in DIR (by their pid files)
# Clients use the cluster with SLURM_CONF=DIR/slurm.conf in their environment. PORT (default
# 16817) and PORT+1 are the controller's and the node's ports.
# Exit status: 0 done; 1 a daemon did not start (its log's last lines on stderr); 2 bad arguments.
set -euo pipefail

usage() { sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; }
[ $# -ge 2 ] || { usage >&2; exit 2; }
cmd=$1 dir=$2 port=${3:-16817}
case "$cmd" in -h|--help) usage; exit 0 ;; esac
[[ "$port" =~ ^[0-9]+$ ]] && [ "$port" -ge 1024 ] && [ "$port" -le 65000 ] ||
  { echo "slurm-single-node: PORT must be 1024..65000" >&2; exit 2; }

stop() {
  local f pid
  for f in slurmd slurmctld munged; do
    [ -f "$dir/$f.pid" ] || continue
    pid=$(cat "$dir/$f.pid")
    if [ -n "$pid" ] && kill "$pid" 2>/dev/null; then
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    fi
    rm -f "$dir/$f.pid"
  done
}

if [ "$cmd" = stop ]; then stop; exit 0; fi
[ "$cmd" = start ] || { echo "slurm-single-node: unknown command $cmd (start|stop)" >&2; exit 2; }
for b in munged slurmctld slurmd sinfo; do
  command -v "$b" >/dev/null ||
    { echo "slurm-single-node: $b not found (apt-get install slurm-wlm munge)" >&2; exit 1; }
done
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
chmod 700 "$dir"
mkdir -p "$dir/state" "$dir/spool" "$dir/log"
host=$(hostname -s)
cpus=$(nproc)

# munge: a fresh key; the daemon runs as root only with --force.
head -c 1024 /dev/urandom >"$dir/munge.key"
chmod 400 "$dir/munge.key"
munged --force --socket="$dir/munge.sock" --key-file="$dir/munge.key" \
  --log-file="$dir/log/munged.log" --pid-file="$dir/munged.pid" --seed-file="$dir/munged.seed"

cat >"$dir/slurm.conf" <<EOF
ClusterName=studio-single-node
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$(id -un)
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.sock
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
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=studio Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$dir/slurm.conf

fail() {
  echo "slurm-single-node: $1" >&2
  for f in "$dir"/log/*.log; do tail -n 3 "$f" | sed "s|^|$(basename "$f"): |" >&2; done
  stop
  exit 1
}
slurmctld -i || fail "slurmctld did not start"
slurmd || fail "slurmd did not start"
for _ in $(seq 120); do
  state=$(sinfo -h -N -o %t 2>/dev/null || true)
  [ "$state" = idle ] && { echo "SLURM_CONF=$SLURM_CONF"; exit 0; }
  sleep 0.5
done
fail "the node is not idle after 60 s (sinfo: ${state:-no answer})"
