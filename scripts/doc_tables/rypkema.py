"""docs/reproductions/rypkema.md's tables: inverted USBL, a fleet commanded by chirps."""

import functools
import json
import re

from .common import PRESETS, RUNS, cli, cli_on_toml, figure, header


# rypkema Table 3: the 2-norm error's 68 % / 95 %, m, all six missions, real data
# against the LBL reference
RYPKEMA_PAPER = "7.89 / 22.74"


RYPKEMA_AUVS = ["platypus", "quokka", "wombat"]


@functools.cache
def fleet(scenario, campaign, quick, reference=False):
    """The error percentiles by label (`fleet/iusbl`, `platypus/iusbl`, ...) of `onebeacon
    fleet SCENARIO --runs N --json`, N from RUNS[campaign]; `reference` adds the 3.9 m LBL
    reference of the -sea scenarios (`[reference] sigma_m`) to a clean one. --quick draws
    the pings the abstract way (`signal.model = "abstract"`). Run once per script run."""
    runs = RUNS[campaign][0 if quick else 1]
    toml = cli("scenarios", "--show", scenario)
    if quick:
        toml = PRESETS.abstract_pings(toml)
    if reference:
        toml += "\n[reference]\nsigma_m = 3.9\n"
    return fleet_statistics(toml, runs)


def fleet_statistics(toml, runs):
    """The error percentiles by label (`fleet/iusbl`, `platypus/iusbl`, ...) of `onebeacon
    fleet FILE --runs RUNS --json` on the scenario text `toml` (its plots and tracks to a
    temporary directory: `fleet` writes them even with --json)."""
    stats = json.loads(cli_on_toml("fleet", toml, "--runs", str(runs), "--json", out=True))["statistics"]
    return {p["label"]: p for p in stats["tracks"] + stats["fleet"]}


def percent_cell(p, digits=None):
    """'68 % / 95 %' of an error percentile, each a figure()."""
    return f"{figure(p['p68_m'], digits)} / {figure(p['p95_m'], digits)}"


def fleet_row(label, stats, key, bold=False, digits=None):
    """A row of the fleet tables: `label`, then `key`'s percent_cell in each mission's
    `stats`, in bold when `bold`."""
    cells = [percent_cell(s[key], digits) for s in stats]
    return f"| {label} | " + " | ".join(f"**{c}**" if bold else c for c in cells) + " |"


def rypkema(quick):
    """docs/reproductions/rypkema.md: `onebeacon fleet rypkema-m1|m6 --runs 2`: the
    2-norm error while submerged, 68 % / 95 %, m, per AUV and for the fleet."""
    missions = ("rypkema-m1", "rypkema-m6")
    stats = [fleet(m, "rypkema", quick) for m in missions]
    rows = header("", *missions)
    auvs = " / ".join(RYPKEMA_AUVS)
    rows.append(f"| {auvs}, iusbl | " + " | ".join(
        ", ".join(percent_cell(s[f"{a}/iusbl"]) for a in RYPKEMA_AUVS) for s in stats) + " |")
    rows += [fleet_row("fleet, iusbl (factored)", stats, "fleet/iusbl", bold=True),
             fleet_row("fleet, iusbl-joint (same likelihoods, no factoring)", stats, "fleet/iusbl-joint"),
             fleet_row("fleet, dead reckoning", stats, "fleet/dead-reckoning")]
    rows.append(f"| paper, Table 3 (all six missions, real data against LBL) | {RYPKEMA_PAPER} | |")
    return rows


def rypkema_sea(quick):
    """docs/reproductions/rypkema.md, rypkema-m1-sea and rypkema-m6-sea: the fleet's iusbl error,
    68 % / 95 %, m, against the truth, against the 3.9 m reference alone and with the sea
    (`onebeacon fleet rypkema-m1-sea|m6-sea`), and dead reckoning in the -sea runs."""
    missions = ("rypkema-m1", "rypkema-m6")
    truth = [fleet(m, "rypkema", quick) for m in missions]
    reference = [fleet(m, "rypkema-reference", quick, reference=True) for m in missions]
    sea = [fleet(f"{m}-sea", "rypkema-sea", quick) for m in missions]
    n = {k: RUNS[k][1] for k in ("rypkema", "rypkema-reference", "rypkema-sea")}
    return header("", *missions) + [
        fleet_row(f"against the truth (the reproduction above, {n['rypkema']} runs)", truth, "fleet/iusbl",
                  digits=2),
        fleet_row(f"against the 3.9 m reference, no sea (`[reference]` alone, {n['rypkema-reference']} runs)",
                  reference, "fleet/iusbl", digits=2),
        fleet_row(f"rypkema-*-sea: the reference and the sea ({n['rypkema-sea']} runs)", sea, "fleet/iusbl",
                  bold=True, digits=2),
        f"| paper, Table 3 (all six missions, against LBL) | {RYPKEMA_PAPER} | |",
        fleet_row("dead reckoning in the -sea runs", sea, "fleet/dead-reckoning", digits=2)]


def rypkema_nees(quick):
    """docs/reproductions/rypkema.md, consistency: each estimator's mean NEES against the
    truth (pooled over every run and AUV), from the runs of the two tables above, with
    the chi-square band of as many draws (95 %)."""
    missions = ("rypkema-m1", "rypkema-m6")
    runs = [fleet(m, "rypkema", quick) for m in missions] + [fleet(f"{m}-sea", "rypkema-sea", quick)
                                                            for m in missions]
    n = {k: RUNS[k][1] for k in ("rypkema", "rypkema-sea")}
    rows = header("", *(f"{m} ({n['rypkema']} runs)" for m in missions),
                  *(f"{m}-sea ({n['rypkema-sea']} runs)" for m in missions))
    for label, key in (("iusbl (factored)", "fleet/iusbl"), ("iusbl-joint", "fleet/iusbl-joint"),
                       ("dead reckoning", "fleet/dead-reckoning")):
        rows.append(f"| {label} | " + " | ".join(figure(r[key]["nees_mean"]) for r in runs) + " |")
    rows.append("| band (95 %) | " + " | ".join(
        f"{figure(r['fleet/iusbl']['nees_band'][0])}-{figure(r['fleet/iusbl']['nees_band'][1])}" for r in runs) + " |")
    return rows


# rypkema-dead-reckoning: what moves dead reckoning to the paper's (label, [sea.sensors] keys,
# [sea.current] speed): the -sea preset as shipped, a compass deviation (all of the paper's
# 3 deg 1 sigma as one, amplitude 3 sqrt(2), and 3 deg), and the 5 cm/s current of 2026-12-03
DEAD_RECKONING_VARIANTS = [
    ("as shipped", "", None),
    ("+ a compass deviation of 3 deg (`sea.sensors.heading_deviation_deg`)", "heading_deviation_deg = 3.0", None),
    ("+ a compass deviation of 4.24 deg (the paper's 3 deg 1 sigma, all of it)", "heading_deviation_deg = 4.24",
     None),
    ("+ a current of 5 cm/s (for 2.6 mm/s)", "", "0.05"),
]


def fleet_variant(scenario, sensors, current, runs):
    """`fleet_statistics` of `onebeacon fleet SCENARIO` with its pings drawn the abstract
    way, `sensors` (TOML keys) as its `[sea.sensors]` and `current` (m/s, text, or None) as
    its `[sea.current]` speed."""
    toml = PRESETS.abstract_pings(cli("scenarios", "--show", scenario))
    if sensors:
        toml += f"\n[sea.sensors]\n{sensors}\n"
    if current:
        head, rest = toml.split("[sea.current]", 1)
        toml = head + "[sea.current]" + re.sub(r"(?m)^speed_m_s = [0-9.e-]+", f"speed_m_s = {current}", rest, count=1)
    return fleet_statistics(toml, runs)


def rypkema_dead_reckoning(quick):
    """docs/reproductions/rypkema.md: dead reckoning's error in rypkema-m1-sea and -m6-sea
    (pings drawn the abstract way, 8 runs) as shipped and with each candidate cause added:
    the fleet's iusbl and dead reckoning, 68 % / 95 %, m, and dead reckoning's mean NEES."""
    runs = RUNS["rypkema-dead-reckoning"][0 if quick else 1]
    missions = ("rypkema-m1-sea", "rypkema-m6-sea")
    rows = header("", *(f"{m}: {e}" for m in missions for e in ("iusbl", "dead reckoning (NEES)")))
    for label, sensors, current in DEAD_RECKONING_VARIANTS:
        cells = []
        for m in missions:
            f = fleet_variant(m, sensors, current, runs)
            dr = f["fleet/dead-reckoning"]
            cells += [percent_cell(f["fleet/iusbl"], 2), f"{percent_cell(dr, 2)} ({figure(dr['nees_mean'])})"]
        rows.append(f"| {label} | " + " | ".join(cells) + " |")
    return rows


# the tables of this module by the name that marks them in docs/
TABLES = {
    "rypkema": rypkema,
    "rypkema-sea": rypkema_sea,
    "rypkema-nees": rypkema_nees,
    "rypkema-dead-reckoning": rypkema_dead_reckoning,
}
