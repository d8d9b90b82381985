#!/usr/bin/env python3
"""Writes a synthetic long-baseline log with an early burst of false ranges (issue 30):
a vehicle at 1.5 m/s for 30 min among four beacons 400-600 m away, odometry 2 % long
and turning 3 % too far, ranges 1 % long plus 1 m with 0.8 m of noise, one every 4 s to
the beacons in turn; the first 11 ranges to beacon 0 are 200 m short.

    python3 scripts/lbl_burst.py DIR
    onebeacon replay DIR/burst.toml        # the burst
    onebeacon replay DIR/clean.toml        # the same log without it
    onebeacon replay DIR/ungated.toml      # the burst, every estimator with nis_gate = inf
    onebeacon replay DIR/off_start.toml    # no burst, started 39 m off with a 0.5 m sigma
    onebeacon replay DIR/ranges_start.toml         # [initial] from = "ranges", 60 s window
    onebeacon replay DIR/ranges_start_burst.toml   # the same with the burst

The estimators are plaza1's (data/plaza/plaza1.toml). Seeded: the files are the same
on every run. Only the standard library is used."""
import math, os, random, re, sys

BEACONS = {0: (400.0, 300.0), 1: (-350.0, 420.0), 2: (-300.0, -380.0), 3: (450.0, -350.0)}
BURST = (11, -200.0)
HERE = os.path.dirname(os.path.abspath(__file__))


def write(out, burst):
    """The CSV files of the log, with or without the burst (suffix _burst or _clean)."""
    rng = random.Random(1)
    x, y, psi = 0.0, 0.0, 0.3
    odo, truth, ranges = [], [(0.0, x, y, psi)], []
    heard0 = 0
    for k in range(1, 1801):
        t = float(k)
        dpsi = 0.02 * math.sin(t / 60.0)
        d = 1.5
        x += d * math.cos(psi + dpsi / 2)  # ENU: x east, y north, heading from x
        y += d * math.sin(psi + dpsi / 2)
        psi += dpsi
        odo.append((t, d * 1.02 + rng.gauss(0, 0.01), dpsi * 1.03 + rng.gauss(0, 0.002)))
        truth.append((t, x, y, psi))
        if k % 4 == 0:
            b = (k // 4) % 4
            bx, by = BEACONS[b]
            r = math.hypot(x - bx, y - by) * 1.01 + 1.0 + rng.gauss(0, 0.8)
            if b == 0:
                heard0 += 1
                if burst and heard0 <= BURST[0]:
                    r += BURST[1]
            ranges.append((t + 0.001, b, r))
    tag = "burst" if burst else "clean"
    def csv(name, header, rows):
        with open(os.path.join(out, name), "w") as f:
            f.write(header + "\n" + "".join(",".join(str(v) for v in row) + "\n" for row in rows))
    csv(f"odometry_{tag}.csv", "t_s,delta_distance_m,delta_heading_rad", odo)
    csv(f"ground_truth_{tag}.csv", "t_s,x_m,y_m,heading_rad", truth)
    csv(f"ranges_{tag}.csv", "t_s,beacon_id,range_m", ranges)


def description(name, tag, edit=lambda t: t):
    """plaza1's description on this log's files, edited by `edit`."""
    with open(os.path.join(HERE, "..", "data", "plaza", "plaza1.toml")) as f:
        t = f.read()
    t = t.replace('name = "plaza1"', f'name = "{name}"', 1)
    for a, b in [("plaza1_odometry", f"odometry_{tag}"), ("plaza1_ranges", f"ranges_{tag}"),
                 ("plaza1_ground_truth", f"ground_truth_{tag}"), ("plaza1_beacons", "beacons")]:
        t = t.replace(a, b)
    return edit(t)


def ungated(t):
    """Every range estimator without a gate."""
    t = re.sub(r"nis_gate = [^\n]*\n", "", t)
    return t.replace('kind = "range-ekf"\n', 'kind = "range-ekf"\nnis_gate = inf\n')


def off_start(t):
    """Started 39 m off (30 m east, 25 m north) with plaza1's 0.5 m sigma."""
    return t.replace('from = "ground_truth"', 'from = "given"\nx_m = 30.0\ny_m = 25.0\nheading_deg = 17.19', 1)


def ranges_start(t):
    """Started from the first 60 s of ranges (the first at 4 s), with the true heading at
    the window's end (64 s: 0.3 rad plus the turns, in the log's ENU degrees)."""
    heading = 0.3 + sum(0.02 * math.sin(k / 60.0) for k in range(1, 65))
    return t.replace('from = "ground_truth"',
                     f'from = "ranges"\nranges_window_s = 60\nheading_deg = {math.degrees(heading):.4f}', 1)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: lbl_burst.py DIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    write(out, True)
    write(out, False)
    with open(os.path.join(out, "beacons.csv"), "w") as f:
        f.write("beacon_id,x_m,y_m\n" + "".join(f"{k},{x},{y}\n" for k, (x, y) in BEACONS.items()))
    for name, tag, edit in [("burst", "burst", lambda t: t), ("clean", "clean", lambda t: t),
                            ("ungated", "burst", ungated), ("off_start", "clean", off_start),
                            ("ranges_start", "clean", ranges_start), ("ranges_start_burst", "burst", ranges_start)]:
        with open(os.path.join(out, f"{name}.toml"), "w") as f:
            f.write(description(name, tag, edit))
    print(f"wrote {out}/burst.toml, clean.toml, ungated.toml, off_start.toml, ranges_start.toml, "
          "ranges_start_burst.toml")


main()
