"""ROS 2 bags written by an independent writer (the `rosbags` package) read by `onebeacon
replay` (a build with `--features ros2`, $ONEBEACON_CLI): plaza as bags replays as its
CSV files do, bit for bit; the standard messages are read by name, with and without the
definitions in the bag; bad bags and keys are one line and exit 2; a damaged bag is read
up to its damage, which is reported."""
import json
import math
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import ros2_bags  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
CLI = os.environ.get("ONEBEACON_CLI", str(REPO / "target" / "release" / "onebeacon"))


def run(*args):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)


@pytest.mark.parametrize("log", ["plaza1", "plaza2"])
@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_plaza_as_a_bag_replays_as_its_csv_files_bit_for_bit(tmp_path, log, storage):
    bag = ros2_bags.write_bag(log, tmp_path / "bag", storage)
    description = ros2_bags.write_description(log, bag, tmp_path / "log.toml")
    csv = ros2_bags.summary(CLI, ros2_bags.PLAZA / f"{log}.toml")
    assert ros2_bags.summary(CLI, description) == csv
    # and item by item: the stream replay prints is the CSV's, byte for byte
    a = run("replay", ros2_bags.PLAZA / f"{log}.toml", "--print-stream")
    b = run("replay", description, "--print-stream")
    assert a.returncode == 0 and b.returncode == 0, b.stderr
    assert a.stdout == b.stdout and len(a.stdout.splitlines()) > 9000


def quaternion(yaw):
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}


def yaw(q):
    """ZYX yaw of a quaternion, as ROS's tf2 gives it."""
    return math.atan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2))


def standard_bag(path, storage):
    """A bag of each standard message onebeacon reads by name; returns what each row
    must read as: (kind, t_s, values)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_JAZZY)
    T = ts.types
    H = lambda t, frame="base_link": T["std_msgs/msg/Header"](  # noqa: E731
        stamp=T["builtin_interfaces/msg/Time"](sec=int(t), nanosec=int(round((t % 1) * 1e9))), frame_id=frame
    )
    V = lambda x, y, z: T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)  # noqa: E731
    P = lambda x, y, z: T["geometry_msgs/msg/Point"](x=x, y=y, z=z)  # noqa: E731
    Q = lambda q: T["geometry_msgs/msg/Quaternion"](**q)  # noqa: E731
    pose = lambda x, y, h: T["geometry_msgs/msg/Pose"](position=P(x, y, -3.0), orientation=Q(quaternion(h)))  # noqa: E731
    twist = lambda u, v, r: T["geometry_msgs/msg/Twist"](linear=V(u, v, 0.0), angular=V(0.0, 0.0, r))  # noqa: E731
    cov = [0.0] * 36
    import numpy as np

    msgs, expect = [], []
    for i in range(5):
        t = 100.0 + i
        h = 0.3 + 0.5 * i
        msgs.append(("/odom", "nav_msgs/msg/Odometry", t, T["nav_msgs/msg/Odometry"](
            header=H(t), child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose(1.0 + i, 2.0 * i, h), covariance=np.array(cov)),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist(0.5 + i, -0.1 * i, 0.01 * i), covariance=np.array(cov)))))
        expect.append(("odom", t, {"x_m": 1.0 + i, "y_m": 2.0 * i, "heading_rad": yaw(quaternion(h))}))
        msgs.append(("/dvl", "geometry_msgs/msg/TwistStamped", t + 0.25,
                     T["geometry_msgs/msg/TwistStamped"](header=H(t + 0.25), twist=twist(1.5, 0.2 * i, -0.02))))
        expect.append(("dvl", t + 0.25, {"nu": [1.5, 0.2 * i, 0.0, 0.0, 0.0, -0.02]}))
        msgs.append(("/dvl_cov", "geometry_msgs/msg/TwistWithCovarianceStamped", t + 0.3,
                     T["geometry_msgs/msg/TwistWithCovarianceStamped"](header=H(t + 0.3), twist=T[
                         "geometry_msgs/msg/TwistWithCovariance"](twist=twist(0.7, 0.0, 0.03 * i), covariance=np.array(cov)))))
        expect.append(("dvl_cov", t + 0.3, {"nu": [0.7, 0.0, 0.0, 0.0, 0.0, 0.03 * i]}))
        q = quaternion(-1.0 + 0.7 * i)
        msgs.append(("/imu", "sensor_msgs/msg/Imu", t + 0.5, T["sensor_msgs/msg/Imu"](
            header=H(t + 0.5), orientation=Q(q), orientation_covariance=np.zeros(9), angular_velocity=V(0, 0, 0),
            angular_velocity_covariance=np.zeros(9), linear_acceleration=V(0, 0, 9.8),
            linear_acceleration_covariance=np.zeros(9))))
        expect.append(("imu", t + 0.5, {"heading_rad": yaw(q)}))
        r = 10.0 + 0.1 * i
        msgs.append(("/range", "sensor_msgs/msg/Range", t + 0.75, T["sensor_msgs/msg/Range"](
            header=H(t + 0.75, f"beacon_{3 if i % 2 else 7}"), radiation_type=0, field_of_view=0.1, min_range=0.5,
            max_range=500.0, range=r, variance=0.0)))
        expect.append(("range", t + 0.75, {"beacon": 3 if i % 2 else 7, "range_m": float(np.float32(r))}))
        msgs.append(("/pose", "geometry_msgs/msg/PoseStamped", t + 0.8,
                     T["geometry_msgs/msg/PoseStamped"](header=H(t + 0.8), pose=pose(-4.0, 5.0 + i, 2.5))))
        expect.append(("pose", t + 0.8, {"x_m": -4.0, "y_m": 5.0 + i, "heading_rad": yaw(quaternion(2.5))}))
        msgs.append(("/pose_cov", "geometry_msgs/msg/PoseWithCovarianceStamped", t + 0.85,
                     T["geometry_msgs/msg/PoseWithCovarianceStamped"](header=H(t + 0.85), pose=T[
                         "geometry_msgs/msg/PoseWithCovariance"](pose=pose(7.0, -1.0 * i, -2.0), covariance=np.array(cov)))))
        expect.append(("pose_cov", t + 0.85, {"x_m": 7.0, "y_m": -1.0 * i, "heading_rad": yaw(quaternion(-2.0))}))
        # a fix 0.001 deg north of the first each second: the first is the origin
        msgs.append(("/fix", "sensor_msgs/msg/NavSatFix", t + 0.9, T["sensor_msgs/msg/NavSatFix"](
            header=H(t + 0.9), status=T["sensor_msgs/msg/NavSatStatus"](status=0, service=1),
            latitude=43.0 + 0.001 * i, longitude=5.9, altitude=0.0, position_covariance=np.zeros(9),
            position_covariance_type=0)))
        expect.append(("fix", t + 0.9, {"north_m": 0.001 * i * math.pi / 180 * 6_371_000.0}))
    plugin = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}[storage]
    with Writer(path, version=9, storage_plugin=plugin) as w:
        conns = {}
        for topic, ty, t, m in msgs:
            if topic not in conns:
                conns[topic] = w.add_connection(topic, ty, typestore=ts)
            w.write(conns[topic], int(round(t * 1e9)), ts.serialize_cdr(m, ty))
    return expect


STANDARD_TOML = """name = "standard"
frame = "enu"
[[source]]
kind = "ground_truth"
bag = "bag"
topic = "/odom"
[[source]]
kind = "body_velocity"
bag = "bag"
topic = "/dvl"
[[source]]
kind = "body_velocity"
bag = "bag"
topic = "/dvl_cov"
[[source]]
kind = "heading"
bag = "bag"
topic = "/imu"
[[source]]
kind = "range"
bag = "bag"
topic = "/range"
[[source]]
kind = "ground_truth"
bag = "bag"
topic = "/pose"
[[source]]
kind = "ground_truth"
bag = "bag"
topic = "/pose_cov"
[[beacon]]
id = 3
x_m = 0.0
y_m = 0.0
[[beacon]]
id = 7
x_m = 10.0
y_m = 0.0
[initial]
from = "given"
x_m = 0.0
y_m = 0.0
heading_deg = 0.0
[[estimators]]
name = "ekf"
kind = "range-ekf"
"""


@pytest.mark.parametrize("storage", ["mcap", "sqlite3", "sqlite3-without-definitions"])
def test_standard_messages_are_read_by_name(tmp_path, storage):
    expect = standard_bag(tmp_path / "bag", storage.split("-")[0])
    if storage.endswith("without-definitions"):
        # a bag from before rosbag2 kept definitions: onebeacon's own of the standard types
        (db,) = (tmp_path / "bag").glob("*.db3")
        with sqlite3.connect(db) as c:
            assert c.execute("DELETE FROM message_definitions").rowcount > 0
    (tmp_path / "log.toml").write_text(STANDARD_TOML)
    out = run("replay", tmp_path / "log.toml", "--print-stream")
    assert out.returncode == 0, out.stderr
    lines = [json.loads(l) for l in out.stdout.splitlines()]
    seen = {}
    for line in lines:
        seen.setdefault(line["kind"], []).append(line)
    rows = {k: [e for e in expect if e[0] == k] for k in {e[0] for e in expect}}
    gt = sorted(rows["odom"] + rows["pose"] + rows["pose_cov"], key=lambda e: e[1])
    assert len(seen["ground_truth"]) == len(gt)
    for got, (_, t, want) in zip(seen["ground_truth"], gt):
        assert abs(got["t_s"] - t) < 1e-9
        for k, v in want.items():
            assert abs(got[k] - v) < 1e-12, (k, got, want)
    vel = sorted(rows["dvl"] + rows["dvl_cov"], key=lambda e: e[1])
    # float64 on the wire: the very values written
    assert [l["nu"] for l in seen["body_velocity"]] == [w["nu"] for _, _, w in vel]
    assert [l["heading_rad"] for l in seen["heading"]] == pytest.approx([w["heading_rad"] for _, _, w in rows["imu"]], abs=1e-12)
    # float32 on the wire: the float32 nearest each range, exactly
    assert [(l["beacon"], l["range_m"]) for l in seen["range"]] == [(w["beacon"], w["range_m"]) for _, _, w in rows["range"]]


def test_a_fix_is_read_as_latitude_and_longitude(tmp_path):
    expect = standard_bag(tmp_path / "bag", "mcap")
    text = STANDARD_TOML.split("[[source]]")[0] + '[[source]]\nkind = "ground_truth"\nbag = "bag"\ntopic = "/fix"\n' + \
        "[[source]]" + STANDARD_TOML.split("[[source]]")[5]  # the range source, for the estimator
    text += STANDARD_TOML[STANDARD_TOML.index("[[beacon]]"):]
    (tmp_path / "log.toml").write_text(text)
    out = run("replay", tmp_path / "log.toml", "--print-stream")
    assert out.returncode == 0, out.stderr
    fixes = [json.loads(l) for l in out.stdout.splitlines() if '"ground_truth"' in l]
    want = [w["north_m"] for k, _, w in expect if k == "fix"]
    # ENU: y north; a spherical earth's metres per degree to 0.5 % (the ellipsoid's
    # north radius at 43 deg is within 0.3 % of the mean radius)
    assert len(fixes) == len(want) and fixes[0]["y_m"] == 0.0 and fixes[0]["x_m"] == 0.0
    for f, w in zip(fixes[1:], want[1:]):
        assert abs(f["y_m"] - w) < 0.005 * w and abs(f["x_m"]) < 1e-6


def one_line_exit_2(out, *words):
    assert out.returncode == 2, (out.returncode, out.stderr)
    err = out.stderr.strip()
    assert "\n" not in err and "panicked" not in err, err
    for w in words:
        assert w in err, (w, err)


@pytest.fixture(scope="module")
def plaza_bag(tmp_path_factory):
    d = tmp_path_factory.mktemp("plaza")
    return ros2_bags.write_bag("plaza1", d / "bag", "mcap")


def test_an_unknown_topic_field_or_bag_is_one_line(tmp_path, plaza_bag):
    text = ros2_bags.write_description("plaza1", plaza_bag, tmp_path / "log.toml").read_text()
    bag_abs = f'bag = "{plaza_bag.as_posix()}"'
    text = text.replace(f'bag = "{plaza_bag.name}"', bag_abs)
    cases = [
        (text.replace('topic = "/radio/range"', 'topic = "/radio/rnage"'),
         ["topic `/radio/rnage`", "/radio/range", "/wheel/increment"]),
        (text.replace('range = "range"', 'range = "rang"'),
         ["/radio/range", "no field `rang` in onebeacon_msgs/BeaconRange", "header, range"]),
        (text.replace('distance = "distance"', 'distance = "header"'),
         ["/wheel/increment", "`header` is a std_msgs/Header"]),
        (text.replace(bag_abs, 'bag = "nowhere.mcap"', 1), ["nowhere.mcap", "cannot open"]),
        (text.replace(bag_abs, f'{bag_abs}\nfile = "x.csv"', 1), ["source[0].bag", "not both"]),
        (text.replace('topic = "/wheel/increment"\n', "", 1), ["source[0].topic", "missing"]),
    ]
    for i, (t, words) in enumerate(cases):
        p = tmp_path / f"case{i}.toml"
        p.write_text(t)
        one_line_exit_2(run("replay", p), *words)
    # a file that is no bag
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not a bag at all" * 100)
    p = tmp_path / "junk.toml"
    p.write_text(text.replace(bag_abs, f'bag = "{junk.as_posix()}"'))
    one_line_exit_2(run("replay", p), "junk.mcap", "not a readable MCAP file")
    junk = tmp_path / "junk.db3"
    junk.write_bytes(b"not a bag at all" * 100)
    p.write_text(text.replace(bag_abs, f'bag = "{junk.as_posix()}"'))
    one_line_exit_2(run("replay", p), "junk.db3", "SQLite")


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_damaged_bag_is_read_up_to_its_damage(tmp_path, storage):
    bag = ros2_bags.write_bag("plaza1", tmp_path / "bag", storage)
    (f,) = [p for p in bag.iterdir() if p.suffix in (".mcap", ".db3")]
    whole = run("replay", ros2_bags.write_description("plaza1", bag, tmp_path / "log.toml"), "--print-stream")
    data = f.read_bytes()
    if storage == "mcap":
        f.write_bytes(data[: len(data) * 6 // 10])  # cut short, as a recorder killed mid-write leaves it
    else:
        # pages of the messages table overwritten past 60 %
        cut = len(data) * 6 // 10
        f.write_bytes(data[:cut] + b"\xa5" * 8192 + data[cut + 8192:])
    out = run("replay", tmp_path / "log.toml", "--print-stream")
    assert "panicked" not in out.stderr
    if out.returncode == 0:
        got = out.stdout.splitlines()
        assert 0 < len(got) < len(whole.stdout.splitlines())
        # what was read is the whole bag's, line for line, to the damage
        assert set(got) <= set(whole.stdout.splitlines())
        assert "damaged" in out.stderr or "did not decode" in out.stderr, out.stderr
    else:
        one_line_exit_2(out, str(f.name))
