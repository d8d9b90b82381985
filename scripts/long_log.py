#!/usr/bin/env python3
"""Writes a long synthetic log (for replay's memory test): a vehicle on a 40 m circle
with wheel-style odometry and ground truth at 10 Hz and ranges to two beacons at 5 Hz.

    python3 scripts/long_log.py DIR ROWS     # then: onebeacon replay DIR/long.toml

ROWS is the total number of CSV rows (about 40 % odometry, 40 % truth, 20 % ranges).
Only the standard library is used; the noise is seeded, so a given ROWS gives the
same files."""
import math, os, random, sys

def main():
    if len(sys.argv) != 3:
        sys.exit("usage: long_log.py DIR ROWS")
    out, rows = sys.argv[1], int(sys.argv[2])
    os.makedirs(out, exist_ok=True)
    steps = rows * 10 // 25  # 10 Hz odometry + 10 Hz truth + 5 Hz ranges
    rng = random.Random(1)
    radius, speed, dt = 40.0, 1.0, 0.1
    omega = speed / radius
    beacons = {0: (-30.0, 10.0), 1: (25.0, -45.0)}
    with open(f"{out}/long_beacons.csv", "w") as f:
        f.write("beacon_id,x_m,y_m\n")
        for b, (x, y) in beacons.items():
            f.write(f"{b},{x},{y}\n")
    with open(f"{out}/long_odometry.csv", "w") as odo, open(f"{out}/long_truth.csv", "w") as gt, \
            open(f"{out}/long_ranges.csv", "w") as rg:
        odo.write("t_s,d_m,dpsi_rad\n")
        gt.write("t_s,x_m,y_m,heading_rad\n")
        rg.write("t_s,beacon_id,range_m\n")
        for k in range(steps + 1):
            t = k * dt
            a = omega * t
            x, y = radius * math.sin(a), radius * (1 - math.cos(a))
            psi = math.atan2(math.sin(a), math.cos(a))  # ENU, heading from x, wrapped
            gt.write(f"{t:.2f},{x:.4f},{y:.4f},{psi:.6f}\n")
            if k > 0:
                odo.write(f"{t:.2f},{speed * dt * (1 + rng.gauss(0, 0.01)):.6f},{omega * dt + rng.gauss(0, 1e-4):.7f}\n")
            if k % 2 == 1:
                b = (k // 2) % 2
                bx, by = beacons[b]
                r = math.hypot(x - bx, y - by) + rng.gauss(0, 0.3)
                rg.write(f"{t + 0.05:.2f},{b},{r:.3f}\n")
    with open(f"{out}/long.toml", "w") as f:
        f.write(f'''name = "long"
description = "synthetic: {steps} steps of a 40 m circle, odometry, ranges to 2 beacons, truth"
frame = "enu"

[[source]]
kind = "odometry"
file = "long_odometry.csv"
time = "t_s"
distance = "d_m"
heading_change = "dpsi_rad"

[[source]]
kind = "range"
file = "long_ranges.csv"
time = "t_s"
beacon = "beacon_id"
range = "range_m"

[[source]]
kind = "ground_truth"
file = "long_truth.csv"
time = "t_s"
x = "x_m"
y = "y_m"
heading = "heading_rad"

[beacons]
file = "long_beacons.csv"
id = "beacon_id"
x = "x_m"
y = "y_m"

[initial]
from = "ground_truth"
heading_from = "column"

[[estimators]]
name = "dead-reckoning"
kind = "dead-reckoning"

[[estimators]]
name = "ekf-gated"
kind = "range-ekf"
nis_gate = 10.83
''')

main()
