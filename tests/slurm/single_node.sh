#!/usr/bin/env bash
# A real single-node Slurm cluster for the sweeps (docs/sweeps.md): installs Debian's slurmctld,
# slurmd and munge if they are missing (as root, with apt-get), writes a minimal slurm.conf in a
# temporary folder, starts munged, slurmctld and slurmd, submits scripts/sweeps/tiny.toml as a
# 12-task job array, waits, collects, and compares the table with `--local -j 1` (identical
# bytes); then checks that `sbatch --test-only` accepts the script written for the 618-run
# scripts/sweeps/feng_bending.toml. Skips with a message (exit 0) where Slurm cannot be had.
# Usage: tests/slurm/single_node.sh [EMILION_BINARY]   (default target/release/emilion)
set -euo pipefail
cd "$(dirname "$0")/../.."
EXE=${1:-target/release/emilion}
skip() { echo "slurm test skipped: $*"; exit 0; }
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
   || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
      slurmctld slurmd slurm-client munge >/dev/null 2>&1 \
      || skip "apt-get could not install slurmctld, slurmd, slurm-client, munge"
  else
    skip "slurmctld, slurmd, munge are not installed (they need root and apt-get)"
  fi
fi
[ "$(id -u)" = 0 ] || skip "starting munged and slurmd needs root"
[ -x "$EXE" ] || skip "no emilion binary at $EXE (cargo build --release first)"
EXE=$(realpath "$EXE")
WORK=$(mktemp -d /tmp/emilion-slurm.XXXXXX)
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do
    [ -f "$p" ] && kill "$(cat "$p")" 2>/dev/null || true
  done
}
trap cleanup EXIT

# munge: the key the package made, our own daemon
[ -f /etc/munge/munge.key ] || { mkdir -p /etc/munge; dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 2>/dev/null; chmod 400 /etc/munge/munge.key; }
MUNGE_SOCKET=$WORK/munge.socket
mkdir -p "$WORK/munge"
munged --force --socket="$MUNGE_SOCKET" --pid-file="$WORK/munged.pid" --seed-file="$WORK/munge/seed" \
  --log-file="$WORK/munged.log" || skip "munged does not start (see $WORK/munged.log)"
PIDS+=("$WORK/munged.pid")

# slurm.conf for this node, as slurmd itself measures it
HOST=$(hostname -s)
NODE=$(slurmd -C | head -1)
mkdir -p "$WORK/state" "$WORK/spool"
cat > "$WORK/slurm.conf" <<CONF
ClusterName=emilion
SlurmctldHost=$HOST
AuthType=auth/munge
AuthInfo=socket=$MUNGE_SOCKET
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
ReturnToService=2
MpiDefault=none
$NODE State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$WORK/slurm.conf
slurmctld -f "$SLURM_CONF" || skip "slurmctld does not start (see $WORK/slurmctld.log)"
PIDS+=("$WORK/slurmctld.pid")
slurmd -f "$SLURM_CONF" || skip "slurmd does not start (see $WORK/slurmd.log)"
PIDS+=("$WORK/slurmd.pid")
for _ in $(seq 60); do
  sinfo -h -o %t 2>/dev/null | grep -q idle && break
  sleep 1
done
sinfo -h -o %t | grep -q idle || skip "the node never became idle: $(sinfo 2>&1 | tail -2)"
echo "slurm: $(sinfo --version), node $HOST up"

# the 12-run array
OUT=$WORK/cluster
"$EXE" sweep run scripts/sweeps/tiny.toml --slurm --out "$OUT" | tee "$WORK/submit.txt"
JOB=$(sed -n 's/.*job=\([0-9]*\).*/\1/p' "$WORK/submit.txt")
[ -n "$JOB" ] || { echo "FAIL: no job id"; exit 1; }
for _ in $(seq 300); do
  [ -z "$(squeue -h -j "$JOB" 2>/dev/null)" ] && break
  sleep 1
done
[ -z "$(squeue -h -j "$JOB")" ] || { echo "FAIL: job $JOB still queued after 300 s"; squeue; exit 1; }
"$EXE" sweep collect scripts/sweeps/tiny.toml --out "$OUT" | tail -1
"$EXE" sweep run scripts/sweeps/tiny.toml --local -j 1 --out "$WORK/local" | tail -1
"$EXE" sweep collect scripts/sweeps/tiny.toml --out "$WORK/local" | tail -1
if ! cmp "$OUT/tiny/results.csv" "$WORK/local/tiny/results.csv"; then
  diff "$OUT/tiny/results.csv" "$WORK/local/tiny/results.csv" | head -20
  echo "FAIL: the cluster's table differs from the local one"; exit 1
fi
DONE=$(grep -c ',done,' "$OUT/tiny/results.csv")
[ "$DONE" = 12 ] || { echo "FAIL: $DONE of 12 runs complete on the cluster"; exit 1; }
echo "slurm: 12-task array $JOB collected, identical to --local -j 1"

# the 618-run manifest's script, accepted by sbatch --test-only
"$EXE" sweep run scripts/sweeps/feng_bending.toml --slurm --dry-run --out "$WORK/feng" >/dev/null
SCRIPT=$WORK/feng/feng_bending/slurm/feng_bending.sbatch
grep -q -- '--array=0-617%64' "$SCRIPT" || { echo "FAIL: $SCRIPT has no 618-task array"; exit 1; }
sbatch --test-only "$SCRIPT" 2>&1 | tee "$WORK/test_only.txt"
grep -q "to start at" "$WORK/test_only.txt" || { echo "FAIL: sbatch --test-only refused $SCRIPT"; exit 1; }
echo "slurm: sbatch --test-only accepts the 618-task script"
cleanup
PIDS=()
sleep 2
rm -rf "$WORK" 2>/dev/null || true
