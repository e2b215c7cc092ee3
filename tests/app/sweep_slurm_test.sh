#!/usr/bin/env bash
# A planned sweep run by a real Slurm: starts munge, slurmctld and slurmd on this machine as a
# one-node cluster (private configuration and state in a temporary directory, ports 16817/16818),
# submits DIR/sweep.sbatch and the dependent collect job as the docs say, and checks that the
# collected deterministic columns and untimed report equal the one-process sweep's.
#   bash tests/app/sweep_slurm_test.sh path/to/cdlab
# Needs root and Debian 12's slurm-wlm (munge comes with it); .ci/bootstrap check-all runs it.
# Stops only the daemons it started.
set -euo pipefail

cdlab="$(realpath "${1:?usage: sweep_slurm_test.sh CDLAB_BINARY}")"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
[ "$(id -u)" -eq 0 ] || { echo "sweep_slurm_test: needs root (slurmd, munged)" >&2; exit 2; }
for tool in munged slurmctld slurmd sbatch sinfo; do
  command -v "$tool" > /dev/null || { echo "sweep_slurm_test: $tool missing (apt-get install slurm-wlm)" >&2; exit 2; }
done

work="$(mktemp -d /tmp/cdlab_slurm_XXXXXX)"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2> /dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

# munge: a running munged is used as it is; otherwise one is started for the test.
if ! munge -n 2> /dev/null | unmunge > /dev/null 2>&1; then
  mkdir -p /run/munge && chown munge:munge /run/munge
  [ -s /etc/munge/munge.key ] || { echo "sweep_slurm_test: no /etc/munge/munge.key" >&2; exit 2; }
  # setpriv execs munged as the munge user: the pid recorded is munged's own.
  setpriv --reuid=munge --regid=munge --init-groups /usr/sbin/munged -F > "$work/munged.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 50); do munge -n 2> /dev/null | unmunge > /dev/null 2>&1 && break; sleep 0.1; done
fi

node="$(hostname -s)"
mkdir -p "$work/ctld" "$work/d"
export SLURM_CONF="$work/slurm.conf"
cat > "$SLURM_CONF" << EOF
ClusterName=cdlabtest
SlurmctldHost=$node
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/ctld
SlurmdSpoolDir=$work/d
SlurmctldPidFile=$work/ctld.pid
SlurmdPidFile=$work/d.pid
SlurmctldLogFile=$work/ctld.log
SlurmdLogFile=$work/d.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
AuthType=auth/munge
NodeName=$node CPUs=$(nproc) State=UNKNOWN
PartitionName=cdlab Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -i > "$work/ctld.out" 2>&1 &
pids+=($!)
slurmd -D > "$work/d.out" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
  sinfo -h -o %t 2> /dev/null | grep -q idle && break
  sleep 0.2
done
sinfo -h -o %t | grep -q idle || { echo "sweep_slurm_test: the node never became idle" >&2; cat "$work"/*.out >&2; exit 1; }

scene="$root/tests/data/tunnel_small.yaml"
vary=(--vary broadphase=sap,hgrid --vary world.time_step=0.05,0.005 --repeat 2)
"$cdlab" sweep "$scene" "${vary[@]}" --no-report-timing --out "$work/one" > /dev/null
"$cdlab" sweep "$scene" "${vary[@]}" --plan "$work/plan" --slurm > /dev/null
jobid="$(sbatch --parsable "$work/plan/sweep.sbatch")"
# The collect step as docs/distributed-sweeps.md submits it; --wait returns when it has ended.
sbatch --wait --dependency="afterany:$jobid" --output="$work/collect.log" \
  --wrap "$cdlab sweep --collect $work/plan --no-report-timing" > /dev/null \
  || { echo "sweep_slurm_test: the collect job failed" >&2; cat "$work/collect.log" "$work"/plan/logs/* >&2; exit 1; }

# results.csv without its timed and per-machine columns.
deterministic() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) keep[i] = $i !~ /^(ms_|cpu_ms_)|^(memory_mib|host|concurrent)$/ }
           { line = ""; for (i = 1; i <= NF; i++) if (keep[i]) line = line $i "|"; print line }' "$1"
}
[ "$(ls "$work/plan/results" | wc -l)" -eq 5 ] || { echo "sweep_slurm_test: expected 5 results" >&2; exit 1; }
diff <(deterministic "$work/one/results.csv") <(deterministic "$work/plan/results.csv")
diff "$work/one/report.md" "$work/plan/report.md"
echo "sweep_slurm_test: 5 jobs ran as Slurm array $jobid; collected columns equal the one-process sweep's"
