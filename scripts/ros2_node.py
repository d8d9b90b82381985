#!/usr/bin/env python3
"""`onebeacon ros2` against an independent DDS: Eclipse Cyclone DDS (the Python package
`cyclonedds`) publishes plaza's inputs, or what a simulated vehicle's computer heard
(`onebeacon run SCENARIO --messages`), as ROS 2 messages and subscribes to the node's
outputs. Used by scripts/ros2_tests/test_node.py, and on its own for the node's latency
and memory at a rate:

    python3 scripts/ros2_node.py bench OUT_DIR [--log plaza1] [--hours 1] [--speed 10]

replays the log's inputs (repeated, time-shifted, to fill --hours) at --speed times real
time into a node, samples its RSS every 5 s, measures each output's latency (the input's
publication to the Odometry it caused, on one clock) and prints both. Needs a
`--features ros2` build ($ONEBEACON_CLI, else target/release/onebeacon) and
`pip install cyclonedds rosbags`.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float64, int32, sequence, uint8, uint32
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

sys.path.insert(0, str(Path(__file__).resolve().parent))
import ros2_bags  # noqa: E402
from ros2_bags import PLAZA, ROOT, rows  # noqa: E402

CLI = os.environ.get("ONEBEACON_CLI", str(ROOT / "target" / "release" / "onebeacon"))


# ROS 2 messages as DDS types (rosidl's names: pkg::msg::dds_::Type_), written here from
# their .msg definitions, independently of the node's Rust structs
@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class OdometryIncrement(IdlStruct, typename="onebeacon_msgs::msg::dds_::OdometryIncrement_"):
    header: Header
    distance: float64
    heading_change: float64


@dataclass
class BeaconRange(IdlStruct, typename="onebeacon_msgs::msg::dds_::BeaconRange_"):
    header: Header
    range: float64


@dataclass
class Pose2DStamped(IdlStruct, typename="onebeacon_msgs::msg::dds_::Pose2DStamped_"):
    header: Header
    x: float64
    y: float64
    heading: float64


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: float64
    y: float64
    z: float64


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64
    y: float64
    z: float64
    w: float64


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point
    orientation: Quaternion


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose
    covariance: array[float64, 36]


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64
    y: float64
    z: float64


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3
    angular: Vector3


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist
    covariance: array[float64, 36]


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header
    child_frame_id: str
    pose: PoseWithCovariance
    twist: TwistWithCovariance


@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    header: Header
    pose: Pose


@dataclass
class Setpoint(IdlStruct, typename="onebeacon_msgs::msg::dds_::Setpoint_"):
    """crates/onebeacon-ros2/msg/Setpoint.msg."""
    header: Header
    heading: float64
    speed: float64
    depth: float64
    mode: int32
    phase: str


@dataclass
class KeyValue(IdlStruct, typename="diagnostic_msgs::msg::dds_::KeyValue_"):
    key: str
    value: str


@dataclass
class DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticStatus_"):
    level: uint8
    name: str
    message: str
    hardware_id: str
    values: sequence[KeyValue]


@dataclass
class DiagnosticArray(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticArray_"):
    header: Header
    status: sequence[DiagnosticStatus]


# the node's inputs: ros2_bags.MESSAGES's topics, types, definitions and source keys,
# with the DDS type of each
IDL = {
    "onebeacon_msgs/msg/OdometryIncrement": OdometryIncrement,
    "onebeacon_msgs/msg/BeaconRange": BeaconRange,
    "onebeacon_msgs/msg/Pose2DStamped": Pose2DStamped,
}
INPUTS = [(what, topic, IDL[msgtype], msgtype, definition, keys)
          for what, (topic, msgtype, definition, keys) in ros2_bags.MESSAGES.items()]


def stamp(text):
    sec, nanosec = ros2_bags.stamp(text)
    return Time(sec=sec, nanosec=nanosec)


def live_description(log, directory):
    """plaza `log`'s description with its sources as live topics (their .msg files
    written beside it); returns its path."""
    sources = []
    for _, topic, _, msgtype, definition, keys in INPUTS:
        msg = directory / (msgtype.split("/")[-1] + ".msg")
        msg.write_text(definition)
        lines = [f'topic = "{topic}"', f'type = "{msgtype}"', f'definition = "{msg.name}"']
        sources.append(lines + [f'{k} = "{v}"' for k, v in keys.items()])
    return ros2_bags.description_with(log, sources, directory / f"{log}-live.toml")


def messages(log, hours=None):
    """plaza `log`'s inputs in time order as (t_s, topic, message); with `hours`, the log
    repeated (each pass shifted by its length) to fill that long."""
    one = []
    for what, topic, cls, _, _, _ in INPUTS:
        for r in rows(PLAZA / f"{log}_{what}.csv"):
            frame, fields = ros2_bags.fields(what, r)
            one.append((Decimal(r["t_s"]), what, topic, cls, frame, fields))
    one.sort(key=lambda m: m[0])
    span = one[-1][0] - one[0][0] + Decimal(1)
    passes = 1 if hours is None else max(1, int(Decimal(hours * 3600) / span + 1))
    out = []
    for k in range(passes):
        for t, what, topic, cls, frame, fields in one:
            tk = t + k * span
            if hours is not None and tk - one[0][0] > Decimal(hours * 3600):
                break
            out.append((float(tk), topic, cls(header=Header(stamp=stamp(str(tk)), frame_id=frame), **fields)))
    return out


class Graph:
    """A Cyclone DDS participant with writers for the inputs and readers of the node's
    outputs (every message kept, with when it came)."""

    def __init__(self, domain, estimators, inputs=None, namespace="/onebeacon"):
        """`estimators`: the node's odometry topics below `namespace` (`ekf`,
        `vehicle1/pf`); `inputs`: {topic: DDS type} written to (plaza's by default)."""
        self.dp = DomainParticipant(domain)
        reliable = Qos(Policy.Reliability.Reliable(max_blocking_time=duration(seconds=1)), Policy.History.KeepLast(10000))
        inputs = inputs or {topic: cls for _, topic, cls, _, _, _ in INPUTS}
        self.writers = {
            topic: DataWriter(self.dp, Topic(self.dp, "rt" + topic, cls), qos=reliable) for topic, cls in inputs.items()
        }
        self.received = {}  # topic -> [(arrival s, message)]
        self.readers = []
        outputs = [(f"{namespace}/{e}/odometry", Odometry) for e in estimators]
        outputs += [(f"{namespace}/diagnostics", DiagnosticArray), (f"{namespace}/waypoint", PoseStamped),
                    (f"{namespace}/setpoint", Setpoint)]
        for topic, cls in outputs:
            reader = DataReader(self.dp, Topic(self.dp, "rt" + topic, cls), qos=reliable)
            self.received[topic] = []
            self.readers.append((topic, cls, reader))
        self.running = True
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self):
        while self.running:
            got = False
            for topic, cls, reader in self.readers:
                for m in reader.take(N=1000):
                    # a writer gone (the node at its end) comes as an invalid sample
                    if isinstance(m, cls):
                        self.received[topic].append((time.monotonic(), m))
                    got = True
            if not got:
                time.sleep(0.0005)

    def matched(self, timeout=20.0):
        """Waits until each writer has matched the node's reader."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if all(w.get_matched_subscriptions() for w in self.writers.values()):
                return True
            time.sleep(0.05)
        return False

    def publish(self, msgs, rate_hz=None, speed=None, sent=None):
        """Publishes (t_s, topic, message) in order: at `rate_hz` messages a second, or at
        `speed` times their own time; `sent` gets each one's publication time."""
        start, t0 = time.monotonic(), msgs[0][0] if msgs else 0.0
        for i, (t, topic, m) in enumerate(msgs):
            due = start + (i / rate_hz if rate_hz else (t - t0) / speed)
            while (wait := due - time.monotonic()) > 0:
                time.sleep(min(wait, 0.01))
            if sent is not None:
                sent.append(time.monotonic())
            self.writers[topic].write(m)

    def close(self):
        self.running = False
        self.thread.join()


# A simulated vehicle's computer (`onebeacon run SCENARIO --messages`) on a ROS graph:
# its stream lines as the messages a vehicle's drivers publish. Fixes, poses, twists and
# the IMU are standard messages; an acoustic modem's report, a USBL's bearing and an
# inverted USBL's fix have none, so these are the vehicle's own (their .msg definitions
# below, given to the node by the description's `definition`).
@dataclass
class PointStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PointStamped_"):
    header: Header
    point: Point


@dataclass
class TwistStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TwistStamped_"):
    header: Header
    twist: Twist


@dataclass
class PoseWithCovarianceStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovarianceStamped_"):
    header: Header
    pose: PoseWithCovariance


@dataclass
class Imu(IdlStruct, typename="sensor_msgs::msg::dds_::Imu_"):
    header: Header
    orientation: Quaternion
    orientation_covariance: array[float64, 9]
    angular_velocity: Vector3
    angular_velocity_covariance: array[float64, 9]
    linear_acceleration: Vector3
    linear_acceleration_covariance: array[float64, 9]


@dataclass
class VehicleReport(IdlStruct, typename="onebeacon_msgs::msg::dds_::VehicleReport_"):
    header: Header
    heading: float64
    speed: float64
    depth: float64


@dataclass
class UsblBearing(IdlStruct, typename="onebeacon_msgs::msg::dds_::UsblBearing_"):
    header: Header
    station: str
    station_heading: float64
    azimuth: float64
    elevation: float64


@dataclass
class ArrayFix(IdlStruct, typename="onebeacon_msgs::msg::dds_::ArrayFix_"):
    header: Header
    t_tx: Time
    beacon_sigma: float64
    range: float64
    azimuth: float64
    inclination: float64
    mode: uint8


# per computer, stream kind -> topic, type, DDS type, its definition (None: a standard
# message), source keys; in the order of the description's sources
COMPUTERS = {
    # hoff2024's surface vehicle: its own fix, the USBL's position, the AUVs' reports
    # and bearings
    "asv": {
        "beacon_position": ("/asv/usbl/position", "geometry_msgs/msg/PointStamped", PointStamped, None,
                            {"beacon": "header.frame_id"}),
        "report": ("/asv/modem/report", "onebeacon_msgs/msg/VehicleReport", VehicleReport,
                   "# what a vehicle says of itself; header.frame_id: the vehicle (auv_1)\n"
                   "std_msgs/Header header\nfloat64 heading\nfloat64 speed\nfloat64 depth\n",
                   {"vehicle": "header.frame_id", "heading": "heading", "speed": "speed", "depth": "depth"}),
        "bearing": ("/asv/usbl/bearing", "onebeacon_msgs/msg/UsblBearing", UsblBearing,
                    "# a USBL's bearing to a vehicle; header.frame_id: the vehicle heard, station: the USBL\n"
                    "std_msgs/Header header\nstring station\nfloat64 station_heading\nfloat64 azimuth\n"
                    "float64 elevation\n",
                    {"vehicle": "header.frame_id", "beacon": "station", "station_heading": "station_heading",
                     "azimuth": "azimuth", "elevation": "elevation"}),
        "own_fix": ("/asv/odometry", "nav_msgs/msg/Odometry", Odometry, None, {}),
    },
    # rypkema's AUV: its DVL's speed, its IMU, its depth, and its inverted USBL's fixes
    # of the beacon (with the beacon's position)
    "auv": {
        "beacon_position": ("/auv/beacon/position", "geometry_msgs/msg/PointStamped", PointStamped, None,
                            {"beacon": "header.frame_id"}),
        "speed": ("/auv/dvl/twist", "geometry_msgs/msg/TwistStamped", TwistStamped, None,
                  {"speed": "twist.linear.x"}),
        "attitude": ("/auv/imu", "sensor_msgs/msg/Imu", Imu, None, {}),
        "depth": ("/auv/depth", "geometry_msgs/msg/PoseWithCovarianceStamped", PoseWithCovarianceStamped, None,
                  {"depth": "pose.pose.position.z"}),
        "array_fix": ("/auv/iusbl/fix", "onebeacon_msgs/msg/ArrayFix", ArrayFix,
                      "# an inverted USBL's fix of a beacon's ping; header.frame_id: the beacon (beacon_0)\n"
                      "std_msgs/Header header\nbuiltin_interfaces/Time t_tx\nfloat64 beacon_sigma\n"
                      "float64 range\nfloat64 azimuth\nfloat64 inclination\nuint8 mode\n",
                      {"beacon": "header.frame_id", "t_tx": "t_tx", "beacon_sigma": "beacon_sigma",
                       "range": "range", "azimuth": "azimuth", "inclination": "inclination", "mode": "mode"}),
    },
}


def computer_inputs(computer):
    """{topic: DDS type} of a computer's inputs."""
    return {topic: cls for topic, _, cls, _, _ in COMPUTERS[computer].values()}


def computer_description(computer, stream_toml, directory):
    """A computer's stream configuration `stream_toml` (run --messages's) with its
    inputs as live topics (COMPUTERS[computer]; the .msg files beside it); returns its
    path."""
    sources = []
    for kind, (topic, msgtype, _, definition, keys) in COMPUTERS[computer].items():
        lines = ["[[source]]", f'kind = "{kind.replace("beacon_position", "beacon_track")}"', f'topic = "{topic}"',
                 f'type = "{msgtype}"']
        if definition:
            msg = directory / (msgtype.split("/")[-1] + ".msg")
            msg.write_text(definition)
            lines.append(f'definition = "{msg.name}"')
        sources.append("\n".join(lines + [f'{k} = "{v}"' for k, v in keys.items()]))
    text = Path(stream_toml).read_text()
    # the sources before the first table, whose keys they would otherwise join
    cut = text.index("\n[")
    path = directory / f"{computer}-live.toml"
    path.write_text(text[:cut] + "\n\n" + "\n\n".join(sources) + "\n" + text[cut:])
    return path


def quaternion(roll, pitch, yaw):
    """The unit quaternion (x, y, z, w) of ZYX Euler angles."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return Quaternion(x=sr * cp * cy - cr * sp * sy, y=cr * sp * cy + sr * cp * sy, z=cr * cp * sy - sr * sp * cy,
                      w=cr * cp * cy + sr * sp * sy)


def computer_messages(computer, input_jsonl):
    """The stream lines of `input_jsonl` (run --messages's NAME.input.jsonl) as (t_s,
    topic, message), in their order; times to the nanosecond, as a stamp holds them."""
    zero3, zero9, zero36 = Vector3(x=0.0, y=0.0, z=0.0), [0.0] * 9, [0.0] * 36
    out = []
    for line in Path(input_jsonl).read_text().splitlines():
        d = json.loads(line)
        kind, t = d["kind"], d["t_s"]
        header = Header(stamp=stamp(repr(t)), frame_id=f"auv_{d.get('vehicle', 0)}")
        beacon = Header(stamp=header.stamp, frame_id=f"beacon_{d.get('beacon', 0)}")
        if kind == "own_fix":
            pose = Pose(position=Point(x=d["x_m"], y=d["y_m"], z=0.0), orientation=quaternion(0, 0, d["heading_rad"]))
            twist = Twist(linear=Vector3(x=d["speed_m_s"], y=0.0, z=0.0), angular=zero3)
            m = Odometry(header=Header(stamp=header.stamp, frame_id="map"), child_frame_id="base_link",
                         pose=PoseWithCovariance(pose=pose, covariance=zero36),
                         twist=TwistWithCovariance(twist=twist, covariance=zero36))
        elif kind == "beacon_position":
            m = PointStamped(header=beacon, point=Point(x=d["x_m"], y=d["y_m"], z=d["z_m"]))
        elif kind == "report":
            m = VehicleReport(header=header, heading=d["heading_rad"], speed=d["speed_m_s"], depth=d["depth_m"])
        elif kind == "bearing":
            m = UsblBearing(header=header, station=f"beacon_{d['beacon']}", station_heading=d["station_heading_rad"],
                            azimuth=d["azimuth_rad"], elevation=d["elevation_rad"])
        elif kind == "speed":
            m = TwistStamped(header=header, twist=Twist(linear=Vector3(x=d["speed_m_s"], y=0.0, z=0.0), angular=zero3))
        elif kind == "attitude":
            m = Imu(header=header, orientation=quaternion(d["roll_rad"], d["pitch_rad"], d["heading_rad"]),
                    orientation_covariance=zero9, angular_velocity=zero3, angular_velocity_covariance=zero9,
                    linear_acceleration=zero3, linear_acceleration_covariance=zero9)
        elif kind == "depth":
            pose = Pose(position=Point(x=0.0, y=0.0, z=d["depth_m"]), orientation=quaternion(0, 0, 0))
            m = PoseWithCovarianceStamped(header=header, pose=PoseWithCovariance(pose=pose, covariance=zero36))
        elif kind == "array_fix":
            m = ArrayFix(header=beacon, t_tx=stamp(repr(d["t_tx_s"])), beacon_sigma=d.get("beacon_sigma_m", 0.0),
                         range=d["range_m"], azimuth=d["azimuth_rad"], inclination=d["inclination_rad"],
                         mode=d["mode"])
        else:
            raise ValueError(f"{input_jsonl}: a {kind} line has no message here")
        out.append((t, COMPUTERS[computer][kind][0], m))
    return out


def start_node(description, domain, out_dir, idle_s=3.0, extra=()):
    """The node on `description`; its stdout, stderr and record in `out_dir`."""
    out = open(out_dir / "node.jsonl", "w")
    err = open(out_dir / "node.err", "w")
    p = subprocess.Popen(
        [CLI, "ros2", str(description), "--domain", str(domain), "--record", str(out_dir / "record.jsonl"),
         "--idle-exit-s", str(idle_s), *extra],
        stdout=out, stderr=err,
    )
    return p


def estimator_names(log):
    import tomllib
    names = [e["name"] for e in tomllib.loads((PLAZA / f"{log}.toml").read_text())["estimators"]]
    return ["".join(c if c.isalnum() else "_" for c in n) for n in names]


def rss_kib(pid):
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def bench(a):
    a.out.mkdir(parents=True, exist_ok=True)
    description = live_description(a.log, a.out)
    domain = 40 + os.getpid() % 150
    names = estimator_names(a.log)
    graph = Graph(domain, names)
    node = start_node(description, domain, a.out, idle_s=5.0)
    if not graph.matched():
        sys.exit("the node's readers did not match the writers in 20 s")
    msgs = messages(a.log, a.hours)
    sent, rss = [], []
    sampler_on = True

    def sample():
        t0 = time.monotonic()
        while sampler_on:
            rss.append((time.monotonic() - t0, rss_kib(node.pid)))
            time.sleep(5.0)

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    graph.publish(msgs, speed=a.speed, sent=sent)
    node.wait(timeout=600)
    sampler_on = False
    time.sleep(0.5)
    graph.close()
    # latency: an input's publication to the first estimator's Odometry it caused (the
    # node answers every input line but the screened ones with one line, in order)
    record = (a.out / "record.jsonl").read_text().splitlines()
    odo = graph.received[f"/onebeacon/{names[0]}/odometry"]
    lat = []
    stamps = {}
    for (arrived, m) in odo:
        stamps.setdefault((m.header.stamp.sec, m.header.stamp.nanosec), arrived)
    for (t, topic, m), s in zip(msgs, sent):
        key = (m.header.stamp.sec, m.header.stamp.nanosec)
        if key in stamps and stamps[key] >= s:
            lat.append(stamps.pop(key) - s)
    lat.sort()
    q = lambda p: lat[min(len(lat) - 1, int(p * len(lat)))] * 1e3 if lat else float("nan")  # noqa: E731
    at5 = next((r for t, r in rss if t >= 300), rss[-1][1] if rss else 0)
    peak_after = max((r for t, r in rss if t >= 300), default=at5)
    report = {
        "log": a.log, "hours": a.hours, "speed": a.speed, "messages_published": len(msgs),
        "messages_recorded": len(record), "odometry_received": len(odo),
        "latency_ms_p50": q(0.5), "latency_ms_p99": q(0.99), "latency_samples": len(lat),
        "rss_kib_at_5_min": at5, "rss_kib_peak_after_5_min": peak_after,
        "rss_kib_last": rss[-1][1] if rss else 0, "rss_samples": rss,
    }
    (a.out / "bench.json").write_text(json.dumps(report, indent=1))
    print(json.dumps({k: v for k, v in report.items() if k != "rss_samples"}, indent=1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bench")
    b.add_argument("out", type=Path)
    b.add_argument("--log", default="plaza1")
    b.add_argument("--hours", type=float, default=1.0)
    b.add_argument("--speed", type=float, default=10.0)
    a = ap.parse_args()
    bench(a)


if __name__ == "__main__":
    main()
