"""The tables of `onebeacon sea-fit` (docs/logs.md, "The sea of a log"): what it finds on
the plaza logs, and how often its intervals cover a simulated sea's truth."""

import json
import os
import re
import subprocess
import sys

from .common import ROOT, cli, header

# seeds of the coverage table: (--quick, full)
SEEDS = (4, 200)


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


TABLES = {
    "sea-fit-plaza": sea_fit_plaza,
    "sea-fit-coverage": sea_fit_coverage,
}
