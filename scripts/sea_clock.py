#!/usr/bin/env python3
"""A drifting clock against the range filter with and without a clock state.

Builds two scenarios from the built-in sousa (one-hour missions at 5 m; circular,
lawnmower and still vehicle; guidance A and the 30 m circle; 10 runs per cell): one with
perfect clocks, one where every clock draws a drift of 1 ppm standard deviation
([sea.clocks]). Each runs the range EKF, the range EKF with a range offset and drift
state (estimate_bias_drift) and dead reckoning. Prints each cell's mean error and NEES
and the ratio of the clock-state filter's error to the plain filter's without clock
error (docs/scenarios.md, "The sea").

Usage: scripts/sea_clock.py [BIN] [OUT_DIR]   (default target/release/onebeacon, /tmp/sea_clock)
"""
import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
BIN = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target/release/onebeacon")
OUT = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else "/tmp/sea_clock")

ESTIMATORS = """
[[estimators]]
kind = "range-ekf"

[[estimators]]
kind = "range-ekf"
name = "range-ekf-clock"
estimate_bias_drift = true

[[estimators]]
kind = "dead-reckoning"

[sweep]
path = ["circular", "lawnmower", "stationary"]
depth_m = [5.0]
guidance = ["A", "circle"]
"""


def scenario(clocks: bool) -> str:
    base = (ROOT / "scenarios/sousa.toml").read_text()
    base = base.replace("duration_s = 7200", "duration_s = 3600")
    assert "duration_s = 3600" in base, "sousa.toml's duration line moved"
    base = base[: base.index("# The first estimator")] + ESTIMATORS
    if clocks:
        base = base.replace("[mission]", "[sea.clocks]\ndrift_sigma_ppm = 1.0\n\n[mission]", 1)
    return base


def run(name: str, clocks: bool) -> dict:
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / f"{name}.toml"
    path.write_text(scenario(clocks))
    subprocess.run([BIN, "mc", str(path), "--out", str(OUT / name)], check=True, stdout=subprocess.DEVNULL)
    cells = json.loads((OUT / name / "mc.json").read_text())["cells"]
    return {(c["sweep"]["path"], c["sweep"]["guidance"], c["estimator"]): c for c in cells}


def main() -> None:
    clean, drift = run("clean", False), run("drift", True)
    print(f"{'cell':24} {'estimator':16} {'clean m':>8} {'NEES':>6} {'1 ppm m':>8} {'NEES':>6} {'1 ppm / plain clean':>20}")
    for key in sorted(clean):
        path, guidance, est = key
        c, d = clean[key], drift[key]
        plain = clean[(path, guidance, "range-ekf")]["mean_error_m"]
        print(
            f"{path + ' ' + guidance:24} {est:16} {c['mean_error_m']:8.3f} {c['nees_mean']:6.2f} "
            f"{d['mean_error_m']:8.3f} {d['nees_mean']:6.2f} {d['mean_error_m'] / plain:20.3f}"
        )


if __name__ == "__main__":
    main()
