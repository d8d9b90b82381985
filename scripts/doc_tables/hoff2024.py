"""docs/reproductions/hoff2024.md's tables (and docs/scenarios.md's hoff2024-literal):
passive USBL, particle filter, the ASV's planner."""

import functools
import math
import re
import statistics

from .common import (PAIRED, ROOT, RUNS, blocks_kept, cli, figure, header, interval,
    mc, mc_text, nees_figure, paired_cell)
from .sea import ablation


@functools.cache
def hoff2024_campaign(scenario, quick):
    """The cells of `onebeacon mc SCENARIO` (hoff2024 and its variants) at RUNS' count, run
    once per script run; --quick runs 15-minute missions with 5e4 particles."""
    if not quick:
        return mc(scenario, quick)
    toml = cli("scenarios", "--show", scenario)
    toml = re.sub(r"(?m)^duration_s = \d+", "duration_s = 900", toml)
    toml = re.sub(r"(?m)^particles = \d+", "particles = 50000", toml)
    return mc_text(toml, RUNS[scenario][0])


def hoff2024_cells(scenario, quick, vehicle="auv"):
    """`hoff2024_campaign`'s cells of one vehicle by (guidance swept or None, estimator)."""
    return {(c["sweep"].get("guidance"), c["estimator"]): c for c in hoff2024_campaign(scenario, quick)
            if c["vehicle"] == vehicle}


def hoff2024(quick):
    """docs/reproductions/hoff2024.md: `onebeacon mc hoff2024` and `mc hoff2024-kinematic`
    (20 runs per cell, 1 h, 5e5 particles; 18 and 17 min on 2 cores): per guidance the particle
    filter's mean error (RMSE / PCRB), mean NEES (95 % band) and second-half / first-half
    error, the EKF's and UKF's mean error (NEES), and the kinematic world's."""
    dynamic, kinematic = hoff2024_cells("hoff2024", quick), hoff2024_cells("hoff2024-kinematic", quick)
    rows = header("guidance", "pf mean (RMSE / PCRB)", "pf NEES (95 % band)", "pf h2/h1", "EKF mean (NEES)",
                  "UKF mean (NEES)", "kinematic: pf mean (RMSE / PCRB), NEES, EKF (NEES)")
    for g in ("det", "max-eig", "static", "circle", "offset"):
        pf, ekf, ukf = (dynamic[(g, e)] for e in ("pf", "bearing", "bearing-ukf"))
        kpf, kekf = kinematic[(g, "pf")], kinematic[(g, "bearing")]
        lo, hi = pf["nees_band"]
        rows.append(
            f"| {g} | {pf['mean_error_m']:.3f} ({pf['rmse_m']:.3f} / {pf['pcrb_rmse_m']:.3f}) "
            f"| {pf['nees_mean']:.2f} ({lo:.2f}-{hi:.2f}) "
            f"| {pf['mean_error_second_half_m'] / pf['mean_error_first_half_m']:.2f} "
            f"| {ekf['mean_error_m']:.3f} ({ekf['nees_mean']:.1f}) | {ukf['mean_error_m']:.3f} ({ukf['nees_mean']:.2f}) "
            f"| {kpf['mean_error_m']:.3f} ({kpf['rmse_m']:.3f} / {kpf['pcrb_rmse_m']:.3f}), {kpf['nees_mean']:.2f}, "
            f"{kekf['mean_error_m']:.3f} ({kekf['nees_mean']:.1f}) |")
    return rows


# hoff2024-paired: the planners against each other and against each baseline
HOFF_PAIRS = [("det", "max-eig"), ("det", "circle"), ("det", "offset"), ("det", "static"),
              ("max-eig", "circle"), ("max-eig", "offset"), ("max-eig", "static")]


def hoff2024_paired(quick):
    """docs/reproductions/hoff2024.md: the particle filter's run mean error under one
    guidance against another, paired by run (the same seed's draws), m, with 95 %
    intervals, from the campaigns of the hoff2024 table."""
    dynamic, kinematic = hoff2024_cells("hoff2024", quick), hoff2024_cells("hoff2024-kinematic", quick)
    rows = header("pf: guidance - guidance", "Otter (hoff2024)", "kinematic ASV (hoff2024-kinematic)")
    for a, b in HOFF_PAIRS:
        rows.append(f"| {a} - {b} | " + " | ".join(paired_cell(cells[(a, "pf")], cells[(b, "pf")], 3)
                                              for cells in (dynamic, kinematic)) + " |")
    return rows


def hoff2024_dynamics(quick):
    """docs/reproductions/hoff2024.md: what the Otter's and REMUS's dynamics change: per
    guidance, the particle filter's mean error in hoff2024 against hoff2024-kinematic (two
    worlds, so unpaired: Welch's 95 % interval), m, and their ratio."""
    dynamic, kinematic = hoff2024_cells("hoff2024", quick), hoff2024_cells("hoff2024-kinematic", quick)
    rows = header("guidance", "pf: dynamics - kinematic, m [95 %, Welch]", "ratio of the means")
    for g in ("det", "max-eig", "static", "circle", "offset"):
        a, b = dynamic[(g, "pf")], kinematic[(g, "pf")]
        m, h, _ = PAIRED.welch(a["run_mean_errors_m"], b["run_mean_errors_m"])
        rows.append(f"| {g} | {interval(m, h, 3)} | {a['mean_error_m'] / b['mean_error_m']:.2f} |")
    return rows


def hoff2024_consistency(quick):
    """docs/reproductions/hoff2024.md: `onebeacon mc hoff2024-consistency` (10 runs, 1 h, 5e4
    particles, det; 97 s): each filter's mean error, mean NEES (the particle filter's 95 %
    band), and its run mean error against the matched particle filter's, paired by run."""
    by = {e: c for (_, e), c in hoff2024_cells("hoff2024-consistency", quick).items()}
    lo, hi = by["pf"]["nees_band"]
    rows = header("estimator", "mean error, m", f"NEES (band {lo:.2f}-{hi:.2f})", "- pf, m")
    for name, c in by.items():
        digits = 3 if c["mean_error_m"] < 1 else 1
        against = "(the base)" if name == "pf" else paired_cell(c, by["pf"], digits)
        rows.append(f"| {name} | {figure(c['mean_error_m'], digits)} "
                    f"| {nees_figure(c['nees_mean'])} | {against} |")
    return rows


def hoff2024_current(quick):
    """docs/reproductions/hoff2024.md: `onebeacon mc hoff2024-current` (10 runs, 1 h, 5e4
    particles; 5 min): per guidance the particle filter's mean error, NEES and h2/h1, the
    EKF's mean error, and the particle filter against it under det, paired by run."""
    cells = hoff2024_cells("hoff2024-current", quick)
    rows = header("guidance", "pf mean error, m", "pf NEES", "pf h2/h1", "EKF mean error, m",
                  "pf: det - this guidance, m")
    for g in ("det", "circle", "offset"):
        pf, ekf = cells[(g, "pf")], cells[(g, "bearing")]
        against = "(the base)" if g == "det" else paired_cell(cells[("det", "pf")], pf, 3)
        rows.append(f"| {g} | {pf['mean_error_m']:.3f} | {pf['nees_mean']:.2f} "
                    f"| {pf['mean_error_second_half_m'] / pf['mean_error_first_half_m']:.2f} "
                    f"| {ekf['mean_error_m']:.3f} | {against} |")
    return rows


def hoff2024_pair(quick):
    """docs/reproductions/hoff2024.md: `onebeacon mc hoff2024-pair` (two AUVs 100 m apart,
    1e5 particles, 10 runs; 2 min): per guidance and AUV the particle filter's mean error,
    NEES and h2/h1, and its error against the static ASV's, paired by run."""
    rows = header("guidance", "AUV", "pf mean error, m", "pf NEES", "pf h2/h1", "pf: this guidance - static, m")
    for g in ("det", "max-eig", "static"):
        for vehicle in ("auv", "auv2"):
            cells = hoff2024_cells("hoff2024-pair", quick, vehicle)
            pf = cells[(g, "pf")]
            against = "(the base)" if g == "static" else paired_cell(pf, cells[("static", "pf")])
            rows.append(f"| {g} | {vehicle} | {pf['mean_error_m']:.2f} | {pf['nees_mean']:.2f} "
                        f"| {pf['mean_error_second_half_m'] / pf['mean_error_first_half_m']:.2f} | {against} |")
    return rows


# hoff2024-literal's filters: how each reads eq. 6, section 5's process noise and the
# filter noise
HOFF_LITERAL = [("pf-literal", "as printed", "as printed", "Table 1's filter column"),
                ("pf-eq6", "as printed", "scaled (onebeacon)", "matched"),
                ("pf-section5", "squared (onebeacon)", "as printed", "matched"),
                ("pf", "squared (onebeacon)", "scaled (onebeacon)", "matched")]


def hoff2024_literal(quick):
    """docs/scenarios.md: `onebeacon mc hoff2024-literal` (10 runs): each reading of the
    paper's equations, mean error, RMSE and mean NEES with its 95 % band."""
    by = {c["estimator"]: c for c in mc("hoff2024-literal", quick)}
    lo, hi = by["pf"]["nees_band"]
    rows = header("estimator", "eq. 6", "section 5's process noise", "filter noise", "mean error", "RMSE",
                  f"NEES (band {lo:.2f}-{hi:.2f})")
    for name, eq6, process, noise in HOFF_LITERAL:
        c = by[name]
        rows.append(f"| {name} | {eq6} | {process} | {noise} | {figure(c['mean_error_m'])} m | "
                    f"{figure(c['rmse_m'])} m | {nees_figure(c['nees_mean'])} |")
    return rows


def hoff2024_sea(quick):
    """docs/reproductions/hoff2024.md, hoff2024-sea: `onebeacon mc hoff2024-sea` (10 runs per cell):
    mean error over every run, m, mean NEES over every run, and the runs over 20 m."""
    cells = mc("hoff2024-sea", quick)
    estimators = ("pf", "pf-sea", "bearing-sea")
    labels = {"det": "det (the planner, driven by pf)", "circle": "circle (20 m about pf's belief)"}
    rows = header("guidance", *(x for e in estimators for x in (e, "its NEES")),
                  "runs > 20 m (" + " / ".join(estimators) + ")")
    for g in dict.fromkeys(c["sweep"]["guidance"] for c in cells):
        by = {c["estimator"]: c for c in cells if c["sweep"]["guidance"] == g}
        means = [sum(by[e]["run_mean_errors_m"]) / len(by[e]["run_mean_errors_m"]) for e in estimators]
        cell = [x for e, m in zip(estimators, means)
                for x in (f"{m:.{1 if m >= 10 else 2}f}", f"{by[e]['nees_mean_all_runs']:.3g}")]
        over = " / ".join(str(sum(r > 20.0 for r in by[e]["run_mean_errors_m"])) for e in estimators)
        rows.append(f"| {labels.get(g, g)} | " + " | ".join(cell) + f" | {over} |")
    return rows


def hoff2024_sea_paired(quick):
    """docs/reproductions/hoff2024.md, hoff2024-sea: paired by run (the same draws of the
    sea), m, 95 % intervals, from the hoff2024-sea table's campaign: the planner against
    each baseline for each filter, and under the planner each filter against pf."""
    cells = {(c["sweep"]["guidance"], c["estimator"]): c for c in mc("hoff2024-sea", quick)}
    estimators = ("pf", "pf-sea", "bearing-sea")
    rows = header("", *estimators)
    for base in ("static", "circle"):
        rows.append(f"| det - {base} | " + " | ".join(paired_cell(cells[("det", e)], cells[(base, e)])
                                                     for e in estimators) + " |")
    rows.append("| under det: the filter - pf | (the base) | " + " | ".join(
        paired_cell(cells[("det", e)], cells[("det", "pf")]) for e in estimators[1:]) + " |")
    return rows


def pf_sea_alone(floor):
    """scenarios/hoff2024-sea.toml with pf-sea its one estimator, told of the angle floor
    `floor` (deg, text), and its sweep removed: the planner's cell."""
    toml = blocks_kept(ROOT / "scenarios/hoff2024-sea.toml", lambda head, text: head != "sweep" and not (
        head == "estimators" and 'name = "pf-sea"' not in text))
    return re.sub(r"(?m)^usbl_floor_deg = [0-9.]+", f"usbl_floor_deg = {floor}", toml)


def hoff2024_sea_long(quick):
    """docs/reproductions/hoff2024.md, hoff2024-sea: pf-sea alone under the planner, 300 runs
    (scenarios/hoff2024-sea.toml with the other estimators and the sweep removed; 30 min
    missions), with its angle floor as shipped and at 1 deg: the run mean errors' mean,
    median and 95th percentile, the runs over 5 m and over 20 m with the 95 % upper bound
    of the share over 20 m, and the mean NEES over the runs that are not outliers and over
    every run, with its band."""
    runs = RUNS["hoff2024-sea-long"][0 if quick else 1]
    rows = header("usbl_floor_deg", "runs", "mean error, m", "median", "95th percentile", "runs over 5 m",
                  "runs over 20 m (95 % upper bound of the share)", "NEES (every run)", "NEES band")
    for floor, label in (("1.25", "1.25 (as shipped)"), ("1.0", "1.0")):
        (c,) = mc_text(pf_sea_alone(floor), runs, progress=not quick)
        errors = sorted(c["run_mean_errors_m"])
        n = len(errors)
        over = sum(e > 20.0 for e in errors)
        lo, hi = c["nees_band"]
        rows.append(f"| {label} | {n} | {figure(c['mean_error_m'])} | {figure(statistics.median(errors))} "
                    f"| {figure(errors[min(n - 1, math.ceil(0.95 * n) - 1)])} | {sum(e > 5.0 for e in errors)} "
                    f"| {over} ({100 * PAIRED.binomial_upper(over, n):.1f} %) "
                    f"| {figure(c['nees_mean'])} ({figure(c['nees_mean_all_runs'])}) | {lo:.2f}-{hi:.2f} |")
    return rows


def hoff2024_sea_floors(quick):
    """docs/reproductions/hoff2024.md, hoff2024-sea: pf-sea alone under the planner with each
    angle floor it may be told, on seed 1001 (not the seed the docs report; 60 runs each):
    mean error, mean NEES over the runs that are not outliers (over every run) and its band."""
    runs = RUNS["hoff2024-sea-floors"][0 if quick else 1]
    rows = header("usbl_floor_deg", "mean error, m", "NEES (every run)", "NEES band")
    for floor in ("1.0", "1.25", "1.5", "2.0"):
        (c,) = mc_text(pf_sea_alone(floor), runs, "--seed", "1001", progress=not quick)
        lo, hi = c["nees_band"]
        rows.append(f"| {floor} | {figure(c['mean_error_m'])} | {figure(c['nees_mean'])} "
                    f"({figure(c['nees_mean_all_runs'])}) | {lo:.2f}-{hi:.2f} |")
    return rows


def hoff2024_sea_ablation(quick):
    """docs/reproductions/hoff2024.md, hoff2024-sea: each error source alone, det, 10 runs."""
    return ablation("hoff2024-sea", quick, [(e, e) for e in ("pf", "pf-sea", "bearing-sea")])


# hoff2024-untold-floor: the angle floors the world draws, in the clean world and in hoff2024-sea's
UNTOLD_FLOORS = {"hoff2024": ("0", "1.5", "3", "4.5", "6", "9", "12"), "hoff2024-sea": ("0.1", "3", "6")}


def untold_floor_world(scenario, floor):
    """The planner's cell of `scenario` (hoff2024: its missions cut to the paper's 15 min) whose
    USBL draws an angle floor of `floor` deg (text), with two particle filters of 5e4 particles:
    the paper's ("pf", not told of the floor; the first, whom the planner follows) and
    "pf-told", told of it (in hoff2024-sea: as pf-sea, its floor summed in quadrature with
    the 1.25 deg pf-sea is told of, and Student's t)."""
    sea = scenario == "hoff2024-sea"
    toml = blocks_kept(ROOT / f"scenarios/{scenario}.toml", lambda head, text: head not in ("sweep", "estimators"))
    told = math.hypot(1.25, float(floor)) if sea else float(floor)
    if sea:
        toml = re.sub(r"(?m)^angle_floor_deg = [0-9.]+", f"angle_floor_deg = {floor}", toml)
    else:
        toml = re.sub(r"(?m)^duration_s = \d+", "duration_s = 900", toml) + f"\n[sea.usbl]\nangle_floor_deg = {floor}\n"
    pf = '\n[[estimators]]\nkind = "pf"\nparticles = 50000\nresampler = "multinomial"\n'
    robust = 'robust = "student_t"\nstudent_t_dof = 4.0\n' if sea else ""
    return toml + pf + pf + f'name = "pf-told"\nusbl_floor_deg = {told:.3f}\n{robust}'


def hoff2024_untold_floor(quick):
    """docs/reproductions/hoff2024.md: the paper's "about 5 m" against an angle floor the
    world draws and the paper's filter is not told of, under the planner (det), 20 runs per
    floor: in the clean world (15 min missions) and in hoff2024-sea's sea (30 min). Per
    floor the paper's filter's mean error (the median of the run means) and mean NEES, the
    filter told of the floor likewise, and the difference paired by run (the planner follows
    the paper's filter, so both see the same bearings)."""
    runs = RUNS["hoff2024-untold-floor"][0 if quick else 1]
    rows = header("world", "angle floor, deg", "pf: mean error, m (median)", "its NEES", "pf-told: mean (median)",
                  "its NEES", "pf - pf-told, m [95 %]")
    for scenario, floors in UNTOLD_FLOORS.items():
        for floor in floors:
            cells = {c["estimator"]: c for c in mc_text(untold_floor_world(scenario, floor), runs, progress=not quick)}
            pf, told = cells["pf"], cells["pf-told"]
            rows.append(f"| {scenario} | {floor} | " + " | ".join(
                f"{figure(c['mean_error_m'])} ({figure(statistics.median(c['run_mean_errors_m']))}) "
                f"| {figure(c['nees_mean'])}" for c in (pf, told)) + f" | {paired_cell(pf, told)} |")
    return rows


# the tables of this module by the name that marks them in docs/
TABLES = {
    "hoff2024-sea": hoff2024_sea,
    "hoff2024-sea-paired": hoff2024_sea_paired,
    "hoff2024-sea-long": hoff2024_sea_long,
    "hoff2024-sea-floors": hoff2024_sea_floors,
    "hoff2024-sea-ablation": hoff2024_sea_ablation,
    "hoff2024-untold-floor": hoff2024_untold_floor,
    "hoff2024-literal": hoff2024_literal,
    "hoff2024": hoff2024,
    "hoff2024-paired": hoff2024_paired,
    "hoff2024-dynamics": hoff2024_dynamics,
    "hoff2024-consistency": hoff2024_consistency,
    "hoff2024-current": hoff2024_current,
    "hoff2024-pair": hoff2024_pair,
}
