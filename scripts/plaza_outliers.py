#!/usr/bin/env python3
"""Writes plaza1 with five gross range outliers in its first minute (issue 12): ranges
whose error is -200, -75, +50, +175 and +300 m, one every 10 s from 10 s after the
start, to the beacons in turn. Everything else is plaza1's own files and estimators.

    python3 scripts/plaza_outliers.py DIR
    onebeacon replay DIR/plaza1_outliers.toml     # against: onebeacon replay data/plaza/plaza1.toml

An error that makes the range negative is screened by the session's limits (a range
must be in (0, limits.max_range_m]); the others reach the estimators.
Only the standard library is used."""
import math, os, shutil, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plaza_common  # noqa: E402
from plaza_common import rows  # noqa: E402

ERRORS_M = [-200.0, -75.0, 50.0, 175.0, 300.0]


def write(out, say=print):
    """plaza1 with the outliers in directory OUT: its CSV files and plaza1_outliers.toml;
    `say` is told each outlier."""
    src = plaza_common.DATA
    os.makedirs(out, exist_ok=True)
    for f in ["plaza1_beacons.csv", "plaza1_ground_truth.csv", "plaza1_odometry.csv"]:
        shutil.copy(os.path.join(src, f), os.path.join(out, f))
    truth = rows(os.path.join(src, "plaza1_ground_truth.csv"))
    beacons = {int(b["beacon_id"]): (float(b["x_m"]), float(b["y_m"])) for b in rows(os.path.join(src, "plaza1_beacons.csv"))}
    t0 = float(truth[0]["t_s"])

    truth_at = plaza_common.truth_at(truth)

    ranges = rows(os.path.join(src, "plaza1_ranges.csv"))
    ids = sorted(beacons)
    for k, e in enumerate(ERRORS_M):
        t = t0 + 10.0 * (k + 1) + 0.0005  # between plaza's own range times
        b = ids[k % len(ids)]
        x, y = truth_at(t)
        r = math.hypot(x - beacons[b][0], y - beacons[b][1]) + e
        ranges.append({"t_s": f"{t:.6f}", "beacon_id": str(b), "range_m": f"{r:.6f}"})
        say(f"t = {t - t0:.1f} s, beacon {b}: range {r:.1f} m (error {e:+.0f} m)")
    with open(os.path.join(out, "plaza1_ranges.csv"), "w") as f:
        f.write("t_s,beacon_id,range_m\n")
        for r in ranges:  # appended at the end: the source sorts by time
            f.write(f"{r['t_s']},{r['beacon_id']},{r['range_m']}\n")
    with open(os.path.join(src, "plaza1.toml")) as f:
        text = f.read().replace('name = "plaza1"', 'name = "plaza1_outliers"', 1)
    with open(os.path.join(out, "plaza1_outliers.toml"), "w") as f:
        f.write(text)


def main():
    if len(sys.argv) != 2:
        print("usage: plaza_outliers.py DIR", file=sys.stderr)
        sys.exit(2)
    write(sys.argv[1])


if __name__ == "__main__":
    main()
