"""The tables of `onebeacon sea-fit` and `onebeacon twin` (docs/logs.md, "The sea of a
log", "The twin of a log"): what sea-fit finds on the plaza logs, how often its intervals
cover a simulated sea's truth, and how well each log's twin predicts the other's replay."""

import functools
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from .common import ROOT, cli, header

# seeds of the coverage table: (--quick, full)
SEEDS = (4, 200)
# runs of each twin: (--quick, full)
TWIN_RUNS = (8, 50)


def _fmt(v, digits):
    value = v["value"]
    lo_hi = v["interval"]
    if lo_hi is None:
        return f"{value:.{digits}f}"
    return f"{value:.{digits}f} [{lo_hi[0]:.{digits}f}, {lo_hi[1]:.{digits}f}]"


def sea_fit_plaza(quick):
    """`onebeacon sea-fit data/plaza/plazaN.toml --json`: per beacon the ranges' scale k,
    sigma and offset with their 95 % intervals; the odometry's turn scale."""
    del quick  # real data: the same figures at any count
    rows = header("log, beacon", "ranges", "scale k", "sigma, m", "offset, m", "multipath share")
    for n in (1, 2):
        j = json.loads(cli("sea-fit", str(ROOT / f"data/plaza/plaza{n}.toml"), "--json",
                           "--out", str(ROOT / f"target/reproduce/sea-fit-plaza{n}")))
        for r in j["ranges"]:
            mp = "none" if r["multipath_prob"]["value"] == 0 else _fmt(r["multipath_prob"], 2)
            rows.append(f"| plaza{n}, {r['beacon']} | {r['ranges']} | {_fmt(r['scale'], 4)} | "
                        f"{_fmt(r['sigma_m'], 2)} | {_fmt(r['bias_m'], 2)} | {mp} |")
        turn = j["odometry"]["turn_scale"] if j["odometry"] else None
        loss = j["loss_pooled"]
        rows.append(f"| plaza{n}, odometry and link | | turn k {_fmt(turn, 4) if turn else '-'} | | | "
                    f"lost {_fmt(loss['loss_prob'], 3) if loss else '- (no schedule)'} |")
    return rows


def sea_fit_coverage(quick):
    """The recovery test's table (crates/onebeacon-sim/src/seafit/tests.rs, `coverage_table`):
    per value, the share of seeds whose 95 % interval covers the simulated truth."""
    seeds = SEEDS[0 if quick else 1]
    env = dict(os.environ, ONEBEACON_SEAFIT_SEEDS=str(seeds))
    done = subprocess.run(
        ["cargo", "test", "--release", "--locked", "-p", "onebeacon-sim", "--lib",
         "seafit::tests::coverage_table", "--", "--ignored", "--nocapture"],
        cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit(f"reproduce: the sea-fit coverage test failed: {done.stderr.strip()[-2000:]}")
    return [line for line in done.stdout.splitlines() if re.match(r"^\|", line)]


@functools.cache
def _seas():
    """sea.toml of each plaza log, and the two mixed seas (one log's ranges with the other's
    odometry), by name."""
    seas = {}
    for n in (1, 2):
        out = ROOT / f"target/reproduce/twin-sea-plaza{n}"
        cli("sea-fit", str(ROOT / f"data/plaza/plaza{n}.toml"), "--json", "--out", str(out))
        seas[f"plaza{n}"] = (out / "sea.toml").read_text()
    def split(text):
        at = text.index("\n[sea.odometry]\n")
        return text[:at], text[at:]
    for a, b in (("plaza1", "plaza2"), ("plaza2", "plaza1")):
        seas[f"{a}'s ranges, {b}'s odometry"] = split(seas[a])[0] + split(seas[b])[1]
    return seas


@functools.cache
def _twin(log, sea, runs):
    """`onebeacon twin data/plaza/LOG.toml --sea SEA --runs RUNS --json`."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sea.toml"
        path.write_text(_seas()[sea])
        return json.loads(cli("twin", str(ROOT / f"data/plaza/{log}.toml"), "--sea", str(path),
                              "--runs", str(runs), "--seed", "1", "--json", "--out", str(Path(tmp) / "out")))


# (log, sea): the two predictions, the two in-sample twins, and the ranges alone carried over
TWINS = (
    ("plaza2", "plaza1"),
    ("plaza1", "plaza2"),
    ("plaza2", "plaza2"),
    ("plaza1", "plaza1"),
    ("plaza2", "plaza1's ranges, plaza2's odometry"),
    ("plaza1", "plaza2's ranges, plaza1's odometry"),
)


def twin_plaza(quick):
    """`onebeacon twin`: per (log, sea) the cells (beacon set x estimator) whose real RMSE lies
    within the twin's 5-95 % band, and whose real NEES is within 1.5x of its median."""
    runs = TWIN_RUNS[0 if quick else 1]
    rows = header("log", "sea fitted on", "runs", "RMSE within the band", "NEES within 1.5x", "twin, s")
    for log, sea in TWINS:
        j = _twin(log, sea, runs)
        a = j["agreement"]
        pct = lambda k, n: f"{a[k]} of {a[n]} ({100 * a[k] / a[n]:.0f} %)"
        rows.append(f"| {log} | {sea} | {runs} | {pct('rmse_within_band', 'cells')} | "
                    f"{pct('nees_within_factor', 'cells_with_nees')} | {j['wall_s']:.1f} |")
    return rows


def twin_plaza_cells(quick):
    """The cells of all four beacons of the two predictions: real RMSE and NEES beside the
    twin's median [5 %, 95 %]."""
    runs = TWIN_RUNS[0 if quick else 1]
    rows = header("log <- sea", "estimator", "real RMSE, m", "twin RMSE, m", "real NEES", "twin NEES")
    for log, sea in TWINS[:2]:
        for c in _twin(log, sea, runs)["cells"]:
            if len(c["beacons"]) < 4:
                continue
            t = c["twin"]
            band = lambda b: f"{b['median']:.2f} [{b['p5']:.2f}, {b['p95']:.2f}]"
            rows.append(f"| {log} <- {sea} | {c['estimator']} | {c['real']['rmse_m']:.2f} | {band(t['rmse_m'])} | "
                        f"{c['real']['nees']:.1f} | {band(t['nees'])} |")
    return rows


TABLES = {
    "sea-fit-plaza": sea_fit_plaza,
    "sea-fit-coverage": sea_fit_coverage,
    "twin-plaza": twin_plaza,
    "twin-plaza-cells": twin_plaza_cells,
}
