#!/usr/bin/env bash
# Runs every fuzz target under libFuzzer for SECONDS each (default 60), from the
# checked-in seeds, and copies whatever it finds into fuzz/regressions/TARGET/, which
# the normal test command replays (crates/onebeacon-fuzz/tests/corpus.rs).
# Needs the nightly toolchain and cargo-fuzz: rustup toolchain install nightly;
# cargo install cargo-fuzz.   Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(scenario log_description log_csv stream wav ping_config partial log_bag)
fi
for t in "${targets[@]}"; do
  corpus="fuzz/corpus/$t"            # grows as the fuzzer learns; not checked in
  mkdir -p "$corpus" "fuzz/regressions/$t"
  echo "== $t: ${seconds}s"
  status=0
  # -rss_limit_mb: an input that makes a target hold over 1 GB is a finding too
  cargo +nightly fuzz run --sanitizer none -j 1 "$t" "$corpus" "fuzz/seeds/$t" -- \
    -max_total_time="$seconds" -rss_limit_mb=1024 -timeout=20 -print_final_stats=1 2>&1 \
    | grep -E "^(stat::|#[0-9]+ +DONE|==[0-9]+==|SUMMARY|artifact_prefix|Test unit written)|panicked" || status=$?
  for f in fuzz/artifacts/"$t"/*; do
    [ -e "$f" ] || continue
    echo "found: $f -> fuzz/regressions/$t/"
    mv "$f" "fuzz/regressions/$t/"
  done
done
