#!/usr/bin/env bash
# CI test of the Slurm recipe (docs/SHARDING.md), for real: installs Debian's slurm-wlm and munge,
# starts a single-node cluster on this machine (munged, slurmctld, slurmd; no cgroups), submits
# tools/slurm/shards.sbatch as a 4-task job array with `sbatch --wait`, merges the shards with
# `cryoslosh merge` and checks the merged files byte-identical to the one-machine run.
# Runs as root. Usage: tools/slurm/ci_slurm.sh PATH_TO_CRYOSLOSH_BINARY
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN=$(readlink -f "$1")
WORK=$(mktemp -d /tmp/cryoslosh-slurm.XXXXXX)
fail() {
    echo "slurm test: $*" >&2
    for f in /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log "$WORK"/logs/*; do
        [ -f "$f" ] && { echo "--- $f" >&2; tail -n 30 "$f" >&2; }
    done
    exit 1
}

DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge procps >/dev/null \
    || fail "cannot install slurm-wlm, munge and procps (pgrep) with apt-get"

# munge: a key, its directories, the daemon as the munge user.
install -d -o munge -g munge -m 0700 /etc/munge /var/lib/munge /var/log/munge
install -d -o munge -g munge -m 0755 /run/munge
[ -s /etc/munge/munge.key ] || dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
chown munge:munge /etc/munge/munge.key && chmod 0400 /etc/munge/munge.key
# What this script starts it stops on exit, so CI leaves no daemon behind.
STARTED=()
stop_started() {
    for d in "${STARTED[@]}"; do
        case "$d" in
            slurm) scontrol shutdown >/dev/null 2>&1 || true ;;
            munged) [ -f /run/munge/munged.pid ] && kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true ;;
        esac
    done
}
trap stop_started EXIT
if ! pgrep -x munged >/dev/null; then
    runuser -u munge -- /usr/sbin/munged || fail "munged does not start"
    STARTED+=(munged)
fi
munge -n | unmunge >/dev/null || fail "munge cannot encode and decode a credential"

# slurm.conf for this host alone: no cgroups (proctrack/linuxproc, task/none), no accounting.
HOST=$(hostname -s)
CPUS=$(nproc)
install -d /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
cat > /etc/slurm/slurm.conf <<CONF
ClusterName=ci
SlurmctldHost=${HOST}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=${HOST} NodeAddr=127.0.0.1 CPUs=${CPUS} State=UNKNOWN
PartitionName=ci Nodes=${HOST} Default=YES MaxTime=INFINITE State=UP
CONF
# slurmd reads cgroup.conf when present; none of its plugins are used here.
rm -f /etc/slurm/cgroup.conf

if ! pgrep -x slurmctld >/dev/null; then
    slurmctld -i || fail "slurmctld does not start"
    STARTED=(slurm "${STARTED[@]}")
fi
pgrep -x slurmd >/dev/null || slurmd -N "$HOST" || fail "slurmd does not start"
for _ in $(seq 60); do
    state=$(sinfo -h -N -n "$HOST" -o %T 2>/dev/null || true)
    case "$state" in idle*|mix*|alloc*) break ;; esac
    sleep 1
done
case "$state" in
    idle*|mix*|alloc*) ;;
    *) fail "the node does not come up (sinfo state: '${state:-none}')" ;;
esac
echo "slurm test: single-node cluster up: $(sinfo -h -o '%P %D %T %C')"

# The recipe, as documented, on 4 array tasks; then the merge and the one-machine run.
mkdir -p "$WORK/bin" "$WORK/logs" "$WORK/campaigns"
ln -s "$BIN" "$WORK/bin/cryoslosh"
cp campaigns/mhtb_selfpress.toml "$WORK/campaigns/"
cd "$WORK"
export PATH="$WORK/bin:$PATH"
sbatch --wait --array=0-3 --cpus-per-task=1 --time=00:20:00 \
    --export=ALL,CAMPAIGN=campaigns/mhtb_selfpress.toml,INSTANCES=200,SEED=42,RESULTS=results \
    "$OLDPWD/tools/slurm/shards.sbatch" || fail "the job array failed"
cryoslosh merge results/shard-* --out results/merged
cryoslosh run campaigns/mhtb_selfpress.toml --instances 200 --seed 42 --backend cpu --out results/one
for f in instances.parquet statistics.parquet; do
    cmp "results/merged/$f" "results/one/$f" || fail "merged $f differs from the one-machine run"
done
echo "slurm test: 4-task job array merged byte-identical to the one-machine run (instances.parquet, statistics.parquet)"
# Kept on failure (fail() exits before here) for the logs; removed once the test has passed.
cd / && rm -rf "$WORK"
