#!/usr/bin/env bash
# CI test of cluster runs on a real one-node Slurm (Debian packages, no systemd; after
# ../shared/reference/slurm-single-node.sh): a 4-task job array of `generate` shards, merged, must
# equal a one-process run of the same indices (every column but the wall time). Needs root.
set -euo pipefail
cd "$(dirname "$0")/.."
HPGE_CV=${HPGE_CV:-$PWD/target/debug/hpge-cv}
D=${SLURM_CI_DIR:-$(mktemp -d)}
H=$(hostname -s)

export DEBIAN_FRONTEND=noninteractive
apt-get install -y -qq --no-install-recommends slurmctld slurmd slurm-client munge > /dev/null
[ -s /etc/munge/munge.key ] || runuser -u munge -- mungekey -c
install -d -o munge -g munge -m 0755 /run/munge
if ! munge -n 2> /dev/null | unmunge > /dev/null 2>&1; then
  runuser -u munge -- /usr/sbin/munged
fi
munge -n | unmunge > /dev/null

mkdir -p "$D/state" "$D/spool" "$D/log"
cat > /etc/slurm/slurm.conf <<CONF
ClusterName=ci
SlurmctldHost=${H}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
MailProg=/bin/true
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/log/slurmctld.log
SlurmdLogFile=$D/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=${H} NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=${H} Default=YES MaxTime=INFINITE State=UP
CONF
stop() {
  for p in "$D/slurmd.pid" "$D/slurmctld.pid" /run/munge/munged.pid; do
    [ -s "$p" ] || continue
    pid=$(cat "$p")
    kill -TERM "$pid" 2> /dev/null || true
    while kill -0 "$pid" 2> /dev/null; do sleep 0.2; done
  done
  # A folder this script made goes with it (one given in SLURM_CI_DIR stays for inspection).
  [ -n "${SLURM_CI_DIR:-}" ] || rm -rf "$D"
}
trap stop EXIT
/usr/sbin/slurmctld
/usr/sbin/slurmd
for _ in $(seq 60); do
  [ "$(sinfo -h -n "$H" -o %t 2> /dev/null)" = idle ] && break
  sleep 1
done
sinfo

N=12
sbatch --wait --array=0-3 --cpus-per-task=1 -o "$D/log/gen_%a.out" \
  --export=ALL,HPGE_CV="$HPGE_CV",N=$N,OUT="$D/gen" cluster/slurm/generate.sbatch
"$HPGE_CV" merge --out "$D/merged.csv" "$D"/gen/shard-*
"$HPGE_CV" generate --space spaces/super-siegfried-rz.toml --detector detectors/super-siegfried-k1.toml \
  --n $N --out "$D/single" --threads 2
strip() { tail -n +2 "$1" | sed 's/,[^,]*$//' | sort -t, -k1,1n; }
if ! diff <(strip "$D/merged.csv") <(strip "$D/single/rows.csv") > /dev/null; then
  echo "slurm test: the merged shards differ from the one-process run" >&2
  exit 1
fi
echo "slurm test: 4 array tasks, $N rows, merged set equals the one-process run"
