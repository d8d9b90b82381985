#!/usr/bin/env bash
# onebeacon's receiver chain against the vectorised numpy/scipy version of the same ping
# (issue 15), back to back on one machine: ../shared/bench/dsp_numpy.py and the
# dsp_peer example, alternated over ROUNDS rounds.
#
#   scripts/dsp_peers.sh PYTHON [ROUNDS]
#
# PYTHON: a Python with numpy and scipy (python3 -m venv .venv-peers &&
# .venv-peers/bin/pip install numpy scipy).
set -euo pipefail
cd "$(dirname "$0")/.."
py=${1:?usage: scripts/dsp_peers.sh PYTHON [ROUNDS]}
rounds=${2:-3}
cargo build --release -q -p onebeacon --example dsp_peer
for round in $(seq "$rounds"); do
  target/release/examples/dsp_peer 60
  env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE OPENBLAS_NUM_THREADS=1 "$py" ../shared/bench/dsp_numpy.py 30 \
    | grep -E "ping_full|ping_range"
done
