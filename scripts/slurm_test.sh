#!/usr/bin/env bash
# A real Slurm on this machine, for `onebeacon mc --slurm`: installs Debian's slurm-wlm
# and munge where they are missing, starts a single-node cluster on localhost (munged,
# slurmctld and slurmd as root, a minimal slurm.conf in a scratch directory), submits a
# 4-shard campaign of a short garin2024 through the script `mc --slurm 4` writes, waits
# for the array and the merge job, and compares the merged cells with an unsharded `mc`
# of the same scenario. It stops the daemons it started, whatever happens. Needs root.
#
#   scripts/slurm_test.sh [ONEBEACON]     (default: target/release/onebeacon)
set -euo pipefail
cd "$(dirname "$0")/.."
ONEBEACON=$(realpath "${1:-target/release/onebeacon}")
[ -x "$ONEBEACON" ] || { echo "slurm_test: $ONEBEACON is not an executable (cargo build --release first)" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "slurm_test: needs root (it starts slurmd and munged)" >&2; exit 2; }
log() { echo "[slurm_test $(date +%T)] $*"; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  log "installing slurm-wlm and munge"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi

RUN=$(mktemp -d /tmp/onebeacon-slurm.XXXXXX)
PIDS=()
stop() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${PIDS[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$p" 2>/dev/null || true
  done
  log "daemons stopped"
}
trap stop EXIT

# munge: its own key and socket in the scratch directory, so that a munged already
# running here is left alone
mkdir -p "$RUN/munge" "$RUN/state" "$RUN/spool"
chmod 700 "$RUN/munge"
dd if=/dev/urandom of="$RUN/munge/munge.key" bs=1 count=1024 status=none
chmod 400 "$RUN/munge/munge.key"
SOCKET=$RUN/munge/munge.socket
munged --force --key-file="$RUN/munge/munge.key" --socket="$SOCKET" \
  --pid-file="$RUN/munge/munged.pid" --log-file="$RUN/munge/munged.log" --seed-file="$RUN/munge/munged.seed"
for _ in $(seq 50); do [ -s "$RUN/munge/munged.pid" ] && break; sleep 0.1; done
PIDS+=("$(cat "$RUN/munge/munged.pid")")
log "munged up (pid ${PIDS[0]})"

CPUS=$(nproc)
cat > "$RUN/slurm.conf" <<EOF
ClusterName=onebeacon-test
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCKET
CredType=cred/munge
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$RUN/state
SlurmdSpoolDir=$RUN/spool
SlurmctldPidFile=$RUN/slurmctld.pid
SlurmdPidFile=$RUN/slurmd.pid
SlurmctldLogFile=$RUN/slurmctld.log
SlurmdLogFile=$RUN/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$CPUS State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$RUN/slurm.conf
slurmctld -i
for _ in $(seq 100); do [ -s "$RUN/slurmctld.pid" ] && break; sleep 0.1; done
PIDS+=("$(cat "$RUN/slurmctld.pid")")
slurmd -N localhost
for _ in $(seq 100); do [ -s "$RUN/slurmd.pid" ] && break; sleep 0.1; done
PIDS+=("$(cat "$RUN/slurmd.pid")")
for _ in $(seq 100); do
  sinfo -h -N -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
  sleep 0.2
done
sinfo -h -N -o '%T' | grep -qE '^(idle|mixed|allocated)' || {
  log "the node did not come up:"; sinfo -N || true; tail -n 20 "$RUN/slurmctld.log" "$RUN/slurmd.log" || true; exit 1
}
log "cluster up: $(sinfo -h -N -o '%N %T %c cpus')"

# a short garin2024: 2 cells x 6 runs of 300 s
SCENARIO=$RUN/garin-short.toml
"$ONEBEACON" scenarios --show garin2024 > "$SCENARIO"
sed -i -e 's/^# duration_s = .*/duration_s = 300.0/' -e 's/^t_com_s = \[.*/t_com_s = [3.0, 15.0]/' "$SCENARIO"
grep -q '^duration_s = 300.0' "$SCENARIO" && grep -q '^t_com_s = \[3.0, 15.0\]' "$SCENARIO" || {
  log "cannot shorten garin2024 (its keys moved?)"; exit 1
}

CAMPAIGN=$RUN/campaign
"$ONEBEACON" mc "$SCENARIO" --runs 6 --seed 7 --slurm 4 --partition debug --time 00:10:00 --out "$CAMPAIGN"
log "submitting: bash $CAMPAIGN/campaign.sh"
bash "$CAMPAIGN/campaign.sh"
read -r ARRAY MERGE < "$CAMPAIGN/jobs"
last=""
for _ in $(seq 600); do
  states=$(squeue -h -o '%i %j %T %r' 2>/dev/null | sort || true)
  if [ "$states" != "$last" ]; then
    log "queue:"; echo "${states:-  (empty)}" | sed 's/^/  /'
    last=$states
  fi
  [ -z "$states" ] && break
  sleep 0.5
done
[ -z "$(squeue -h 2>/dev/null)" ] || { log "jobs still queued after 5 min"; squeue; exit 1; }
log "finished: array $ARRAY, merge $MERGE; final states:"
scontrol -o show job "$ARRAY" | grep -oE '^JobId=[0-9]+ |ArrayTaskId=[^ ]+|JobState=[^ ]+|ExitCode=[^ ]+' | paste -d' ' - - - - | sed 's/^/  /'
scontrol -o show job "$MERGE" | grep -oE '^JobId=[0-9]+ |JobState=[^ ]+|ExitCode=[^ ]+' | paste -d' ' - - - | sed 's/^/  /'
if { scontrol -o show job "$ARRAY"; scontrol -o show job "$MERGE"; } | grep -v 'JobState=COMPLETED' | grep -q .; then
  log "a job did not complete"; exit 1
fi
for f in "$CAMPAIGN"/logs/*.out; do echo "  $(basename "$f"): $(grep -v '^{' "$f" | tr '\n' ' ')"; done
ls "$CAMPAIGN/partials"
# each shard's log shows its progress (plain lines: stderr is a file there)
for i in 0 1 2 3; do
  grep -qE "^mc .* shard $i/4: [0-9]+/[0-9]+ runs in " "$CAMPAIGN/logs/shard-$i.out" || {
    log "shard $i's log has no progress line"; cat "$CAMPAIGN/logs/shard-$i.out"; exit 1
  }
done
[ -s "$CAMPAIGN/result/mc.json" ] || { log "no merged result"; cat "$CAMPAIGN"/logs/*; exit 1; }

"$ONEBEACON" mc "$SCENARIO" --runs 6 --seed 7 --json > "$RUN/local.json"
python3 - "$CAMPAIGN/result/mc.json" "$RUN/local.json" <<'EOF'
import json, sys
merged, local = (json.load(open(p)) for p in sys.argv[1:3])
same = merged["cells"] == local["cells"]
print(f"  merged {len(merged['cells'])} cells from the cluster, local {len(local['cells'])}: "
      + ("identical" if same else "DIFFERENT"))
for m, l in zip(merged["cells"], local["cells"]):
    print(f"  {m['sweep']} {m['estimator']:<12} mean {m['mean_error_m']:.6f} m  local {l['mean_error_m']:.6f} m")
sys.exit(0 if same else 1)
EOF
log "slurm test passed"
