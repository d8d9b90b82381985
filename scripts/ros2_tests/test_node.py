"""`onebeacon ros2` against an independent DDS, Eclipse Cyclone DDS (Python package
`cyclonedds`): it publishes plaza1's inputs as ROS 2 messages on loopback and subscribes
to the node's outputs. The node's inputs are replay's items, its outputs stream's on
them, bit for bit; its Odometry carries those estimates; bad messages are screened and
the node goes on; a bad configuration is one line, exit 2. The simulated vehicles'
computers (`run --messages`) on topics: a surface vehicle's waypoints are the
simulator's decisions, an AUV's setpoints its output lines' commands."""
import json
import math
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import ros2_node as rn  # noqa: E402

REPO = Path(__file__).resolve().parents[2]


def domain():
    """A DDS domain of this test process's own (0 to 232), away from a ROS default."""
    return 100 + os.getpid() % 100


def run_node(tmp_path, msgs, rate_hz=2000, extra=("--reorder-s", "0.5"), more=None):
    """Publishes `msgs` into a node on plaza1's live description; returns the graph (what
    Cyclone received), the node's output lines, its record and its stderr."""
    description = rn.live_description("plaza1", tmp_path)
    d = domain()
    graph = rn.Graph(d, rn.estimator_names("plaza1"))
    node = rn.start_node(description, d, tmp_path, idle_s=3.0, extra=extra)
    try:
        assert graph.matched(), "the node's readers never matched Cyclone's writers"
        graph.publish(msgs, rate_hz=rate_hz)
        if more:
            more(graph)
        assert node.wait(timeout=120) == 0, (tmp_path / "node.err").read_text()
    finally:
        if node.poll() is None:
            node.kill()
        time.sleep(0.5)
        graph.close()
    out = (tmp_path / "node.jsonl").read_text().splitlines()
    record = (tmp_path / "record.jsonl").read_text().splitlines()
    return graph, description, out, record, (tmp_path / "node.err").read_text()


def test_the_node_is_stream_on_plaza1_through_cyclone_dds(tmp_path):
    msgs = rn.messages("plaza1")
    graph, description, out, record, err = run_node(tmp_path, msgs)
    # every message came and became the item replay reads from the CSV files, in order
    want = subprocess.run([rn.CLI, "replay", rn.PLAZA / "plaza1.toml", "--print-stream"], capture_output=True,
                          text=True, check=True).stdout.splitlines()
    assert len(msgs) == len(want) == len(record)
    assert record == want
    # the node's outputs are stream's on those inputs, bit for bit
    stream = subprocess.run([rn.CLI, "stream", description], input="\n".join(record) + "\n", capture_output=True,
                            text=True, check=True).stdout.splitlines()
    assert out == stream and len(out) == len(record)
    # each Odometry Cyclone received is its output line's estimate
    lines = {}  # (stamp ns, estimator) -> its estimates on the lines of that stamp
    for line in map(json.loads, out):
        for e in line.get("estimates", []):
            lines.setdefault((round(line["t_s"] * 1e9), e["name"]), []).append(e)
    names = json.loads(out[-1])["estimates"]
    checked = 0
    for e in names:
        topic = f"/onebeacon/{''.join(c if c.isalnum() else '_' for c in e['name'])}/odometry"
        got = graph.received[topic]
        assert got, f"nothing on {topic}"
        for _, m in got:
            # the stamp is the input's, to the nanosecond: one of that stamp's lines
            key = (m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec, e["name"])
            candidates = [v for v in lines.get(key, []) if (v["x_m"], v["y_m"]) == (m.pose.pose.position.x, m.pose.pose.position.y)]
            assert candidates, (topic, key)
            v = candidates[0]
            q = m.pose.pose.orientation
            yaw = math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z)
            assert abs(math.remainder(yaw - v["heading_rad"], 2 * math.pi)) < 1e-12
            c = m.pose.covariance
            sx, sy, sh = v["sigma_x_m"], v["sigma_y_m"], v["sigma_heading_rad"]
            assert c[0] == sx * sx and c[7] == sy * sy
            assert c[1] == c[6] == v["cov_xy_m2"] and c[35] == sh * sh
            assert m.header.frame_id == "map" and m.child_frame_id == "base_link"
            checked += 1
    # a Python reader keeps up with part of 9 x 22844 messages in 12 s; the node drops
    # (and counts) what its cache cannot hold, and never waits for it
    assert checked > len(out)
    # diagnostics: every estimator, and the inputs: none skipped
    diag = graph.received["/onebeacon/diagnostics"]
    assert diag
    status = {s.name: s for s in diag[-1][1].status}
    assert set(status) == {f"onebeacon: {e['name']}" for e in names} | {"onebeacon: inputs", "onebeacon: outputs"}
    assert {kv.key: kv.value for kv in status["onebeacon: inputs"].values}["skipped"] == "0"
    assert f"{len(msgs)} messages, {len(msgs)} lines, 0 skipped" in err, err


def test_bad_messages_are_screened_and_the_node_goes_on(tmp_path):
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl.types import float32
    from cyclonedds.pub import DataWriter
    from cyclonedds.topic import Topic

    @dataclass
    class Short(rn.IdlStruct, typename="onebeacon_msgs::msg::dds_::BeaconRange_"):
        header: rn.Header
        range: float32

    msgs = rn.messages("plaza1")[:2000]
    t_late = msgs[1500][0] - 30.0  # a range 30 s behind what went in
    bad = [
        # a range that is not a number
        (msgs[1999][0] + 0.01, "/radio/range", rn.BeaconRange(header=rn.Header(stamp=rn.stamp(f"{msgs[1999][0] + 0.01:.6f}"), frame_id="beacon_0"), range=float("nan"))),
        # a beacon that is not the log's
        (msgs[1999][0] + 0.02, "/radio/range", rn.BeaconRange(header=rn.Header(stamp=rn.stamp(f"{msgs[1999][0] + 0.02:.6f}"), frame_id="beacon_9"), range=10.0)),
        # time going back
        (t_late, "/radio/range", rn.BeaconRange(header=rn.Header(stamp=rn.stamp(f"{t_late:.6f}"), frame_id="beacon_0"), range=10.0)),
    ]
    tail = rn.messages("plaza1")[2000:2200]

    def more(graph):
        time.sleep(1.0)  # the good ones in first
        graph.publish(bad, rate_hz=100)
        # a message of the right type name and the wrong layout, from another writer
        dp = DomainParticipant(domain())
        w = DataWriter(dp, Topic(dp, "rt/radio/range", Short))
        end = time.monotonic() + 10
        while not w.get_matched_subscriptions() and time.monotonic() < end:
            time.sleep(0.05)
        w.write(Short(header=rn.Header(stamp=rn.stamp(f"{tail[0][0]:.6f}"), frame_id="beacon_0"), range=3.0))
        time.sleep(1.0)
        graph.publish(tail, rate_hz=2000)

    graph, description, out, record, err = run_node(tmp_path, msgs, more=more)
    assert "not finite" in err and "beacon 9 is not among the beacons" in err
    assert "before the previous item's; screened out" in err
    # the message of the wrong layout: DDS does not deliver it (its writer's type does not
    # match, as Cyclone and RustDDS check it), or it does and it does not decode: either
    # way it is not an input, and the node goes on
    good = 2000 + len(bad) + len(tail)
    assert f"{good} messages, {good - 1} lines, 3 skipped" in err or "does not decode" in err, err
    assert "panicked" not in err
    # it went on: the last good message came, was answered, and its answer is stream's
    want_last = rn.messages("plaza1")[2199]
    assert abs(json.loads(out[-1])["t_s"] - want_last[0]) < 1e-6
    stream = subprocess.run([rn.CLI, "stream", description], input="\n".join(record) + "\n", capture_output=True,
                            text=True).stdout.splitlines()
    assert out == stream


def test_a_bad_configuration_is_one_line_exit_2(tmp_path):
    description = rn.live_description("plaza1", tmp_path)
    text = description.read_text()
    cases = [
        (text.replace('type = "onebeacon_msgs/msg/BeaconRange"', 'type = "onebeacon_msgs/msg/Nothing"', 1)
         .replace('definition = "BeaconRange.msg"\n', "", 1), ["onebeacon_msgs/msg/Nothing", "definition"]),
        (text.replace('range = "range"', 'range = "rnage"', 1), ["/radio/range", "no field `rnage`"]),
        (text.replace('topic = "/radio/range"', 'file = "x.csv"\ntopic = "/radio/range"', 1), ["source[1]"]),
    ]
    for i, (t, words) in enumerate(cases):
        p = tmp_path / f"bad{i}.toml"
        p.write_text(t)
        r = subprocess.run([rn.CLI, "ros2", str(p), "--domain", str(domain()), "--idle-exit-s", "1"],
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == 2, (r.returncode, r.stderr)
        assert "\n" not in r.stderr.strip() and "panicked" not in r.stderr
        for w in words:
            assert w in r.stderr, (w, r.stderr)
    # replay refuses a live topic, naming it
    r = subprocess.run([rn.CLI, "replay", str(description)], capture_output=True, text=True)
    assert r.returncode == 2 and "live topic" in r.stderr and "/wheel/increment" in r.stderr


def run_computer(tmp_path, computer, run, estimators, name=None, **pace):
    """A simulated computer of `run` (`run --messages`'s directory; its files NAME.*,
    NAME the computer's by default) as a node: what it heard published at `pace`
    (Graph.publish's `rate_hz` or `speed`), every message taken and answered. Returns the
    graph, the description, the node's output lines, its record and its stderr."""
    name = name or computer
    description = rn.computer_description(computer, run / f"{name}.stream.toml", tmp_path)
    msgs = rn.computer_messages(computer, run / f"{name}.input.jsonl")
    d = domain()
    graph = rn.Graph(d, estimators, inputs=rn.computer_inputs(computer))
    node = rn.start_node(description, d, tmp_path, idle_s=5.0, extra=("--reorder-s", "0.5"))
    try:
        assert graph.matched(), "the node's readers never matched Cyclone's writers"
        graph.publish(msgs, **pace)
        assert node.wait(timeout=300) == 0, (tmp_path / "node.err").read_text()
    finally:
        if node.poll() is None:
            node.kill()
        time.sleep(0.5)
        graph.close()
    err = (tmp_path / "node.err").read_text()
    assert f"{len(msgs)} messages, {len(msgs)} lines, 0 skipped" in err, err
    out = (tmp_path / "node.jsonl").read_text().splitlines()
    record = (tmp_path / "record.jsonl").read_text().splitlines()
    return graph, description, out, record, err


def test_the_surface_vehicles_computer_decides_on_topics_as_the_simulator(tmp_path):
    """hoff2024-pair's surface vehicle: what it heard in the simulation (its own fixes,
    the USBL's position, two AUVs' reports and bearings) published as ROS 2 messages;
    the node's waypoints on the topic are the simulator's decisions, bit for bit."""
    run = tmp_path / "run"
    subprocess.run([rn.CLI, "run", "hoff2024-pair", "--messages", "--out", str(run)], check=True,
                   capture_output=True)
    decisions = [json.loads(line) for line in (run / "asv.decisions.jsonl").read_text().splitlines()]
    names = [f"vehicle{v}/{e}" for v in (0, 1) for e in ("pf", "bearing")]
    # 150 times the simulation's pace (a 4 s period in 27 ms): the node's particle
    # filters (100000 particles) keep up on two cores
    graph, description, out, record, err = run_computer(tmp_path, "asv", run, names, speed=150.0)
    # the node's inputs are what the simulator's computer heard (in the node's order: at
    # one time, the beacon's position, then each topic's, the own fix last), the own
    # fix's heading through its quaternion within 10 ulp of pi (sin, cos, atan2 each
    # within 1 ulp)
    key = lambda d: (d["t_s"], d["kind"], d.get("vehicle", -1))  # noqa: E731
    heard = sorted(map(json.loads, (run / "asv.input.jsonl").read_text().splitlines()), key=key)
    took = sorted(map(json.loads, record), key=key)
    assert len(heard) == len(took)
    for h, t in zip(heard, took):
        if h["kind"] == "own_fix":
            assert abs(h.pop("heading_rad") - t.pop("heading_rad")) <= 10 * math.ulp(math.pi)
        assert h == t
    # its decisions are the simulator's, and its outputs stream's on its inputs
    decided = [(line["t_s"], line["command"]) for line in map(json.loads, out) if line.get("decided")]
    assert [(x["t_s"], x["command"]) for x in decisions] == decided
    stream = subprocess.run([rn.CLI, "stream", description], input="\n".join(record) + "\n", capture_output=True,
                            text=True, check=True).stdout.splitlines()
    assert out == stream
    # each waypoint on the topic is a decision's: the planner's waypoint, facing it from
    # the path's start, stamped with its time
    got = [m for _, m in graph.received["/onebeacon/waypoint"]]
    assert len(got) == len(decisions)
    for m, x in zip(got, decisions):
        c = x["command"]
        assert m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 == x["t_s"]
        assert (m.pose.position.x, m.pose.position.y) == (c["waypoint_x_m"], c["waypoint_y_m"])
        q = m.pose.orientation
        yaw = math.atan2(2 * q.w * q.z, 1 - 2 * q.z * q.z)
        want = math.atan2(c["waypoint_y_m"] - c["from_y_m"], c["waypoint_x_m"] - c["from_x_m"])
        assert abs(math.remainder(yaw - want, 2 * math.pi)) < 1e-12
    # each AUV's estimates on its own topics
    for n in names:
        assert graph.received[f"/onebeacon/{n}/odometry"], n


def test_an_auvs_computer_publishes_its_setpoints(tmp_path):
    """rypkema-m1's AUV platypus (600 s, the abstract signal model): its DVL, IMU,
    depth and inverted-USBL fixes as ROS 2 messages (sensor_msgs/Imu: the attitude
    through a quaternion); the node's outputs are stream's on its inputs, and each
    setpoint on the topic is a decided command of its output lines, bit for bit."""
    scenario = (REPO / "scenarios" / "rypkema-m1.toml").read_text()
    scenario = scenario.replace('model = "channel"', 'model = "abstract"', 1)
    scenario = scenario.replace("duration_s = 3600.0", "duration_s = 600.0", 1)
    (tmp_path / "fleet.toml").write_text(scenario)
    run = tmp_path / "run"
    subprocess.run([rn.CLI, "run", str(tmp_path / "fleet.toml"), "--messages", "--out", str(run)], check=True,
                   capture_output=True)
    names = ["iusbl", "iusbl_joint", "dead_reckoning"]
    graph, description, out, record, err = run_computer(tmp_path, "auv", run, names, name="platypus", rate_hz=2000)
    # its inputs are what the simulated AUV heard: times to the nanosecond (a stamp's),
    # roll, pitch and heading through a quaternion within 10 ulp of pi
    key = lambda x: (round(x["t_s"], 6), x["kind"])  # noqa: E731
    heard = sorted(map(json.loads, (run / "platypus.input.jsonl").read_text().splitlines()), key=key)
    took = sorted(map(json.loads, record), key=key)
    assert len(heard) == len(took)
    for h, t in zip(heard, took):
        for k in ("t_s", "t_tx_s"):
            if k in h:
                # cut to whole nanoseconds, then a float's rounding of 660 s
                assert abs(h.pop(k) - t.pop(k)) <= 1e-9 + 1e-12, k
        for k in ("roll_rad", "pitch_rad", "heading_rad") if h["kind"] == "attitude" else ():
            assert abs(math.remainder(h.pop(k) - t.pop(k), 2 * math.pi)) <= 10 * math.ulp(math.pi), k
        assert h == t
    stream = subprocess.run([rn.CLI, "stream", description], input="\n".join(record) + "\n", capture_output=True,
                            text=True, check=True).stdout.splitlines()
    assert out == stream
    # each setpoint received is the next decided command (a reader too slow loses some,
    # which the node counts as dropped: together they are all of them)
    decided = [line for line in map(json.loads, out) if line.get("decided")]
    got = [m for _, m in graph.received["/onebeacon/setpoint"]]
    dropped = int(err.rsplit(" skipped, ", 1)[1].split(" outputs dropped")[0])
    assert len(decided) > 5000 and len(got) + dropped >= len(decided) and len(got) > len(decided) // 2
    lines = iter(decided)
    for m in got:
        stamp_s = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
        line = next(x for x in lines if abs(x["t_s"] - stamp_s) <= 1e-9)
        c = line["command"]
        assert (m.heading, m.speed, m.depth) == (c["heading_rad"], c["speed_m_s"], c["depth_m"])
        assert (m.mode, m.phase) == (-1 if c["mode"] is None else c["mode"], c["phase"])
    # the behaviours' phases all came: waiting, then driving, and the dock's surfacing
    assert {m.phase for m in got} >= {"waiting", "driving"}
    for n in names:
        assert graph.received[f"/onebeacon/{n}/odometry"], n
