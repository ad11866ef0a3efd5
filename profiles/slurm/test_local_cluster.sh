#!/usr/bin/env bash
# profiles/slurm against a real Slurm: a single-node cluster on this machine (Debian 12's slurm-wlm 22.05 and
# munge; slurmctld and slurmd on localhost, no accounting database) runs the smoke matrix
# (config/smoke.yaml: every rule and figure type) through `snakemake --profile profiles/slurm` to its 15 figures,
# in a fresh clone of this repository (its committed HEAD) with its own virtual environment
# (pip install -e ".[slurm]"). Needs root (apt-get, the daemons) and the network for apt-get and pip.
#
#   profiles/slurm/test_local_cluster.sh [WORKDIR]     # default WORKDIR: a new /tmp/plough-slurm.XXXXXX
#
# What a bare single-node Slurm needs beyond the profile (docs/workflow.md, "On a cluster"):
# * no slurmdbd: AccountingStorageType=accounting_storage/none, so sacct answers "accounting storage is
#   disabled"; the executor plugin is told to ask squeue for the jobs' states (--slurm-status-command squeue),
#   which needs finished jobs kept in slurmctld for longer than its checks (MinJobAge=600 s here, the plugin
#   wants at least 120 s), and to submit without an account (--slurm-no-account: with no accounting there is
#   no account to guess);
# * the node declared with 16 CPUs (SlurmdParameters=config_overrides) on a machine with fewer cores, so that
#   the profile's 8 threads a run are allocated (inside the job Snakemake then runs the rule on the cores the
#   machine has);
# * no cgroups in a container: proctrack/linuxproc and task/none;
# * the configuration at /etc/slurm/slurm.conf, Slurm's default path: the executor's job step drops SLURM_CONF
#   (every SLURM_ variable but the job's identity) from the environment of the srun it calls inside the job.
#   The file is written only where none is or where this script wrote it (its first line says so).
# The daemons' state and logs live under WORKDIR/slurm, started afresh each time; the daemons this script
# starts are stopped at its end, by their process ids.
set -euo pipefail

if [[ $(id -u) -ne 0 ]]; then
    echo "test_local_cluster.sh: needs root (apt-get, slurmctld, slurmd, munged)" >&2
    exit 2
fi
REPO=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
WORK=${1:-$(mktemp -d /tmp/plough-slurm.XXXXXX)}
WORK=$(realpath "$WORK")
STATE=$WORK/slurm
HOST=$(hostname -s)
started=()
log() { echo "[$(date +%H:%M:%S)] $*"; }

cleanup() {
    # the test cluster's own jobs first (slurmd waits for their steps), then the daemons this script started
    if [[ " ${started[*]} " == *slurmctld.pid* ]]; then
        scancel --quiet --user root 2>/dev/null || true
        sleep 2
    fi
    for pidfile in "${started[@]}"; do
        [[ -s $pidfile ]] || continue
        pid=$(cat "$pidfile")
        kill "$pid" 2>/dev/null || continue
        for _ in $(seq 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.5; done
        kill -9 "$pid" 2>/dev/null || true
    done
}
trap cleanup EXIT
trap 'exit 143' TERM
trap 'exit 130' INT

log "installing slurm-wlm and munge (apt-get)"
apt-get update -qq
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null

log "munge: key and daemon"
if [[ ! -s /etc/munge/munge.key ]]; then
    mungekey --create --keyfile=/etc/munge/munge.key
    chown munge:munge /etc/munge/munge.key
    chmod 400 /etc/munge/munge.key
fi
install -d -o munge -g munge -m 0755 /run/munge
if ! munge -n >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged
    started+=(/run/munge/munged.pid)
    sleep 1
fi
munge -n | unmunge >/dev/null

CONF=/etc/slurm/slurm.conf
MARK="# written by plough's profiles/slurm/test_local_cluster.sh"
log "slurm: a single node, $HOST, configuration in $CONF, state and logs in $STATE"
if [[ -e $CONF ]] && [[ $(head -n 1 "$CONF") != "$MARK" ]]; then
    echo "test_local_cluster.sh: $CONF exists and is not this script's: not overwriting a real cluster's" >&2
    exit 2
fi
rm -rf "$STATE"
mkdir -p "$STATE/slurmctld" "$STATE/slurmd" /etc/slurm
cat >"$CONF" <<EOF
$MARK
ClusterName=plough-local
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$STATE/slurmctld
SlurmdSpoolDir=$STATE/slurmd
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MinJobAge=600
SlurmdParameters=config_overrides
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=16 RealMemory=16000 State=UNKNOWN
PartitionName=local Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
/usr/sbin/slurmctld
started+=("$STATE/slurmctld.pid")
/usr/sbin/slurmd -N "$HOST"
started+=("$STATE/slurmd.pid")
for _ in $(seq 60); do
    [[ $(sinfo -h -N -o %T 2>/dev/null) == idle ]] && break
    sleep 1
done
sinfo -N -o "%N %T %c %m"
[[ $(sinfo -h -N -o %T) == idle ]] || { echo "the node did not come up: see $STATE/slurm*.log" >&2; exit 1; }

log "a fresh clone of $REPO (HEAD $(git -C "$REPO" rev-parse --short HEAD)) and its environment in $WORK"
rm -rf "$WORK/plough"
git clone -q "$REPO" "$WORK/plough"
[[ -x $WORK/venv/bin/python ]] || python3 -m venv "$WORK/venv"
"$WORK/venv/bin/pip" install -q -e "$WORK/plough[slurm]"

log "the smoke matrix through profiles/slurm"
cd "$WORK/plough"
start=$(date +%s)
set +e
"$WORK/venv/bin/python" -m snakemake --profile profiles/slurm --configfile=config/smoke.yaml \
    --slurm-status-command squeue --slurm-no-account 2>&1 | tee "$WORK/snakemake.log"
status=${PIPESTATUS[0]}
set -e
elapsed=$(($(date +%s) - start))

figures=$(find results/figures -name 'fig*.png' | wc -l)
jobs=$(grep -c "Job .* has been submitted with SLURM jobid" "$WORK/snakemake.log" || true)
log "snakemake exited $status after ${elapsed} s; $jobs Slurm jobs submitted; $figures of 15 figures drawn"
log "Slurm's record of the jobs (squeue keeps finished ones for MinJobAge):"
squeue --states=all -h -o "%i %j %T %C %m %l %M" | sort -n | awk '{print "  " $0}' | tail -n 20
[[ $status -eq 0 && $figures -eq 15 ]]
