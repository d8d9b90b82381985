"""The Python package against the CLI: the same numbers, the same one-line errors.

The CLI binary is $ONEBEACON_CLI, else target/release/onebeacon of this clone
(`cargo build --release` makes it).
"""

import json
import os
import struct
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import onebeacon

REPO = Path(__file__).resolve().parents[3]
PLAZA = REPO / "data" / "plaza" / "plaza1.toml"

SHORT = {
    "name": "short",
    "description": "two minutes of the garin2024 mission",
    "mission": {"duration_s": 120.0},
    "sweep": {"t_com_s": [3.0, 9.0]},
}


@pytest.fixture(scope="session")
def cli():
    path = Path(os.environ.get("ONEBEACON_CLI", REPO / "target" / "release" / "onebeacon"))
    if not os.access(path, os.X_OK):
        pytest.fail(f"{path}: no onebeacon CLI to compare with; run `cargo build --release` or set ONEBEACON_CLI")

    def run(*args, stdin=None, ok=True):
        p = subprocess.run([str(path), *map(str, args)], capture_output=True, text=True, input=stdin)
        if ok:
            assert p.returncode == 0, p.stderr
        return p

    return run


def short_file(tmp_path):
    p = tmp_path / "short.toml"
    p.write_text(onebeacon.Scenario.from_dict(SHORT).to_toml())
    return p


# --- scenarios -----------------------------------------------------------------------


def test_scenario_dict_round_trip():
    for info in onebeacon.scenarios():
        s = onebeacon.Scenario.builtin(info["name"])
        assert s.kind == info["kind"] and s.name == info["name"]
        d = s.to_dict()
        assert onebeacon.Scenario.from_dict(d) == s
        assert onebeacon.Scenario.from_toml(s.to_toml()) == s
        # the dict is plain data: it survives JSON
        assert onebeacon.Scenario.from_dict(json.loads(json.dumps(d))) == s
    # an edited dict is another scenario, with the edit in it
    d = onebeacon.Scenario.builtin("garin2024").to_dict()
    d["seed"] = 99
    d["sweep"]["t_com_s"] = [4.0]
    edited = onebeacon.Scenario.from_dict(d)
    assert edited != onebeacon.Scenario.builtin("garin2024")
    assert edited.seed == 99 and edited.cells == [{"t_com_s": 4.0}]
    # a partial dict takes the defaults, as a partial file does
    short = onebeacon.Scenario.from_dict(SHORT)
    assert short.kind == "fixed_beacon" and short.cells == [{"t_com_s": 3.0}, {"t_com_s": 9.0}]
    # numpy values are taken as the numbers they hold
    d = dict(SHORT, mission={"duration_s": np.float64(120.0)}, sweep={"t_com_s": np.array([3.0, 9.0])})
    assert onebeacon.Scenario.from_dict(d) == short
    one = dict(SHORT, seed=np.int64(4), sweep={"t_com_s": np.array([9.0])})
    assert onebeacon.Scenario.from_dict(one).cells == [{"t_com_s": 9.0}]
    assert onebeacon.Scenario.from_dict(one).seed == 4


def test_scenario_from_a_name_a_path_or_a_dict_is_the_same(tmp_path):
    p = short_file(tmp_path)
    assert onebeacon.Scenario.from_file(p) == onebeacon.Scenario.from_dict(SHORT)
    assert onebeacon.mc(p, runs=2) == onebeacon.mc(SHORT, runs=2) == onebeacon.mc(str(p), runs=2)


# --- errors --------------------------------------------------------------------------


def cli_error(cli, *args):
    p = cli(*args, ok=False)
    assert p.returncode == 2, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    return lines[0].removeprefix("error: ")


def test_errors_are_exceptions_with_the_cli_messages(cli, tmp_path):
    assert issubclass(onebeacon.InputError, ValueError)
    with pytest.raises(onebeacon.InputError) as e:
        onebeacon.mc("no-such-scenario")
    assert str(e.value) == cli_error(cli, "mc", "no-such-scenario")

    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\n[mission]\nduration_s = -5.0\n')
    with pytest.raises(onebeacon.InputError) as e:
        onebeacon.Scenario.from_file(bad)
    assert str(e.value) == cli_error(cli, "mc", bad)
    assert "mission.duration_s" in str(e.value) and "\n" not in str(e.value)

    typo = tmp_path / "typo.toml"
    typo.write_text('name = "typo"\n[mision]\nduration_s = 5.0\n')
    with pytest.raises(onebeacon.InputError) as e:
        onebeacon.run(typo)
    assert str(e.value) == cli_error(cli, "run", typo)

    with pytest.raises(onebeacon.InputError, match="mission.duration_s"):
        onebeacon.Scenario.from_dict({"name": "x", "mission": {"duration_s": "long"}})
    with pytest.raises(onebeacon.InputError, match="not a finite number"):
        onebeacon.Scenario.from_dict({"name": "x", "mission": {"duration_s": float("nan")}})
    with pytest.raises(onebeacon.InputError, match="runs"):
        onebeacon.mc(SHORT, runs=0)
    with pytest.raises(onebeacon.InputError, match="expected a built-in name"):
        onebeacon.mc(42)
    with pytest.raises(onebeacon.InputError) as e:
        onebeacon.replay(PLAZA, beacons=[12345])
    assert str(e.value).startswith("beacons 12345: not a beacon of the log")


# --- run: numpy arrays -----------------------------------------------------------------


def read_csv(path):
    lines = Path(path).read_text().splitlines()
    header = lines[0].split(",")
    rows = [[float(x) if x else np.nan for x in line.split(",")] for line in lines[1:]]
    return header, np.array(rows)


def test_run_gives_float64_columns_equal_to_the_csv(cli, tmp_path):
    traj, summary = onebeacon.run(SHORT, seed=3, run=1)
    cli("run", short_file(tmp_path), "--seed", 3, "--run", 1, "--out", tmp_path / "run")
    header, csv = read_csv(tmp_path / "run" / "trajectory.csv")
    assert list(traj) == header
    n = csv.shape[0]
    for i, (name, column) in enumerate(traj.items()):
        assert isinstance(column, np.ndarray) and column.dtype == np.float64 and column.shape == (n,), name
        # the CSV rounds to 0.01 s, 0.001 deg, 0.1 mm
        np.testing.assert_allclose(column, csv[:, i], atol=6e-3, rtol=0, equal_nan=True, err_msg=name)
    assert summary == json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["seed"] == 3 and summary["run"] == 1


# --- mc: the CLI's cells, bit for bit ----------------------------------------------------


def test_mc_cells_are_the_cli_json_bit_for_bit(cli, tmp_path):
    ticks = []
    cells = onebeacon.mc(SHORT, runs=5, seed=8, progress=lambda done, total: ticks.append((done, total)))
    out = json.loads(cli("mc", short_file(tmp_path), "--runs", 5, "--seed", 8, "--json").stdout)
    assert cells == out["cells"]
    assert len(cells) == 2 * len(onebeacon.Scenario.from_dict(SHORT).tracks)
    # the callback saw the end, in order
    assert ticks[-1] == (10, 10) and all(a[0] <= b[0] for a, b in zip(ticks, ticks[1:]))
    # threads do not change a bit
    assert onebeacon.mc(SHORT, runs=5, seed=8, threads=1) == cells


def test_mc_releases_the_gil():
    long = dict(SHORT, mission={"duration_s": 1500.0})
    done = threading.Event()
    worker = threading.Thread(target=lambda: (onebeacon.mc(long, runs=150, threads=1), done.set()))
    start = time.perf_counter()
    worker.start()
    spins = 0
    while not done.is_set():
        spins += 1
        time.sleep(0.001)
    worker.join()
    elapsed = time.perf_counter() - start
    # with the GIL held for the whole mc this thread would not run until it ended
    assert elapsed > 0.2, elapsed
    assert spins > 50 and spins > 0.1 * elapsed / 0.001, (spins, elapsed)


def test_a_raising_progress_callback_raises():
    def boom(done, total):
        raise RuntimeError("stop")

    with pytest.raises(RuntimeError, match="stop"):
        onebeacon.mc(SHORT, runs=2, progress=boom)


# --- replay and the navigator step by step -------------------------------------------------


def test_replay_summary_is_the_cli_json(cli, tmp_path):
    traj, summary = onebeacon.replay(PLAZA)
    out = json.loads(cli("replay", PLAZA, "--json", "--out", tmp_path / "r").stdout)
    for d in (summary, out):
        d.pop("wall_s")
    assert summary == out
    assert traj["t_s"].dtype == np.float64 and traj["t_s"].ndim == 1
    assert all(c.shape == traj["t_s"].shape for c in traj.values())


def test_smooth_is_the_cli_smoother(cli, tmp_path):
    poses, summary = onebeacon.smooth(PLAZA, beacons=[5])
    out = json.loads(cli("smooth", PLAZA, "--beacons", "5", "--json", "--out", tmp_path / "s").stdout)
    line = next(e for e in out["estimators"] if e["name"] == "smoother")
    for d in (summary, line):
        for k in ("build_s", "solve_s"):
            d.pop(k)
    assert summary == line
    assert poses["t_s"].shape == poses["north_m"].shape and poses["t_s"].size > 9000
    assert np.all(poses["sigma_north_m"] > 0)
    with pytest.raises(onebeacon.InputError, match="kernel nope: not a kernel"):
        onebeacon.smooth(PLAZA, kernel="nope")


def test_rts_is_the_cli_rts_lines(cli, tmp_path):
    runs = onebeacon.rts(PLAZA, beacons=[5])
    out = json.loads(cli("smooth", PLAZA, "--beacons", "5", "--json", "--out", tmp_path / "s").stdout)
    lines = {e["name"]: e for e in out["estimators"] if e["name"].endswith("+rts")}
    assert sorted(f"{name}+rts" for name in runs) == sorted(lines)
    assert "dead-reckoning" not in runs
    estimates, summary = runs["ekf-cal"]
    assert summary == lines["ekf-cal+rts"]
    assert np.all(np.diff(estimates["t_s"]) >= 0) and np.all(estimates["sigma_north_m"] > 0)
    with pytest.raises(onebeacon.InputError, match="beacons 9: not a beacon"):
        onebeacon.rts(PLAZA, beacons=[9])


def test_navigator_step_by_step_equals_the_cli_replay(cli, tmp_path):
    items = cli("replay", PLAZA, "--print-stream").stdout.splitlines()
    summary = json.loads(cli("replay", PLAZA, "--json", "--out", tmp_path / "r").stdout)
    nav = onebeacon.Navigator(PLAZA)
    assert nav.names == [e["name"] for e in summary["estimators"]]
    outputs = 0
    for i, line in enumerate(items):
        # half the items as dicts, half as JSON lines
        out = nav.feed(json.loads(line) if i % 2 else line)
        outputs += out is not None
    assert outputs > 20_000 and nav.started
    last = out["estimates"]
    for s, e in zip(summary["estimators"], last):
        assert s["name"] == e["name"]
        for k in ("x_m", "y_m", "heading_rad"):
            assert s["final"][k] == e[k], (s["name"], k)
    # the estimates as arrays: NED (plaza is ENU: north is its y)
    for s, e in zip(summary["estimators"], nav.estimates()):
        p, cov = e["position_ned_m"], e["covariance_m2"]
        assert p.dtype == np.float64 and p.shape == (3,) and cov.shape == (2, 2)
        assert (p[0], p[1]) == (s["final"]["y_m"], s["final"]["x_m"])
        assert np.allclose(cov, cov.T) and np.all(np.linalg.eigvalsh(cov) > 0)


def test_a_bad_item_raises_and_leaves_the_navigator_alone():
    good = onebeacon.Navigator(PLAZA)
    fed = onebeacon.Navigator(PLAZA)
    stream = [
        {"t_s": 0.0, "kind": "ground_truth", "x_m": 1.0, "y_m": 2.0, "heading_rad": 0.3},
        {"t_s": 1.0, "kind": "odometry", "distance_m": 0.5, "heading_change_rad": 0.01},
        {"t_s": 2.0, "kind": "odometry", "distance_m": 0.5, "heading_change_rad": 0.01},
    ]
    with pytest.warns(UserWarning):
        onebeacon.Navigator(PLAZA).feed({"t_s": 0.0, "kind": "odometry", "distance_m": 0.5, "heading_change_rad": 0.0})
    for item in stream[:2]:
        good.feed(item)
        fed.feed(item)
    for bad, why in [
        ({"t_s": 1.5, "kind": "range"}, "beacon"),
        ({"t_s": 1.5, "kind": "odometry", "distance_m": "far", "heading_change_rad": 0.0}, "distance_m"),
        ({"t_s": 1.5, "kind": "teleport"}, "unknown kind"),
        ("not json", "not a JSON object"),
        ({"t_s": 0.5, "kind": "odometry", "distance_m": 0.5, "heading_change_rad": 0.0}, "screened"),
    ]:
        with pytest.raises(onebeacon.InputError, match=why):
            fed.feed(bad)
    a, b = good.feed(stream[2]), fed.feed(stream[2])
    assert a["estimates"] == b["estimates"] and a["line"] == 3 and b["line"] == 8
    for a, b in zip(good.estimates(), fed.estimates()):
        np.testing.assert_array_equal(a["position_ned_m"], b["position_ned_m"])
        np.testing.assert_array_equal(a["covariance_m2"], b["covariance_m2"])


# --- dsp.process on arrays -------------------------------------------------------------------


def read_float_wav(path):
    """A float32 multichannel WAV (what `dsp simulate` writes) as (channels x n, fs)."""
    data = Path(path).read_bytes()
    assert data[:4] == b"RIFF" and data[8:12] == b"WAVE"
    pos, fmt, samples = 12, None, None
    while pos + 8 <= len(data):
        tag, size = data[pos : pos + 4], struct.unpack("<I", data[pos + 4 : pos + 8])[0]
        body = data[pos + 8 : pos + 8 + size]
        if tag == b"fmt ":
            fmt = struct.unpack("<HHIIHH", body[:16])
        elif tag == b"data":
            samples = np.frombuffer(body, dtype="<f4")
        pos += 8 + size + (size & 1)
    code, channels, fs, _, _, bits = fmt
    assert bits == 32 and code in (3, 0xFFFE), fmt
    return samples.reshape(-1, channels).T, fs


def test_dsp_process_on_arrays_equals_the_cli(cli, tmp_path):
    wav = tmp_path / "ping.wav"
    cli("dsp", "simulate", "--out", wav)
    truth = json.loads(wav.with_suffix(".json").read_text())
    expected = json.loads(cli("dsp", "process", wav, "--json").stdout)
    samples, fs = read_float_wav(wav)
    got = onebeacon.dsp.process(samples, fs)
    assert got == expected
    assert got["detected"] and abs(got["range_m"] - truth["range_m"]) < 1.0
    # any real dtype is taken
    assert onebeacon.dsp.process(samples.astype(np.float32), fs) == expected
    with pytest.raises(onebeacon.InputError, match="rows"):
        onebeacon.dsp.process(samples[:2], fs)
    with pytest.raises(onebeacon.InputError, match="fs"):
        onebeacon.dsp.process(samples, -1.0)
    with pytest.raises(onebeacon.InputError, match="pulse"):
        onebeacon.dsp.process(samples[:, :10], fs)


# --- hostile and careless input ------------------------------------------------------


def nested(depth, make):
    inner = make()
    for _ in range(depth):
        inner = make(inner)
    return inner


def test_deep_nesting_raises_instead_of_crashing():
    deep_dict = nested(20000, lambda x=None: {} if x is None else {"x": x})
    deep_list = nested(20000, lambda x=None: [] if x is None else [x])
    with pytest.raises(onebeacon.InputError, match="nested more than"):
        onebeacon.Scenario.from_dict(deep_dict)
    with pytest.raises(onebeacon.InputError, match="nested more than"):
        onebeacon.mc(dict(SHORT, sweep={"t_com_s": deep_list}), runs=1)
    nav = onebeacon.Navigator(PLAZA)
    with pytest.raises(onebeacon.InputError, match="nested more than"):
        nav.feed({"t": 0.0, "kind": "odometry", "extra": deep_dict})
    # a scenario's real depth passes
    assert onebeacon.Scenario.from_dict(SHORT).name == "short"


def test_a_list_where_a_table_belongs_raises():
    for bad in (dict(SHORT, mission=[1.0, 2.0]), dict(SHORT, comms=[])):
        with pytest.raises(onebeacon.InputError, match="must be a table"):
            onebeacon.Scenario.from_dict(bad)
    with pytest.raises(onebeacon.InputError, match="path of a TOML file or a dict"):
        onebeacon.dsp.process(np.zeros((5, 100)), 37500.0, config=[1, 2])


def test_memory_budget_refuses_before_any_work(monkeypatch):
    monkeypatch.setenv("ONEBEACON_MEMORY_GIB", "0.01")
    for call in (lambda: onebeacon.mc(SHORT, runs=2), lambda: onebeacon.run(SHORT), lambda: onebeacon.replay(PLAZA)):
        with pytest.raises(onebeacon.InputError, match="memory budget is 0.0 GB"):
            call()
    monkeypatch.setenv("ONEBEACON_MEMORY_GIB", "lots")
    with pytest.raises(onebeacon.InputError, match="ONEBEACON_MEMORY_GIB"):
        onebeacon.mc(SHORT, runs=1)


def test_the_navigators_memory_budget_refuses_before_any_filter(monkeypatch, tmp_path):
    # 1000 tracked AUVs with a 5e5-particle filter each: about 48 GB (single-precision
    # particles, issue 57), refused in the constructor (cfb7f93 built them and the kernel
    # killed the interpreter)
    tracked = '[[tracked]]\nfrom = "given"\nt0_s = 0.0\nx_m = 50.0\ny_m = 0.0\nheading_deg = 90.0\n' * 1000
    config = tmp_path / "fleet.toml"
    config.write_text('name = "asv"\nframe = "ned"\n' + tracked + '[[estimators]]\nkind = "pf"\nparticles = 500000\n')
    monkeypatch.setenv("ONEBEACON_MEMORY_GIB", "16")
    with pytest.raises(onebeacon.InputError, match="would hold about 48.1 GB.*for 1000 vehicle"):
        onebeacon.Navigator(config)
    monkeypatch.setenv("ONEBEACON_MEMORY_GIB", "0.01")
    with pytest.raises(onebeacon.InputError, match="memory budget is 0.0 GB"):
        onebeacon.Navigator(PLAZA)


@pytest.fixture
def sigint():
    """Python's own Ctrl-C handler for the test: a process started in the background
    of a shell inherits SIGINT ignored, and `_thread.interrupt_main` then does nothing
    (the test would wait for 100000 runs)."""
    import signal

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_ctrl_c_stops_mc_and_raises_keyboard_interrupt(sigint):
    import _thread

    long = dict(SHORT, mission={"duration_s": 1500.0})
    timer = threading.Timer(0.5, _thread.interrupt_main)
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        onebeacon.mc(long, runs=100000, threads=1)
    elapsed = time.perf_counter() - start
    # 100000 runs of 25 min each take hours; stopped, only the run under way finishes
    assert elapsed < 5.0, elapsed


def long_log(tmp_path, rows):
    """A log of `rows` odometry rows (0.1 s, 0.1 m each, a slow turn) with a ground-truth
    row each: a replay of about a second per 200 000 rows."""
    t = np.arange(rows) * 0.1
    np.savetxt(tmp_path / "odo.csv", np.column_stack([t, np.full(rows, 0.1), np.full(rows, 1e-3)]),
               delimiter=",", header="t,d,dh", comments="", fmt="%.3f")
    np.savetxt(tmp_path / "truth.csv", np.column_stack([t, np.zeros(rows), np.zeros(rows), np.zeros(rows)]),
               delimiter=",", header="t,x,y,h", comments="", fmt="%.3f")
    log = tmp_path / "long.toml"
    log.write_text(
        'name = "long"\nframe = "ned"\n'
        '[[source]]\nkind = "odometry"\nfile = "odo.csv"\ntime = "t"\ndistance = "d"\nheading_change = "dh"\n'
        '[[source]]\nkind = "ground_truth"\nfile = "truth.csv"\ntime = "t"\nx = "x"\ny = "y"\nheading = "h"\n'
        '[[estimators]]\nname = "dr"\nkind = "dead-reckoning"\n'
    )
    return log


@pytest.mark.parametrize("call", ["replay", "smooth"])
def test_ctrl_c_during_a_log_raises_keyboard_interrupt(tmp_path, call, sigint):
    # cfb7f93 ignored Ctrl-C here, then raised a PanicException after the whole work
    import _thread

    # the smoother is not stopped mid-solve: it raises when its solve is done
    log = long_log(tmp_path, 600_000 if call == "replay" else 60_000)
    timer = threading.Timer(0.3, _thread.interrupt_main)
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        getattr(onebeacon, call)(log)
    elapsed = time.perf_counter() - start
    if call == "replay":
        # the replay stops at the next row; unstopped it takes about 3 s here
        assert elapsed < 1.5, elapsed


def test_dsp_process_takes_real_numbers_only_and_one_capture(cli, tmp_path):
    wav = tmp_path / "ping.wav"
    cli("dsp", "simulate", "--out", wav)
    samples, fs = read_float_wav(wav)
    for bad in (samples.astype(np.complex128), samples.astype(object), samples.astype(str)):
        with pytest.raises(onebeacon.InputError, match="dtype"):
            onebeacon.dsp.process(bad, fs)
    longer = np.concatenate([samples, np.zeros((samples.shape[0], 1))], axis=1)
    with pytest.raises(onebeacon.InputError, match="capture.samples"):
        onebeacon.dsp.process(longer, fs)
    with pytest.raises(onebeacon.InputError, match="dimensions"):
        onebeacon.dsp.process(samples[np.newaxis], fs)


def test_the_navigator_gives_its_controllers_command(tmp_path):
    # a surface vehicle tracking one AUV by USBL, holding its home point (the static
    # baseline: the path from where it is to home, whatever the AUV does)
    config = tmp_path / "asv.toml"
    config.write_text(
        'name = "asv"\nframe = "ned"\n'
        '[[tracked]]\nfrom = "given"\nt0_s = 0.0\nx_m = 50.0\ny_m = 0.0\nheading_deg = 90.0\ndepth_m = 20.0\n'
        '[[estimators]]\nkind = "bearing"\n'
        '[controller]\nkind = "bearing"\nmode = "static"\nhome_x_m = 10.0\nhome_y_m = -20.0\n'
    )
    nav = onebeacon.Navigator(config)
    assert nav.command() is None
    # it decides on its own fixes only
    out = nav.feed({"t_s": 0.0, "kind": "report", "heading_rad": 1.57, "speed_m_s": 1.5, "depth_m": 20.0})
    assert out["decided"] is False and "command" not in out and out["estimates"][0]["name"] == "bearing"
    out = nav.feed({"t_s": 1.0, "kind": "own_fix", "x_m": 3.0, "y_m": 4.0, "heading_rad": 0.0, "speed_m_s": 1.0})
    assert out["decided"] is True
    expected = {"kind": "path", "from_x_m": 3.0, "from_y_m": 4.0, "to_x_m": 10.0, "to_y_m": -20.0}
    assert out["command"] == expected and nav.command() == expected
