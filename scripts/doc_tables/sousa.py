"""docs/reproductions/sousa.md's tables: range-only EKF, the beacon on a guided ASV."""

import json
import re

from .common import ROOT, RUNS, header, mc, mc_text, paired_cell, spread, verdict_counts
from .sea import ablation


# sousa's thesis, Table 4.1 (approach A): mean error in m, stationary / lawn mower /
# circular / spiral ROV path, as printed (its "1,720" read as 1.720)
SOUSA_THESIS = {
    1: "0.810 / 0.689 / 0.575 / 1.970",
    5: "1.720 / 1.362 / 1.255 / 2.016",
    20: "1.820 / 1.482 / 1.488 / 2.530",
    50: "1.78 / 2.309 / 2.135 / 3.542",
}


SOUSA_PATHS = ["stationary", "lawnmower", "circular", "spiral"]


def sousa(quick):
    """docs/reproductions/sousa.md: `onebeacon mc sousa` (10 runs per cell), the range
    EKF's mean error under approach A beside Table 4.1."""
    cells = [c for c in mc("sousa", quick) if c["estimator"] == "range-ekf" and c["sweep"]["guidance"] == "A"]
    rows = header("depth", *(f"{p} A" for p in SOUSA_PATHS), "thesis A (stat / lawn / circ / spiral)")
    for depth in sorted({c["sweep"]["depth_m"] for c in cells}):
        by = {c["sweep"]["path"]: c for c in cells if c["sweep"]["depth_m"] == depth}
        ours = " | ".join(f"{by[p]['mean_error_m']:.3f}" for p in SOUSA_PATHS)
        rows.append(f"| {depth:g} m | {ours} | {SOUSA_THESIS[round(depth)]} |")
    return rows


def sousa_guidance(quick):
    """docs/reproductions/sousa.md: what the guidance buys, `scripts/paired.py DIR/mc.json
    --vary guidance --base static|circle --estimator E` summed over the 16 (path, depth)
    cells of sousa (range-ekf) and sousa-sea (range-ekf-sea), 10 runs per cell: the cells
    where the guidance's run mean error is lower / tied / higher than the base's (95 %
    interval of the paired difference), and the least and greatest mean difference."""
    rows = header("world, estimator", "guidance - base", "cells lower / tie / higher",
                  "mean differences over the cells, m")
    for world, estimator in (("sousa", "range-ekf"), ("sousa-sea", "range-ekf-sea")):
        cells = {}
        for c in mc(world, quick):
            if c["estimator"] == estimator:
                cells[(c["sweep"]["path"], c["sweep"]["depth_m"], c["sweep"]["guidance"])] = c
        where = sorted({k[:2] for k in cells})
        for guidance, base in (("A", "static"), ("B", "static"), ("circle", "static"), ("A", "circle"), ("B", "circle")):
            counts, means = verdict_counts((cells[w + (guidance,)], cells[w + (base,)]) for w in where)
            rows.append(f"| {world}, {estimator} | {guidance} - {base} | {counts} "
                        f"| {min(means):+.3f} to {max(means):+.3f} |")
    return rows


def sousa_sea(quick):
    """docs/reproductions/sousa.md, sousa-sea: `onebeacon mc sousa-sea` (10 runs per cell): over
    the 16 cells of each guidance, the least and greatest mean error and NEES of the
    thesis's filter and of range-ekf-sea, range-ekf-sea's runs worse than dead reckoning
    (paired by run), and dead reckoning's errors."""
    cells = mc("sousa-sea", quick)
    rows = header(
        "guidance",
        "thesis's range EKF",
        "its NEES",
        "range-ekf-sea",
        "its NEES",
        "range-ekf-sea runs worse than dead reckoning",
        "dead reckoning",
    )
    for g in ("A", "B", "circle", "static"):
        thesis, sea, dr = (
            [c for c in cells if c["sweep"]["guidance"] == g and c["estimator"] == e]
            for e in ("range-ekf", "range-ekf-sea", "dead-reckoning")
        )
        dr_by = {json.dumps(c["sweep"], sort_keys=True): c["run_mean_errors_m"] for c in dr}
        pairs = [(a, b) for c in sea for a, b in zip(c["run_mean_errors_m"], dr_by[json.dumps(c["sweep"], sort_keys=True)])]
        worse = sum(a > b for a, b in pairs)
        rows.append(
            f"| {g} | {spread([c['mean_error_m'] for c in thesis], 1)} | {spread([c['nees_mean'] for c in thesis], 0)} "
            f"| {spread([c['mean_error_m'] for c in sea], 2)} | {spread([c['nees_mean'] for c in sea], 2)} "
            f"| {worse} / {len(pairs)} | {spread([c['mean_error_m'] for c in dr], 2)} |"
        )
    return rows


def sousa_pair(quick):
    """docs/reproductions/sousa.md, sousa-pair: `onebeacon mc sousa-pair` (10 runs per cell):
    each vehicle's range EKF, mean error (RMSE / its own PCRB), and dead reckoning; the
    second vehicle's EKF in each half of the mission."""
    cells = mc("sousa-pair", quick)
    rows = header(
        "guidance",
        "auv range-ekf",
        "auv dead reckoning",
        "auv2 range-ekf",
        "auv2 dead reckoning",
        "auv2 range-ekf first / second half",
    )
    for g in dict.fromkeys(c["sweep"]["guidance"] for c in cells):
        by = {(c["vehicle"], c["estimator"]): c for c in cells if c["sweep"]["guidance"] == g}
        cell = []
        for v in ("auv", "auv2"):
            e = by[(v, "range-ekf")]
            cell.append(f"{e['mean_error_m']:.2f} ({e['rmse_m'] / e['pcrb_rmse_m']:.2f})")
            cell.append(f"{by[(v, 'dead-reckoning')]['mean_error_m']:.2f}")
        e = by[("auv2", "range-ekf")]
        cell.append(f"{e['mean_error_first_half_m']:.2f} / {e['mean_error_second_half_m']:.2f}")
        rows.append(f"| {g} | " + " | ".join(cell) + " |")
    return rows


def sousa_pair_paired(quick):
    """docs/reproductions/sousa.md, sousa-pair: each vehicle's range EKF under a moving ASV
    against the static one, paired by run, m, with 95 % intervals (same campaign)."""
    cells = mc("sousa-pair", quick)
    by = {(c["vehicle"], c["sweep"]["guidance"]): c for c in cells if c["estimator"] == "range-ekf"}
    rows = header("vehicle", "A - static", "circle - static")
    for v in ("auv", "auv2"):
        rows.append(f"| {v} | {paired_cell(by[(v, 'A')], by[(v, 'static')])} | "
                    f"{paired_cell(by[(v, 'circle')], by[(v, 'static')])} |")
    return rows


def sousa_sea_ablation(quick):
    """docs/reproductions/sousa.md, sousa-sea: each error source alone, the base cell, 10 runs."""
    return ablation("sousa-sea", quick, [("range-ekf-sea", "range-ekf-sea"),
                    ("range-ekf", "range-ekf (the thesis's)"), ("dead-reckoning", "dead-reckoning")])


# sousa-spiral: the spiral's descent rates tried, m/s (sousa.toml's 0.005 first)
SPIRAL_DESCENTS = ("0.005", "0.02", "0.05")


def sousa_spiral(quick):
    """docs/reproductions/sousa.md: the conjecture that the thesis's spiral descends faster
    than ours, measured: scenarios/sousa.toml under approach A, circular and spiral paths
    from 1 m and 5 m, with each spiral descent rate; the range EKF's mean error and the
    spiral's minus the circle's, paired by run (10 runs)."""
    runs = RUNS["sousa-spiral"][0 if quick else 1]
    depths = (1.0, 5.0)
    rows = header("spiral descent, m/s (deeper after 2 h)", *(f"spiral from {d:g} m" for d in depths),
                  *(f"spiral - circle from {d:g} m [95 %]" for d in depths))
    for descent in SPIRAL_DESCENTS:
        toml = re.sub(r"(?m)^spiral_descent_m_s = [0-9.]+", f"spiral_descent_m_s = {descent}",
                      (ROOT / "scenarios/sousa.toml").read_text())
        toml = toml[:toml.index("[sweep]")] + (
            '[sweep]\npath = ["circular", "spiral"]\ndepth_m = [1.0, 5.0]\nguidance = ["A"]\n')
        cells = {(c["sweep"]["path"], c["sweep"]["depth_m"]): c
                 for c in mc_text(toml, runs) if c["estimator"] == "range-ekf"}
        rows.append(f"| {descent} ({float(descent) * 7200:.0f} m) | " + " | ".join(
            f"{cells[('spiral', d)]['mean_error_m']:.3f}" for d in depths) + " | " + " | ".join(
            paired_cell(cells[("spiral", d)], cells[("circular", d)], 3) for d in depths) + " |")
    return rows


# the tables of this module by the name that marks them in docs/
TABLES = {
    "sousa": sousa,
    "sousa-sea": sousa_sea,
    "sousa-sea-ablation": sousa_sea_ablation,
    "sousa-guidance": sousa_guidance,
    "sousa-pair": sousa_pair,
    "sousa-pair-paired": sousa_pair_paired,
    "sousa-spiral": sousa_spiral,
}
