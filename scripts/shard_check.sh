#!/usr/bin/env bash
# Sharded and merged against unsharded: `mc SCENARIO --json`, then for each N the N
# shares (`mc --shard I/N`, one after the other) merged with `mc merge --json`, their
# cells compared with the unsharded cells (identical or not), with the wall times.
#
#   scripts/shard_check.sh SCENARIO [RUNS] [N...]   (default: the scenario's runs; N = 1 3 7)
#   ONEBEACON=path/to/onebeacon (default target/release/onebeacon)
set -euo pipefail
cd "$(dirname "$0")/.."
B=${ONEBEACON:-target/release/onebeacon}
SCENARIO=${1:?usage: scripts/shard_check.sh SCENARIO [RUNS] [N...]}
RUNS=()
if [ $# -ge 2 ] && [ "$2" != "-" ]; then RUNS=(--runs "$2"); fi
shift $(( $# >= 2 ? 2 : 1 ))
COUNTS=("$@")
[ ${#COUNTS[@]} -gt 0 ] || COUNTS=(1 3 7)
WORK=$(mktemp -d /tmp/onebeacon-shards.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
t=$(date +%s%N)
"$B" mc "$SCENARIO" "${RUNS[@]}" --json > "$WORK/whole.json"
echo "unsharded: $(( ($(date +%s%N) - t) / 1000000 )) ms"
status=0
for n in "${COUNTS[@]}"; do
  t=$(date +%s%N)
  for ((i = 0; i < n; i++)); do
    "$B" mc "$SCENARIO" "${RUNS[@]}" --shard "$i/$n" --out "$WORK/parts-$n" 2>/dev/null
  done
  "$B" mc merge "$WORK/parts-$n" --json > "$WORK/merged-$n.json"
  wall=$(( ($(date +%s%N) - t) / 1000000 ))
  python3 - "$WORK/whole.json" "$WORK/merged-$n.json" "$n" "$wall" <<'PY' || status=1
import json, sys
whole, merged = (json.load(open(p)) for p in sys.argv[1:3])
same = whole["cells"] == merged["cells"]
size = sum(1 for _ in whole["cells"])
print(f"{sys.argv[3]} shards: {size} cells {'identical' if same else 'DIFFERENT'} "
      f"(shards + merge {int(sys.argv[4]) / 1000:.1f} s wall, shards' compute {merged['wall_s']:.1f} s)")
sys.exit(0 if same else 1)
PY
done
exit $status
