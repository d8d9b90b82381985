#!/usr/bin/env bash
# onebeacon's particle filter against Stone Soup and numpy on the same model, back to
# back on one machine (issue 13): ../shared/bench/pf_peers.py and the pf_peer example.
#
#   scripts/pf_peers.sh PYTHON [N ...]
#
# PYTHON: a Python with numpy, scipy and stonesoup (python3 -m venv .venv-peers &&
# .venv-peers/bin/pip install numpy scipy stonesoup). Each N (default 1e5 5e5) is timed
# twice, the three implementations in turn.
set -euo pipefail
cd "$(dirname "$0")/.."
py=${1:?usage: scripts/pf_peers.sh PYTHON [N ...]}
shift
sizes=("${@:-1e5 5e5}")
peers=../shared/bench/pf_peers.py
cargo build --release -q -p onebeacon --example pf_peer
for n in ${sizes[@]}; do
  for round in 1 2; do
    target/release/examples/pf_peer "$n" 12
    env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE OPENBLAS_NUM_THREADS=1 "$py" "$peers" numpy "$n" 12
    env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE OPENBLAS_NUM_THREADS=1 "$py" "$peers" stonesoup "$n" 6
  done
done
