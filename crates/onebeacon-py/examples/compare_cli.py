"""The Python layer against the CLI, side by side on one machine:

1. `onebeacon.mc(SCENARIO)` and `onebeacon mc SCENARIO --json` (the CLI as a subprocess):
   whether the cells are identical, and each one's wall time (best of ROUNDS);
2. one navigator update from Python (`Navigator.feed` of a range, then of an odometry
   item, on plaza1's configuration) per call, to set beside the Rust bench
   `cargo bench -p onebeacon-bench --bench replay -- "session push"`.

    python compare_cli.py [SCENARIO] [ROUNDS]      (CLI: $ONEBEACON_CLI or target/release/onebeacon)
"""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import onebeacon

REPO = Path(__file__).resolve().parents[3]
name = sys.argv[1] if len(sys.argv) > 1 else "garin2024"
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
cli = os.environ.get("ONEBEACON_CLI", str(REPO / "target" / "release" / "onebeacon"))

py_times, cli_times = [], []
for _ in range(rounds):
    t = time.perf_counter()
    cells = onebeacon.mc(name)
    py_times.append(time.perf_counter() - t)
    t = time.perf_counter()
    out = subprocess.run([cli, "mc", name, "--json"], capture_output=True, text=True, check=True).stdout
    cli_times.append(time.perf_counter() - t)
    same = cells == json.loads(out)["cells"]
    print(f"mc {name}: python {py_times[-1]:.3f} s, cli {cli_times[-1]:.3f} s, cells identical: {same}")
    if not same:
        sys.exit(1)
best_py, best_cli = min(py_times), min(cli_times)
print(f"mc {name}, best of {rounds}: python {best_py:.3f} s, cli {best_cli:.3f} s, "
      f"python / cli = {best_py / best_cli:.3f}")

# one update through the Python layer: a started navigator, then range + odometry items
config = REPO / "data" / "plaza" / "plaza1.toml"
items = subprocess.run([cli, "replay", str(config), "--print-stream"], capture_output=True, text=True,
                       check=True).stdout.splitlines()
nav = onebeacon.Navigator(config)
for line in items[:2000]:
    nav.feed(line)
t0 = json.loads(items[1999])["t_s"]
n = 20000
for label, make in [
    ("range (dict)", lambda k: {"t_s": t0 + 0.01 * k, "kind": "range", "beacon": 1, "range_m": 30.0}),
    ("odometry (dict)", lambda k: {"t_s": t0 + 200 + 0.01 * k, "kind": "odometry", "distance_m": 0.01,
                                   "heading_change_rad": 0.0}),
    ("odometry (JSON line)", lambda k: json.dumps({"t_s": t0 + 400 + 0.01 * k, "kind": "odometry",
                                                    "distance_m": 0.01, "heading_change_rad": 0.0})),
]:
    batch = [make(k) for k in range(n)]
    t = time.perf_counter()
    for item in batch:
        nav.feed(item)
    per = (time.perf_counter() - t) / n
    print(f"Navigator.feed, {label}, {len(nav.names)} estimators: {per * 1e6:.2f} us per item")
