#!/usr/bin/env python3
"""One error source of [sea] against the range filter with and without the state that
estimates it (docs/scenarios.md, "The sea").

Builds two scenarios from the built-in sousa (one-hour missions; circular, lawnmower and
still vehicle; guidance A and the 30 m circle; 10 runs per cell), one without the error
and one with it, each running the range EKF, the range EKF with the state and dead
reckoning. Prints each cell's mean error and NEES and the ratio of each filter's error to
the plain filter's without the error.

  clock        every clock draws a drift of 1 ppm standard deviation ([sea.clocks]);
               the state: a range offset and its drift (estimate_bias_drift); 5 m deep
  link         20 % of the pings lost in bursts of 3 on average, 10 % of the ranges
               heard on a multipath 10 m long on average, 2 % false, up to 500 m
               ([sea.link]); the state: none, a Student-t update (robust =
               "student_t") and, as a fourth filter, a gate at NIS 10.83 (99.9 %)
               instead; 5 and 50 m deep
  sound_speed  a tropical cast, 28 C mixed to 30 m, a thermocline to 20 C at 60 m, 15 C
               at 200 m (Mackenzie 1981, 35 ppt: 1541 m/s at the surface, 1522 at 60 m, 1510 at 200 m), while the vehicle
               converts with 1500 m/s; the state: a range scale (estimate_range_scale);
               20 and 50 m deep

Usage: scripts/sea_sources.py clock|link|sound_speed [BIN] [OUT_DIR]
       (default target/release/onebeacon, /tmp/sea_SOURCE)
"""
import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCES = {
    "clock": {
        "sea": "[sea.clocks]\ndrift_sigma_ppm = 1.0\n",
        "state": "estimate_bias_drift = true",
        "depths": "[5.0]",
    },
    "link": {
        "sea": "[sea.link]\nloss_prob = 0.2\nloss_burst_mean = 3.0\nmultipath_prob = 0.1\nmultipath_excess_m = 10.0\nfalse_prob = 0.02\nfalse_max_range_m = 500.0\n",
        "state": 'robust = "student_t"\n\n[[estimators]]\nkind = "range-ekf"\nname = "range-ekf-gated"\nnis_gate = 10.83',
        "depths": "[5.0, 50.0]",
    },
    "sound_speed": {
        "sea": "[sea.sound_speed]\ndepth_m = [0.0, 30.0, 60.0, 200.0]\ntemperature_c = [28.0, 28.0, 20.0, 15.0]\n",
        "state": "estimate_range_scale = true",
        "depths": "[20.0, 50.0]",
    },
}
ESTIMATORS = """
[[estimators]]
kind = "range-ekf"

[[estimators]]
kind = "range-ekf"
name = "range-ekf-state"
{state}

[[estimators]]
kind = "dead-reckoning"

[sweep]
path = ["circular", "lawnmower", "stationary"]
depth_m = {depths}
guidance = ["A", "circle"]
"""


def scenario(source: str, with_error: bool) -> str:
    """The TOML of the built-in sousa cut to an hour, with the range EKF, the range EKF
    with SOURCE's state and dead reckoning, and (with_error) SOURCE's error."""
    s = SOURCES[source]
    base = (ROOT / "scenarios/sousa.toml").read_text()
    base = base.replace("duration_s = 7200", "duration_s = 3600")
    assert "duration_s = 3600" in base, "sousa.toml's duration line moved"
    base = base[: base.index("# The first estimator")] + ESTIMATORS.format(state=s["state"], depths=s["depths"])
    if with_error:
        base = base.replace("[mission]", s["sea"] + "\n[mission]", 1)
    return base


def run(source: str, with_error: bool, binary: str, out: pathlib.Path, runs=None) -> dict:
    """`onebeacon mc` of scenario(SOURCE, with_error) (its 10 runs, or `runs`) in OUT: its
    cells by (path, depth, guidance, estimator)."""
    name = "sea" if with_error else "clean"
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.toml"
    path.write_text(scenario(source, with_error))
    cmd = [binary, "mc", str(path), "--out", str(out / name)] + (["--runs", str(runs)] if runs else [])
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"sea_sources: {' '.join(cmd)} failed ({done.returncode}): {done.stderr.strip()}")
    cells = json.loads((out / name / "mc.json").read_text())["cells"]
    return {(c["sweep"]["path"], c["sweep"]["depth_m"], c["sweep"]["guidance"], c["estimator"]): c for c in cells}


def main() -> None:
    if len(sys.argv) < 2 or sys.argv[1] not in SOURCES:
        print(f"usage: {sys.argv[0]} {'|'.join(SOURCES)} [BIN] [OUT_DIR]", file=sys.stderr)
        sys.exit(2)
    source = sys.argv[1]
    binary = sys.argv[2] if len(sys.argv) > 2 else str(ROOT / "target/release/onebeacon")
    out = pathlib.Path(sys.argv[3] if len(sys.argv) > 3 else f"/tmp/sea_{source}")
    clean, sea = run(source, False, binary, out), run(source, True, binary, out)
    print(f"{'cell':28} {'estimator':16} {'clean m':>8} {'NEES':>6} {'sea m':>8} {'NEES':>6} {'sea / plain clean':>18}")
    for key in sorted(clean):
        path, depth, guidance, est = key
        c, d = clean[key], sea[key]
        plain = clean[(path, depth, guidance, "range-ekf")]["mean_error_m"]
        print(
            f"{f'{path} {depth:g} m {guidance}':28} {est:16} {c['mean_error_m']:8.3f} {c['nees_mean']:6.2f} "
            f"{d['mean_error_m']:8.3f} {d['nees_mean']:6.2f} {d['mean_error_m'] / plain:18.3f}"
        )


if __name__ == "__main__":
    main()
