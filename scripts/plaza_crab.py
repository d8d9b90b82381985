#!/usr/bin/env python3
"""Writes plaza1 as a crabbing vehicle (issue 12): the ground truth drifts with a
current of 0.1 m/s toward north, the odometry becomes body-frame increments (forward,
lateral to the left: plaza is an ENU log) that include the current, and every range is
scaled by the ratio of the drifted to the original distance (plaza's ranges read as a
scale of the distance, so that error model is kept).

    python3 scripts/plaza_crab.py DIR
    onebeacon replay DIR/crab_body.toml      # body_odometry with its lateral part
    onebeacon replay DIR/crab_forward.toml   # the same forward increments, no lateral part
    onebeacon replay DIR/crab_dvl.toml       # the same motion as body_velocity (a DVL):
                                             # speeds and yaw rate held until the next row

Only the standard library is used."""
import math, os, shutil, sys

import plaza_common
from plaza_common import rows

CURRENT_NORTH_M_S = 0.1


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plaza_crab.py DIR")
    src = plaza_common.DATA
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    truth = rows(os.path.join(src, "plaza1_ground_truth.csv"))
    odo = rows(os.path.join(src, "plaza1_odometry.csv"))
    ranges = rows(os.path.join(src, "plaza1_ranges.csv"))
    beacons = {int(b["beacon_id"]): (float(b["x_m"]), float(b["y_m"])) for b in rows(os.path.join(src, "plaza1_beacons.csv"))}
    shutil.copy(os.path.join(src, "plaza1_beacons.csv"), os.path.join(out, "crab_beacons.csv"))
    t0 = float(truth[0]["t_s"])
    truth_at = plaza_common.truth_at(truth)

    drift = lambda t: CURRENT_NORTH_M_S * (t - t0)
    with open(os.path.join(out, "crab_truth.csv"), "w") as f:
        f.write("t_s,x_m,y_m,heading_rad\n")
        for r in truth:
            t = float(r["t_s"])
            f.write(f"{t:.6f},{float(r['x_m']):.6f},{float(r['y_m']) + drift(t):.6f},{r['heading_rad']}\n")
    # body increments: the odometry's own heading, integrated from the first truth heading
    psi, t_prev = float(truth[0]["heading_rad"]), t0
    increments = []
    with open(os.path.join(out, "crab_odometry.csv"), "w") as f:
        f.write("t_s,forward_m,left_m,dheading_rad\n")
        for r in odo:
            t, d, dpsi = float(r["t_s"]), float(r["delta_distance_m"]), float(r["delta_heading_rad"])
            mid = psi + dpsi / 2.0
            c = CURRENT_NORTH_M_S * (t - t_prev)  # the current's displacement, north (ENU y)
            fwd, left = d + c * math.sin(mid), c * math.cos(mid)
            f.write(f"{t:.6f},{fwd:.9f},{left:.9f},{dpsi:.9f}\n")
            increments.append((t_prev, t, fwd, left, dpsi))
            psi, t_prev = psi + dpsi, t
    # the DVL: each increment as the body velocity of its interval, stamped at its start
    # (held until the next row); the chord of an arc is shorter than the arc by
    # sinc(dpsi / 2), which the velocity undoes
    with open(os.path.join(out, "crab_dvl.csv"), "w") as f:
        f.write("t_s,u_m_s,v_left_m_s,r_rad_s\n")
        for a, b, fwd, left, dpsi in increments:
            if b <= a:
                continue
            k = math.sin(dpsi / 2) / (dpsi / 2) if abs(dpsi) > 1e-12 else 1.0
            f.write(f"{a:.6f},{fwd / k / (b - a):.9f},{left / k / (b - a):.9f},{dpsi / (b - a):.9f}\n")
    with open(os.path.join(out, "crab_ranges.csv"), "w") as f:
        f.write("t_s,beacon_id,range_m\n")
        for r in ranges:
            t, b, rng = float(r["t_s"]), int(r["beacon_id"]), float(r["range_m"])
            x, y = truth_at(t)
            bx, by = beacons[b]
            # plaza's ranges read as a scale of the distance (1.07 x, data/plaza/README.md):
            # scaling by the ratio of the distances keeps that error model
            ratio = math.hypot(x - bx, y + drift(t) - by) / max(math.hypot(x - bx, y - by), 1e-9)
            f.write(f"{t:.6f},{b},{rng * ratio:.6f}\n")
    with open(os.path.join(src, "plaza1.toml")) as f:
        plaza = f.read()
    estimators = plaza[plaza.index("[[estimators]]"):]
    head = f'''frame = "enu"

[[source]]
kind = "{{kind}}"
file = "crab_odometry.csv"
time = "t_s"
{{columns}}

[[source]]
kind = "range"
file = "crab_ranges.csv"
time = "t_s"
beacon = "beacon_id"
range = "range_m"
time_order = "sort"

[[source]]
kind = "ground_truth"
file = "crab_truth.csv"
time = "t_s"
x = "x_m"
y = "y_m"
heading = "heading_rad"

[beacons]
file = "crab_beacons.csv"
id = "beacon_id"
x = "x_m"
y = "y_m"

[initial]
from = "ground_truth"
heading_from = "column"
position_sigma_m = 0.5
heading_sigma_deg = 2.0

'''
    body = head.replace("{kind}", "body_odometry").replace(
        "{columns}", 'forward = "forward_m"\nlateral = "left_m"\nheading_change = "dheading_rad"')
    fwd = head.replace("{kind}", "odometry").replace(
        "{columns}", 'distance = "forward_m"\nheading_change = "dheading_rad"')
    dvl = head.replace("{kind}", "body_velocity").replace("crab_odometry.csv", "crab_dvl.csv").replace(
        "{columns}", 'forward_speed = "u_m_s"\nlateral_speed = "v_left_m_s"\nyaw_rate = "r_rad_s"')
    for name, text in [("crab_body", body), ("crab_forward", fwd), ("crab_dvl", dvl)]:
        with open(os.path.join(out, name + ".toml"), "w") as f:
            f.write(f'name = "{name}"\ndescription = "plaza1 crabbing in a 0.1 m/s current toward north"\n' + text + estimators)

main()
