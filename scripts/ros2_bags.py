#!/usr/bin/env python3
"""The plaza logs as ROS 2 bags, written by an independent writer (the `rosbags` package),
with a log description that reads them; and the bag == CSV comparison of `replay`.

    python3 scripts/ros2_bags.py OUT_DIR [--onebeacon target/release/onebeacon]

writes OUT_DIR/{plaza1,plaza2}-{mcap,sqlite3}/ (a rosbag2 directory and a description
`log.toml`), replays each with the given onebeacon (built with `--features ros2`) and
with the CSV description, and prints a Markdown table: the summary's bytes equal or not.
Needs `pip install rosbags`.

The messages are float64 (a custom package `onebeacon_msgs` the bag carries the definitions
of), so that every value of the CSV goes through unrounded: a header stamp of
sec + nanosec written from the CSV's decimal text, the beacon id in the header's
frame_id (`beacon_5`).
"""

import argparse
import json
import subprocess
import sys
import tempfile
from decimal import Decimal
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PLAZA = ROOT / "data" / "plaza"

# (topic, type, definition, source keys of the description)
MESSAGES = {
    "odometry": (
        "/wheel/increment",
        "onebeacon_msgs/msg/OdometryIncrement",
        "std_msgs/Header header\nfloat64 distance\nfloat64 heading_change\n",
        {"kind": "odometry", "distance": "distance", "heading_change": "heading_change"},
    ),
    "ranges": (
        "/radio/range",
        "onebeacon_msgs/msg/BeaconRange",
        "std_msgs/Header header\nfloat64 range\n",
        {"kind": "range", "beacon": "header.frame_id", "range": "range", "time_order": "sort"},
    ),
    "ground_truth": (
        "/rtk/pose2d",
        "onebeacon_msgs/msg/Pose2DStamped",
        "std_msgs/Header header\nfloat64 x\nfloat64 y\nfloat64 heading\n",
        {"kind": "ground_truth", "x": "x", "y": "y", "heading": "heading"},
    ),
}


def stamp(text):
    """sec, nanosec of a decimal time written as text (exact, no float on the way)."""
    ns = int(Decimal(text) * 1_000_000_000)
    return ns // 1_000_000_000, ns % 1_000_000_000


def rows(path):
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:] if line.strip()]


def fields(what, r):
    """The header's frame id and the fields of the message of a row of plaza's `what`
    (a MESSAGES key): every value the float64 nearest the CSV's text."""
    if what == "odometry":
        return "base_link", dict(distance=float(r["delta_distance_m"]), heading_change=float(r["delta_heading_rad"]))
    if what == "ranges":
        return f"beacon_{r['beacon_id']}", dict(range=float(r["range_m"]))
    return "base_link", dict(x=float(r["x_m"]), y=float(r["y_m"]), heading=float(r["heading_rad"]))


def typestore():
    from rosbags.typesys import Stores, get_typestore, get_types_from_msg

    store = get_typestore(Stores.ROS2_JAZZY)
    for _, msgtype, definition, _ in MESSAGES.values():
        store.register(get_types_from_msg(definition, msgtype))
    return store


def write_bag(log, out, storage, limit=None):
    """Writes plaza `log`'s CSV files (their first `limit` rows each, or all) as a
    rosbag2 directory `out` in `storage` ("mcap" or "sqlite3"); returns its path."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    store = typestore()
    Header = store.types["std_msgs/msg/Header"]
    Time = store.types["builtin_interfaces/msg/Time"]
    plugin = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}[storage]
    messages = []  # (log_time ns, file order, topic, message)
    for n, (what, (topic, msgtype, _, _)) in enumerate(MESSAGES.items()):
        cls = store.types[msgtype]
        for i, r in enumerate(rows(PLAZA / f"{log}_{what}.csv")[:limit]):
            sec, nanosec = stamp(r["t_s"])
            frame, values = fields(what, r)
            msg = cls(header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=frame), **values)
            # the recorder's clock: the stamp
            messages.append((sec * 1_000_000_000 + nanosec, n, i, topic, msgtype, msg))
    messages.sort(key=lambda m: m[:3])  # as a recorder writes them: in time
    with Writer(out, version=9, storage_plugin=plugin) as writer:
        conns = {t: writer.add_connection(t, m, typestore=store) for t, m, _, _ in MESSAGES.values()}
        for t_ns, _, _, topic, msgtype, msg in messages:
            writer.write(conns[topic], t_ns, store.serialize_cdr(msg, msgtype))
    return out


def description_with(log, sources, path):
    """The CSV description of plaza `log` with `sources` (one list of `key = value` lines
    per entry of MESSAGES, in its order) in place of its [[source]] tables."""
    text = (PLAZA / f"{log}.toml").read_text()
    head, rest = text.split("[[source]]", 1)
    tail = rest[rest.index("[beacons]") :]
    tail = tail.replace(f'file = "{log}_beacons.csv"', f'file = "{(PLAZA / f"{log}_beacons.csv").as_posix()}"')
    tables = ["[[source]]\n" + "\n".join(lines) + "\n" for lines in sources]
    path.write_text(head + "\n".join(tables) + "\n" + tail)
    return path


def write_description(log, bag, path):
    """The CSV description of plaza `log` with its sources read from `bag` instead."""
    sources = [[f'bag = "{bag.name}"', f'topic = "{topic}"'] + [f'{k} = "{v}"' for k, v in keys.items()]
               for topic, _, _, keys in MESSAGES.values()]
    return description_with(log, sources, path)


def summary(onebeacon, description):
    """`replay --json`'s summary without the fields that name the files."""
    # its files in a directory of their own, not in the working directory
    with tempfile.TemporaryDirectory() as where:
        out = subprocess.run([onebeacon, "replay", str(description), "--json", "--out", where], capture_output=True,
                             text=True)
    if out.returncode != 0:
        raise SystemExit(f"replay {description} failed: {out.stderr.strip()}")
    s = json.loads(out.stdout)
    for key in ("wall_s",):  # the one field that differs run to run
        s.pop(key, None)
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--onebeacon", default=str(ROOT / "target" / "release" / "onebeacon"))
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    print("| log | storage | messages | bag bytes | summary == CSV's |")
    print("|---|---|---|---|---|")
    bad = 0
    for log in ("plaza1", "plaza2"):
        csv = json.dumps(summary(a.onebeacon, PLAZA / f"{log}.toml"), sort_keys=True)
        for storage in ("mcap", "sqlite3"):
            d = a.out / f"{log}-{storage}"
            d.mkdir(exist_ok=True)
            bag = write_bag(log, d / "bag", storage) if not (d / "bag").exists() else d / "bag"
            description = write_description(log, bag, d / "log.toml")
            same = json.dumps(summary(a.onebeacon, description), sort_keys=True) == csv
            bad += not same
            count = sum(len(rows(PLAZA / f"{log}_{w}.csv")) for w in MESSAGES)
            size = sum(f.stat().st_size for f in bag.iterdir())
            print(f"| {log} | {storage} | {count} | {size} | {'yes, bit for bit' if same else 'NO'} |")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
