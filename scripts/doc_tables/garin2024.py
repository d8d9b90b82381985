"""docs/reproductions/garin2024.md's tables: range + Doppler EKF on one fixed beacon."""

import re
import statistics

from .common import (ABLATION, PAIRED, ROOT, RUNS, blocks_kept, cli, header, mc, mc_text, nees_figure,
    paired_cell)
from .sea import ablation


# garin2024 Table 4: mean positioning error (outliers) in m, proposed method and ROSB,
# 300 simulated missions per T_com
GARIN_PAPER = {
    3: ("3.61 (1)", "4.59 (4)"),
    6: ("5.04 (5)", "6.23 (6)"),
    9: ("6.45 (1)", "7.72 (5)"),
    12: ("8.09 (6)", "9.25 (15)"),
    15: ("9.55 (6)", "10.67 (10)"),
    20: ("12.13 (6)", "12.97 (29)"),
}


GARIN_ESTIMATORS = ["range+doppler", "rosb", "range+doppler-ukf", "range+doppler-robust"]


def garin2024(quick):
    """docs/reproductions/garin2024.md: `onebeacon mc garin2024` (300 runs per cell)."""
    cells = mc("garin2024", quick)
    rows = header("T_com", *(f"{e} (outliers)" for e in GARIN_ESTIMATORS), "paper: proposed", "paper: ROSB")
    for t in sorted({c["sweep"]["t_com_s"] for c in cells}):
        by = {c["estimator"]: c for c in cells if c["sweep"]["t_com_s"] == t}
        ours = [f"{by[e]['mean_error_m']:.2f} ({by[e]['outliers']})" for e in GARIN_ESTIMATORS]
        paper = GARIN_PAPER[round(t)]
        rows.append(f"| {t:g} s | " + " | ".join(ours) + f" | {paper[0]} | {paper[1]} |")
    return rows


def garin2024_over_10m(quick):
    """docs/reproductions/garin2024.md: the runs (of 300) whose mean error is over 10 m,
    of the paper's filter and its robust form, from the same campaign."""
    cells = mc("garin2024", quick)
    t_com = sorted({c["sweep"]["t_com_s"] for c in cells})
    rows = header("T_com", *(f"{t:g} s" for t in t_com))
    for e in ("range+doppler", "range+doppler-robust"):
        counts = []
        for t in t_com:
            (c,) = [c for c in cells if c["estimator"] == e and c["sweep"]["t_com_s"] == t]
            counts.append(str(sum(m > 10.0 for m in c["run_mean_errors_m"])))
        rows.append(f"| {e} | " + " | ".join(counts) + " |")
    return rows


def runs_over(means, by_median):
    """How many of the run mean errors `means` are over 10 m, or over 3 x their median
    (the upper one) when `by_median`."""
    limit = 3 * sorted(means)[len(means) // 2] if by_median else 10.0
    return sum(m > limit for m in means)


# garin2024 with the beacon elsewhere: (north, east), its label, whether a run's outlier
# threshold is 3 x the median of its cell (where the median itself nears 10 m) instead of 10 m
GARIN_BEACONS = [((50, 100), "centre", False), ((0, 0), "the start", False),
                 ((100, 255), "far corner", False), ((50, 400), "145 m east of the area", False),
                 ((-100, 125), "100 m south", True)]


GARIN_BEACON_ESTIMATORS = ["range+doppler", "range+doppler-ukf", "range+doppler-robust", "rosb"]


def garin2024_beacon(quick):
    """docs/reproductions/garin2024.md: `onebeacon mc` of garin2024's TOML with the beacon
    moved (`[beacon]`) and 0 or 30 % of the frames lost (`comms.frame_loss_prob`), at T_com
    3 and 20 s: the runs over 10 m (or over 3 x their cell's median) of each estimator, and
    the robust filter's paired difference from the paper's (run mean errors, m, 95 %)."""
    runs = RUNS["garin2024-beacon"][0 if quick else 1]
    base = cli("scenarios", "--show", "garin2024")
    rows = header("beacon (north, east)", "frames lost",
                  *(f"T_com {t} s: published / ukf / robust / rosb" for t in (3, 20)),
                  "robust - published, 3 s", "robust - published, 20 s")
    for (north, east), label, by_median in GARIN_BEACONS:
        for loss in (0.0, 0.3):
            toml = re.sub(r"(?m)^north_m = .*$", f"north_m = {north}.0", base, count=1)
            toml = re.sub(r"(?m)^east_m = .*$", f"east_m = {east}.0", toml, count=1)
            toml = re.sub(r"(?m)^frame_loss_prob = .*$", f"frame_loss_prob = {loss}", toml)
            toml = re.sub(r"(?m)^t_com_s = \[.*$", "t_com_s = [3.0, 20.0]", toml)
            cells = mc_text(toml, runs)
            counts, pairs = [], []
            for t in (3.0, 20.0):
                by = {c["estimator"]: c for c in cells if c["sweep"]["t_com_s"] == t}
                counts.append(" / ".join(str(runs_over(by[e]["run_mean_errors_m"], by_median))
                                         for e in GARIN_BEACON_ESTIMATORS))
                pairs.append(paired_cell(by["range+doppler-robust"], by["range+doppler"]))
            where = f"({north}, {east}), {label}" + (", over 3 x median" if by_median else "")
            rows.append(f"| {where} | {round(loss * 100)} % | " + " | ".join(counts + pairs) + " |")
    return rows


def garin2024_paired(quick):
    """docs/reproductions/garin2024.md: paired differences of the run mean errors (every
    run, outliers too), m, with 95 % intervals, from the same campaign."""
    cells = mc("garin2024", quick)
    pairs = [("range+doppler", "rosb"), ("range+doppler-ukf", "range+doppler"),
             ("range+doppler-robust", "range+doppler")]
    rows = header("T_com", *(f"{a} - {b}" for a, b in pairs))
    for t in sorted({c["sweep"]["t_com_s"] for c in cells}):
        by = {c["estimator"]: c for c in cells if c["sweep"]["t_com_s"] == t}
        rows.append(f"| {t:g} s | " + " | ".join(paired_cell(by[a], by[b]) for a, b in pairs) + " |")
    return rows


def garin2024_sea(quick):
    """docs/reproductions/garin2024.md, garin2024-sea: `onebeacon mc garin2024-sea` (300 runs per
    T_com): mean error over the runs that are not outliers (NEES over them), and for the
    augmented filters their NEES over every run and their runs over 20 m."""
    cells = mc("garin2024-sea", quick)
    augmented = ("range+doppler-sea", "range+doppler-current")
    rows = header(
        "T_com",
        "paper's filter",
        "its robust form (garin2024.toml)",
        "range+doppler-sea: robust + offset and drift states + Student-t ranges, gated",
        "range+doppler-current: the same + the current as two states (UKF)",
        "their runs over 20 m",
    )
    for t in sorted({c["sweep"]["t_com_s"] for c in cells}):
        by = {c["estimator"]: c for c in cells if c["sweep"]["t_com_s"] == t}
        plain = [f"{by[e]['mean_error_m']:.1f} ({by[e]['nees_mean']:.0f})" for e in ("range+doppler", "range+doppler-robust")]
        rich = [f"{by[e]['mean_error_m']:.2f} ({nees_figure(by[e]['nees_mean'])} / {nees_figure(by[e]['nees_mean_all_runs'])})"
                for e in augmented]
        over = [str(sum(m > 20.0 for m in by[e]["run_mean_errors_m"])) for e in augmented]
        rows.append(f"| {t:g} s | " + " | ".join(plain + rich) + f" | {', '.join(over)} of {by[augmented[0]]['runs']} |")
    return rows


def garin2024_sea_ablation(quick):
    """docs/reproductions/garin2024.md, garin2024-sea: each error source alone, T_com 3 s, 100 runs."""
    return ablation("garin2024-sea", quick,
                    [(e, e) for e in ("range+doppler", "range+doppler-robust", "range+doppler-sea",
                                       "range+doppler-current")])


def ratio_cell(a, b):
    """mean(a) / mean(b) of two cells' run mean errors paired by run, with the 95 % interval
    of the ratio of means (delta method: the t interval of the runs' a_i - r b_i, over
    mean(b))."""
    x, y = a["run_mean_errors_m"], b["run_mean_errors_m"]
    n = len(x)
    r = sum(x) / sum(y)
    m, h, _ = PAIRED.paired(x, [r * v for v in y])
    h /= sum(y) / n
    return f"{r:.2f} [{r - h:.2f}, {r + h:.2f}]"


def garin2024_current(quick):
    """docs/reproductions/garin2024.md: the filter with a current state in still water
    (garin2024-sea without its [sea.current]) and in garin2024-sea's current, run by run
    on the same seeds (300 runs per T_com): mean error over every run (95 % interval) /
    mean NEES over every run, the ratio of the mean errors (95 % interval, paired by run),
    its runs over 20 m; and the filter without the state in both."""
    flowing = mc("garin2024-sea", quick)
    parts = ABLATION.blocks((ROOT / "scenarios/garin2024-sea.toml").read_text())
    still_text = "".join("".join(lines) for head, lines in parts if head != "sea.current")
    still = mc_text(still_text, RUNS["garin2024-sea"][0 if quick else 1])
    e, plain = "range+doppler-current", "range+doppler-sea"
    rows = header("T_com", f"{e}, still water", f"{e}, current", "current / still", "its runs over 20 m (still, current)",
                  f"{plain}, still water", f"{plain}, current")
    for t in sorted({c["sweep"]["t_com_s"] for c in flowing}):
        by = {c["estimator"]: c for c in flowing if c["sweep"]["t_com_s"] == t}
        calm, calm_plain = ([c for c in still if c["estimator"] == x and c["sweep"]["t_com_s"] == t][0] for x in (e, plain))
        cell = lambda c: ABLATION.cell(ABLATION.summary(c))
        over = lambda c: sum(m > 20.0 for m in c["run_mean_errors_m"])
        rows.append(f"| {t:g} s | {cell(calm)} | {cell(by[e])} | {ratio_cell(by[e], calm)} | "
                    f"{over(calm)}, {over(by[e])} | {cell(calm_plain)} | {cell(by[plain])} |")
    return rows


# garin2024 Table 8 (at sea): mean positioning error in m of the proposed method against
# T_com for trajectories #1-#4 (None: "DIV", the filter diverged); Table 6: ROSB's at T_com 3 s
GARIN_AT_SEA = {
    3: (4.6225, 2.1537, 5.0740, 4.2069),
    6: (5.0982, 3.3472, 7.1929, 4.4613),
    9: (5.6782, 3.3813, 7.4395, 5.0431),
    12: (6.0585, 3.4354, 8.4071, 5.6932),
    15: (None, 2.5071, 8.2798, 5.3535),
    18: (13.71, 4.4618, 9.3593, 7.5195),
}
GARIN_AT_SEA_ROSB = (5.4287, 2.9931, 8.6719, 6.2746)


def at_sea_world(with_sea):
    """scenarios/garin2024-sea.toml cut to the trial's 600 s (Table 6: trajectories #1 and #3)
    over Table 8's T_com, with the paper's filter, ROSB and range+doppler-current; its sea
    whole (`with_sea`) or its clocks alone (the sea's sourced part: no link, no current)."""
    def keep(head, text):
        if head == "estimators":
            return "name =" not in text or "range+doppler-current" in text
        return head != "sweep" and (with_sea or head not in ("sea.link", "sea.current"))
    toml = blocks_kept(ROOT / "scenarios/garin2024-sea.toml", keep)
    toml = toml.replace("[mission]\n", "[mission]\nduration_s = 600\n", 1)
    return toml + '\n[[estimators]]\nkind = "rosb"\n\n[sweep]\nt_com_s = [3.0, 6.0, 9.0, 12.0, 15.0, 18.0]\n'


def garin2024_at_sea(quick):
    """docs/reproductions/garin2024.md: Table 8's growth with T_com and Table 6's gain of
    Doppler over ROSB, at sea, beside garin2024-sea cut to the trial's 600 s (300 runs per
    T_com): the paper's mean over its four trajectories (their range), ours with the sea's
    clocks alone (the paper's filter, ROSB, ROSB - the paper's filter paired by run) and in
    the whole sea (range+doppler-current; the paper's filter); the last row, 18 s / 3 s."""
    runs = RUNS["garin2024-at-sea"][0 if quick else 1]
    clocks, whole = ({(c["sweep"]["t_com_s"], c["estimator"]): c for c in mc_text(at_sea_world(w), runs)}
                     for w in (False, True))
    mean = lambda c: sum(c["run_mean_errors_m"]) / len(c["run_mean_errors_m"])
    rows = header("T_com", "paper at sea, Table 8: mean of #1-#4 (range)", "clocks alone: paper's filter",
                  "ROSB", "ROSB - paper's filter [95 %]", "whole sea: range+doppler-current", "paper's filter")
    for t, paper in GARIN_AT_SEA.items():
        known = [x for x in paper if x is not None]
        cell = f"{statistics.mean(known):.2f} ({min(known):.2f}-{max(known):.2f})"
        cell += "" if len(known) == 4 else ", #1 diverged"
        if t == 3:
            gains = [r - p for r, p in zip(GARIN_AT_SEA_ROSB, paper)]
            cell += f"; ROSB - it, Table 6: {statistics.mean(gains):.2f} ({min(gains):.2f}-{max(gains):.2f})"
        rd, rosb = clocks[(float(t), "range+doppler")], clocks[(float(t), "rosb")]
        cur, paper_sea = whole[(float(t), "range+doppler-current")], whole[(float(t), "range+doppler")]
        rows.append(f"| {t} s | {cell} | {mean(rd):.2f} | {mean(rosb):.2f} | {paired_cell(rosb, rd)} "
                    f"| {mean(cur):.2f} | {mean(paper_sea):.1f} |")
    growth = [a / b for a, b in zip(GARIN_AT_SEA[18], GARIN_AT_SEA[3])]
    ratio = lambda cells, e: ratio_cell(cells[(18.0, e)], cells[(3.0, e)])
    rows.append(f"| 18 s / 3 s | {statistics.mean(growth):.2f} ({min(growth):.2f}-{max(growth):.2f}) "
                f"| {ratio(clocks, 'range+doppler')} | {ratio(clocks, 'rosb')} | | "
                f"{ratio(whole, 'range+doppler-current')} | {ratio(whole, 'range+doppler')} |")
    return rows


# the tables of this module by the name that marks them in docs/
TABLES = {
    "garin2024": garin2024,
    "garin2024-at-sea": garin2024_at_sea,
    "garin2024-over-10m": garin2024_over_10m,
    "garin2024-beacon": garin2024_beacon,
    "garin2024-paired": garin2024_paired,
    "garin2024-sea": garin2024_sea,
    "garin2024-sea-ablation": garin2024_sea_ablation,
    "garin2024-current": garin2024_current,
}
