#!/usr/bin/env bash
# The cost of the sea (issue 31): each built-in -sea scenario timed against itself with
# its [sea.*] tables removed (the same estimators and sweep), alternated, on all cores.
#
#   scripts/sea_cost.sh [ROUNDS]
#
# Prints one line per scenario and round: wall seconds with and without the sea and
# their ratio. ROUNDS defaults to 2. Run counts are small, chosen for a minute or so per
# scenario; the ratio, not the time, is the figure.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-2}
cargo build --release -q -p onebeacon-cli
bin=target/release/onebeacon
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# a TOML file without its [sea] and [sea.*] tables
strip_sea() {
  awk '/^[[:space:]]*\[\[?[A-Za-z_.]+/ { t = $0; sub(/^[[:space:]]*\[\[?/, "", t); skip = (t ~ /^sea([.\]]|$)/) } !skip' "$1"
}
seconds() { # wall seconds of `mc SCENARIO --runs RUNS`
  local start end
  start=$(date +%s.%N)
  "$bin" mc "$1" --runs "$2" > /dev/null 2> "$tmp/err" || { cat "$tmp/err" >&2; exit 1; }
  end=$(date +%s.%N)
  awk -v a="$start" -v b="$end" 'BEGIN { print b - a }'
}
printf '%-16s %5s %10s %10s %6s\n' scenario round sea_s clean_s ratio
for pair in garin2024-sea:200 sousa-sea:2 hoff2024-sea:1 rypkema-m1-sea:1; do
  name=${pair%%:*}
  runs=${pair##*:}
  "$bin" scenarios --show "$name" > "$tmp/$name.toml"
  strip_sea "$tmp/$name.toml" > "$tmp/$name-clean.toml"
  if grep -q '^\[sea' "$tmp/$name-clean.toml" || ! grep -q '^\[sea' "$tmp/$name.toml"; then
    echo "$name: could not strip its [sea] tables" >&2
    exit 1
  fi
  for round in $(seq "$rounds"); do
    sea=$(seconds "$tmp/$name.toml" "$runs")
    clean=$(seconds "$tmp/$name-clean.toml" "$runs")
    printf '%-16s %5d %10.2f %10.2f %6.2f\n' "$name" "$round" "$sea" "$clean" "$(awk -v a="$sea" -v b="$clean" 'BEGIN { print a / b }')"
  done
done
