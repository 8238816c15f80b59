#!/usr/bin/env bash
# A throw-away single-node SLURM cluster on loopback, for tests/test_slurm.py (and by hand).
#
#   tests/slurm/cluster.sh start DIR [--accounting-disabled]   # munged, slurmctld, slurmd under DIR
#   export SLURM_CONF=DIR/slurm.conf                           # then sbatch, squeue, snakemake use it
#   tests/slurm/cluster.sh stop DIR                            # stops exactly the daemons it started
#
# Needs root (slurmd starts jobs as their user) and Debian's packages: `apt-get install slurmctld slurmd
# slurm-client munge` (tests/slurm/packages.txt). Exit status 3 with one line on stderr: cannot run here
# (the test skips with that reason); any other failure is an error. Everything lives in DIR: munge key and
# socket, state, spool, logs, ports chosen free at start. No accounting database (accounting_storage/none,
# as on clusters without slurmdbd): `sacct` answers from slurmctld for finished jobs within MinJobAge only.
# The node has one GPU of type `testgpu`, a generic resource without a device file (gres.conf with `Count=`
# and no `File=`): a job that asks for it (`--gpus=1`, `--gpus=testgpu:1`) is scheduled and its request
# recorded (`scontrol show job`: TresPerJob), though no process can use it. Partitions `test` (the default),
# `stickslip` and `gpu`, each of the one node.
#
# The one thing outside DIR is the link /run/slurm/conf -> DIR, removed at stop. Inside each job the jobstep
# executor plugin (snakemake-executor-plugin-slurm-jobstep 0.6.1) runs `srun` with every SLURM_* variable
# but the job's identity removed, SLURM_CONF included; srun then reads /etc/slurm/slurm.conf or else
# /run/slurm/conf/slurm.conf, where a configless slurmd offers the controller's configuration to the
# node's client commands. The link puts DIR/slurm.conf there. (A configless slurmd itself cannot run
# here: it fetches the configuration before it reads AuthInfo, so it needs munge on the machine's default
# socket.) Hence: not where /etc/slurm/slurm.conf exists, and one such cluster per machine at a time.
set -euo pipefail

cannot() { echo "cannot run a SLURM cluster here: $*" >&2; exit 3; }

command=${1:-}
dir=${2:-}
[[ -n "$command" && -n "$dir" ]] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }

# a process that exists and is not a zombie (a daemon's exit is reaped by init, maybe late)
alive() { [[ -r /proc/$1/stat ]] && [[ "$(cut -d ' ' -f 3 "/proc/$1/stat" 2>/dev/null)" != Z ]]; }

#: where client commands on a configless node find the configuration (see above)
node_conf=/run/slurm/conf

stop() {
    local pidfile pids=()
    # jobs first (slurmstepd would outlive slurmd), then the daemons
    if [[ -s "$dir/run/slurmctld.pid" ]]; then
        SLURM_CONF="$dir/slurm.conf" timeout 20 scancel --user "$(id -un)" 2>/dev/null || true
    fi
    for pidfile in "$dir/run/slurmd.pid" "$dir/run/slurmctld.pid" "$dir/run/munged.pid"; do
        if [[ -s "$pidfile" ]]; then pids+=("$(cat "$pidfile")"); fi
    done
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    # wait for each to exit (slurmctld saves its state first)
    for pid in "${pids[@]}"; do
        for _ in $(seq 50); do alive "$pid" || break; sleep 0.1; done
    done
    if [[ -L "$node_conf" && "$(readlink "$node_conf")" == "$dir" ]]; then rm -f "$node_conf"; fi
}

if [[ "$command" == stop ]]; then
    if [[ -d "$dir" ]]; then dir=$(cd "$dir" && pwd); fi
    stop
    exit 0
fi
[[ "$command" == start ]] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }

[[ $(id -u) -eq 0 ]] || cannot "not root (slurmd must run as root to start jobs)"
for program in munged slurmctld slurmd sbatch squeue sinfo scontrol; do
    command -v "$program" >/dev/null || cannot "$program not found (apt-get install slurmctld slurmd slurm-client munge)"
done

[[ ! -e /etc/slurm/slurm.conf ]] || cannot "this machine has its own SLURM configuration (/etc/slurm/slurm.conf), which srun in the jobs would read instead of the test cluster's"
if [[ -L "$node_conf" ]]; then
    other=$(readlink "$node_conf")
    if [[ -s "$other/run/slurmctld.pid" ]] && alive "$(cat "$other/run/slurmctld.pid")"; then
        cannot "another test cluster is running ($node_conf -> $other; stop it with: $0 stop $other)"
    fi
    rm -f "$node_conf"  # left by a cluster that was not stopped
elif [[ -e "$node_conf" ]]; then
    cannot "$node_conf exists (a configless slurmd runs on this machine)"
fi

free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }

mkdir -p "$dir"/{run,state,spool,log}
dir=$(cd "$dir" && pwd)
chmod 0700 "$dir/run"
trap 'stop' ERR

# munge: a private key and socket, so nothing of the machine's own munge is used or changed
dd if=/dev/urandom of="$dir/run/munge.key" bs=1024 count=1 status=none
chmod 0400 "$dir/run/munge.key"
munged --force --key-file="$dir/run/munge.key" --socket="$dir/run/munge.socket" \
    --pid-file="$dir/run/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/run/munged.seed"

host=$(hostname -s)
cpus=$(nproc)
# Memory is not a consumable resource here (CR_CPU, no cgroups): the node states at least 16 GB so that
# the SLURM profile's requests (up to 8 GB per job) fit on small CI machines too.
memory=$(awk '/MemTotal/ {m = int($2 / 1024); print (m > 16000 ? m : 16000)}' /proc/meminfo)
cat > "$dir/slurm.conf" <<EOF
ClusterName=stickslip-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/run/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
ReturnToService=2
# finished jobs stay visible to squeue (and sacct, served by slurmctld) for 10 minutes
MinJobAge=600
SlurmctldTimeout=30
SlurmdTimeout=30
MpiDefault=none
GresTypes=gpu
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory Gres=gpu:testgpu:1 State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
PartitionName=stickslip Nodes=$host Default=NO MaxTime=INFINITE State=UP
PartitionName=gpu Nodes=$host Default=NO MaxTime=INFINITE State=UP
EOF
# slurmd reads gres.conf beside slurm.conf; AutoDetect off: nothing probes for real devices
cat > "$dir/gres.conf" <<EOF
AutoDetect=off
NodeName=$host Name=gpu Type=testgpu File=/dev/null
EOF

mkdir -p "$(dirname "$node_conf")"
ln -s "$dir" "$node_conf"
export SLURM_CONF="$dir/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 120); do
    if [[ "$(sinfo -h -N -o %t 2>/dev/null | sort -u)" == idle ]]; then
        echo "SLURM cluster up: SLURM_CONF=$SLURM_CONF ($cpus CPUs, $memory MB on node $host)"
        exit 0
    fi
    sleep 0.5
done
echo "SLURM cluster did not come up within 60 s; logs in $dir/log:" >&2
tail -n 20 "$dir"/log/*.log >&2 || true
stop
exit 1
