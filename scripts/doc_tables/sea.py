"""docs/scenarios.md's tables of the sea's error sources, and the ablation of a -sea
scenario (each error source alone) that the papers' pages hold."""

import re
import tempfile
from pathlib import Path

from .common import ABLATION, PRESETS, ROOT, RUNS, SEA_SOURCES, binary, header, spread, verdict_counts


def ablation(scenario, quick, columns):
    """The rows of a `scripts/sea_ablation.py scenarios/SCENARIO.toml --runs N` table at
    RUNS' count, the estimators in the order and with the headers of `columns`
    ([(estimator, header)])."""
    runs = RUNS[f"{scenario}-ablation"][0 if quick else 1]
    with tempfile.TemporaryDirectory() as tmp:
        labels, _, table, _ = ABLATION.ablate(ROOT / f"scenarios/{scenario}.toml", runs, binary(), tmp)
    rows = header("sources", *(h for _, h in columns))
    for label in labels:
        rows.append(f"| {label} | " + " | ".join(ABLATION.cell(table[(label, e)]) for e, _ in columns) + " |")
    return rows


def sea_source(source, quick, rows_spec):
    """docs/scenarios.md, "The sea": `scripts/sea_sources.py SOURCE` at RUNS' count: for each
    row of `rows_spec` ([(label, "clean" or "sea", estimator)]) the spread over the cells
    of the mean error, of the mean NEES, of the mean error over the first row's, and the
    cells where it is lower / tied / higher than dead reckoning in the same world, paired
    by run (95 %)."""
    runs = RUNS[f"sea-{source.replace('_', '-')}"][0 if quick else 1]
    with tempfile.TemporaryDirectory() as tmp:
        worlds = {w: SEA_SOURCES.run(source, w == "sea", binary(), Path(tmp), runs) for w in ("clean", "sea")}
    cells = sorted({k[:3] for k in worlds["clean"]})
    _, first_world, first_est = rows_spec[0]
    rows = header("", "mean error, m", "NEES (2 is consistent)", "mean error / the first row's, cell by cell",
                  "against dead reckoning, paired: cells lower / tie / higher")
    for label, world, est in rows_spec:
        by = [worlds[world][c + (est,)] for c in cells]
        ratio = [b["mean_error_m"] / worlds[first_world][c + (first_est,)]["mean_error_m"] for b, c in zip(by, cells)]
        counts, _ = verdict_counts((b, worlds[world][c + ("dead-reckoning",)]) for b, c in zip(by, cells))
        first = (world, est) == (first_world, first_est)
        rows.append(f"| {label} | {spread([b['mean_error_m'] for b in by], 2)} | "
                    f"{spread([b['nees_mean'] for b in by])} | {'-' if first else spread(ratio, 2) + 'x'} | "
                    + ("-" if est == "dead-reckoning" else counts) + " |")
    return rows


def sea_clock(quick):
    """docs/scenarios.md: the range EKF with and without the clock state, 1 ppm clocks."""
    return sea_source("clock", quick, [
        ("range EKF, no clock error", "clean", "range-ekf"),
        ("range EKF, 1 ppm clocks", "sea", "range-ekf"),
        ("range EKF with the clock state, 1 ppm clocks", "sea", "range-ekf-state"),
        ("range EKF with the clock state, no clock error", "clean", "range-ekf-state"),
        ("dead reckoning, 1 ppm clocks", "sea", "dead-reckoning")])


def sea_link(quick):
    """docs/scenarios.md: the range EKF on a lossy, reflecting link, plain, gated and with
    a Student-t update."""
    return sea_source("link", quick, [
        ("range EKF, a clean link", "clean", "range-ekf"),
        ("range EKF, the link's errors", "sea", "range-ekf"),
        ("range EKF gated at NIS 10.83 (99.9 %), the link's errors", "sea", "range-ekf-gated"),
        ("range EKF with a Student-t update (4 dof), the link's errors", "sea", "range-ekf-state"),
        ("dead reckoning, the link's errors", "sea", "dead-reckoning")])


def sea_sound_speed(quick):
    """docs/scenarios.md: the range EKF with and without the range scale state, a tropical
    sound-speed cast."""
    return sea_source("sound_speed", quick, [
        ("range EKF, one speed", "clean", "range-ekf"),
        ("range EKF, the tropical cast", "sea", "range-ekf"),
        ("range EKF with the scale state, the cast", "sea", "range-ekf-state"),
        ("range EKF with the scale state, one speed", "clean", "range-ekf-state"),
        ("dead reckoning, the cast", "sea", "dead-reckoning")])


def sea_presets(quick):
    """docs/scenarios.md: per -sea preset, its error sources' values, how many carry a
    source and how many say "unsourced" (`scripts/sea_presets.py count`; no runs)."""
    rows = header("preset", "values", "sourced", "unsourced")
    counts = PRESETS.counts()
    for name, n, s, u in counts:
        rows.append(f"| {name} | {n} | {s} | {u} |")
    n, s = sum(c[1] for c in counts), sum(c[2] for c in counts)
    rows.append(f"| all | {n} | {s} ({100 * s / n:.0f} %) | {n - s} |")
    return rows


def unsourced(preset, estimator, quick, transform=None):
    """docs/scenarios.md: `scripts/sea_presets.py ablate PRESET --runs N --estimator E` at
    RUNS' count (its text rewritten by `transform`, as --abstract-pings does): each unsourced
    value of the preset, the estimator's mean error with the value as set, and each
    variant's change from it, paired by run (95 %)."""
    runs = RUNS[f"{preset}-unsourced"][0 if quick else 1]
    with tempfile.TemporaryDirectory() as tmp:
        first, found = PRESETS.ablate(preset, runs, binary(), tmp, progress=not quick, estimator=estimator,
                                      transform=transform)
    rows = header("value", f"{first}: mean error as set, m (95 %)", "default or x0.5: change, m (95 %)",
                  "x2 or +180 deg: change, m (95 %)")
    for table, key, value, (mean, half, _, _), changes in found:
        cells = [PRESETS.change(c) for c in changes] + ["-"] * (2 - len(changes))
        rows.append(f"| [{table}] {key} = {value} | {mean:.2f} (+-{half:.2f}) | " + " | ".join(cells) + " |")
    return rows


# the tables of this module by the name that marks them in docs/
TABLES = {
    "sea-clock": sea_clock,
    "sea-link": sea_link,
    "sea-sound-speed": sea_sound_speed,
    "sea-presets": sea_presets,
    "garin2024-sea-unsourced": lambda quick: unsourced("garin2024-sea", "range+doppler", quick),
    "sousa-sea-unsourced": lambda quick: unsourced("sousa-sea", "range-ekf", quick),
    # --quick checks the rows alone: hoff2024-sea's missions cut to 5 min there
    "hoff2024-sea-unsourced": lambda quick: unsourced(
        "hoff2024-sea", "pf-sea", quick,
        (lambda text: re.sub(r"(?m)^duration_s = \d+", "duration_s = 300", text)) if quick else None),
    "rypkema-m1-sea-unsourced": lambda quick: unsourced("rypkema-m1-sea", "iusbl", quick, PRESETS.abstract_pings),
    "rypkema-m6-sea-unsourced": lambda quick: unsourced("rypkema-m6-sea", "iusbl", quick, PRESETS.abstract_pings),
}
