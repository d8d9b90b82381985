"""The tables of the plaza logs replayed (docs/reproductions/plaza.md, docs/logs.md), and
the runs on a log that docs/smooth.md's tables share."""

import functools
import json
import re
import tempfile
from pathlib import Path

from .common import ABLATION, LOG_PAIRED, OUTLIERS, ROOT, blocks_kept, cli, cli_on_toml, header, interval


def replay(n, beacons=None, estimators=None):
    """`onebeacon replay data/plaza/plazaN.toml --json [--beacons B] [--estimators FILE]`:
    its estimators by name, replayed once per script run (plaza and plaza-tune share the
    logs as shipped)."""
    return _replay(n, beacons, estimators)


@functools.cache
def _replay(n, beacons, estimators):
    args = ["replay", str(ROOT / f"data/plaza/plaza{n}.toml"), "--json"]
    args += ["--beacons", beacons] if beacons else []
    args += ["--estimators", str(estimators)] if estimators else []
    return {e["name"]: e for e in json.loads(cli(*args))["estimators"]}


PLAZA_COLUMNS = ["dead-reckoning", "ekf", "ekf-gated", "ekf-bias", "ekf-cal", "ekf-cal-gated"]


PLAZA_BEACONS = ["0", "1", "5", "6"]


PLAZA_SETS = [None, *PLAZA_BEACONS]


def plaza(quick):
    """docs/reproductions/plaza.md: `onebeacon replay data/plaza/plazaN.toml [--beacons B]`:
    RMSE against the ground truth, m, [ranges the gate rejected] when any; a cell of the
    single-beacon rows equal to the one on its left in every beacon says "same"."""
    del quick  # real data: the same figures at any count

    def cell(e):
        rejected = e.get("rejected") or 0
        return f"{e['rmse_m']:.2f}" + (f" [{rejected}]" if rejected else "")

    rows = header("beacons", "dead reckoning", *PLAZA_COLUMNS[1:])
    for n in (1, 2):
        every = replay(n)
        rows.append(f"| plaza{n}, all 4 | " + " | ".join(cell(every[c]) for c in PLAZA_COLUMNS) + " |")
        single = [replay(n, b) for b in PLAZA_BEACONS]
        cells = []
        for i, c in enumerate(PLAZA_COLUMNS):
            values = [cell(s[c]) for s in single]
            if c == "dead-reckoning":
                cells.append(values[0] if len(set(values)) == 1 else " / ".join(values))
            elif i > 1 and values == [cell(s[PLAZA_COLUMNS[i - 1]]) for s in single]:
                cells.append("same")
            else:
                cells.append(" / ".join(values))
        rows.append(f"| plaza{n}, {' / '.join(PLAZA_BEACONS)} | " + " | ".join(cells) + " |")
    return rows


def plaza_tune(quick):
    """docs/reproductions/plaza.md: `ekf-cal` with its noise as shipped, tuned on the other
    log and tuned on the same one (`onebeacon tune LOG --keys
    range_sigma_m,distance_sigma_frac`, as scripts/plaza_tune.py runs it), RMSE m (mean
    NEES), all beacons and each one alone."""
    del quick  # real data: the same figures at any count
    with tempfile.TemporaryDirectory() as tmp:
        tuned = {}
        for n in (1, 2):
            out = Path(tmp) / f"tune-plaza{n}"
            log = str(ROOT / f"data/plaza/plaza{n}.toml")
            cli("tune", log, "--keys", "range_sigma_m,distance_sigma_frac", "--out", str(out), "--json")
            tuned[n] = out / "estimators.toml"
        rows = header("log", "noise", "all 4", *(f"beacon {b}" for b in PLAZA_BEACONS))
        for n in (1, 2):
            other = 3 - n
            dr = replay(n)["dead-reckoning"]["rmse_m"]
            noises = [(f"plaza{n} (DR {dr:.2f})", "as shipped (grid, in-sample)", None),
                      (f"plaza{n}", f"tuned on plaza{other}: out-of-sample", tuned[other]),
                      (f"plaza{n}", f"tuned on plaza{n}: in-sample", tuned[n])]
            for log, noise, estimators in noises:
                cells = []
                for b in [None, *PLAZA_BEACONS]:
                    e = replay(n, b, estimators)["ekf-cal"]
                    nees = e["nees_mean"]
                    cells.append(f"{e['rmse_m']:.2f} ({nees:.{0 if nees >= 100 else 1}f})")
                rows.append(f"| {log} | {noise} | " + " | ".join(cells) + " |")
    return rows


# plaza-no-odometry's motion models: (label, the estimator's keys)
NO_ODOMETRY_MODELS = [
    ("none (frozen)", {}),
    ("none, `nis_gate = inf`", {"nis_gate": "inf"}),
    ("position walk 0.3 m/sqrt(s)", {"position_walk_m_per_sqrt_s": 0.3}),
    ("position walk 1 m/sqrt(s)", {"position_walk_m_per_sqrt_s": 1}),
    ("constant velocity 0.05 m/s^2", {"track_accel_sigma_m_s2": 0.05}),
    ("constant velocity 0.1 m/s^2", {"track_accel_sigma_m_s2": 0.1}),
    ("constant velocity 0.3 m/s^2", {"track_accel_sigma_m_s2": 0.3}),
]


# ... each as a range EKF and with offset and scale states
NO_ODOMETRY_CALIBRATION = {"estimate_bias": "true", "estimate_range_scale": "true", "range_scale_sigma": 0.1}


def plaza1_without_odometry():
    """data/plaza/plaza1.toml without its odometry source and its estimators (ranges and
    truth only), its files named by absolute path."""
    data = ROOT / "data/plaza"
    log = blocks_kept(data / "plaza1.toml", lambda head, text: head != "estimators" and not (
        head == "source" and 'kind = "odometry"' in text))
    return re.sub(r'(?m)^file = "([^"/]+)"', lambda m: f'file = "{data / m.group(1)}"', log)


def plaza_no_odometry(quick):
    """docs/logs.md: plaza1 with its odometry source left out (ranges and truth only), each
    motion model of NO_ODOMETRY_MODELS as a range EKF and with offset and scale states
    (`onebeacon replay LOG --beacons B`): RMSE, m, [ranges the gate rejected] when any,
    all four beacons, 0 and 1, 5 and 6."""
    del quick  # real data: the same figures at any count
    log = plaza1_without_odometry()
    for i, (_, keys) in enumerate(NO_ODOMETRY_MODELS):
        for cal in ("", "-cal"):
            every = {**keys, **(NO_ODOMETRY_CALIBRATION if cal else {})}
            log += f'\n[[estimators]]\nname = "m{i}{cal}"\nkind = "range-ekf"\n'
            log += "".join(f"{k} = {v}\n" for k, v in every.items())

    def cell(e):
        rejected = e.get("rejected") or 0
        return f"{e['rmse_m']:.1f}" + (f" [{rejected}]" if rejected else "")

    sets = {"all 4": None, "0 and 1": "0,1", "5 and 6": "5,6"}
    runs = {label: {e["name"]: e for e in json.loads(cli_on_toml(
        "replay", log, "--json", *(["--beacons", b] if b else []), out=True))["estimators"]}
        for label, b in sets.items()}
    rows = header("motion model", *(f"{label}: {f}" for label in sets
                                    for f in ("range EKF", "with offset and scale states")))
    for i, (label, _) in enumerate(NO_ODOMETRY_MODELS):
        rows.append(f"| {label} | " + " | ".join(cell(runs[s][f"m{i}{cal}"]) for s in sets for cal in ("", "-cal"))
                    + " |")
    return rows


@functools.cache
def log_run(command, n, beacons, *extra):
    """`onebeacon COMMAND data/plaza/plazaN.toml --out DIR --json [--beacons B] EXTRA...`,
    run once per script run: its JSON's estimators by name, and each estimator's error per
    row of the trajectory.csv it writes."""
    with tempfile.TemporaryDirectory() as tmp:
        args = [command, str(ROOT / f"data/plaza/plaza{n}.toml"), "--out", tmp, "--json", *extra]
        summary = json.loads(cli(*args, *(["--beacons", beacons] if beacons else [])))
        return {e["name"]: e for e in summary["estimators"]}, LOG_PAIRED.errors(Path(tmp) / "trajectory.csv")


def trajectory_errors(command, n, beacons, *extra):
    """Each estimator's error per row of `log_run`'s trajectory.csv."""
    return log_run(command, n, beacons, *extra)[1]


def log_paired_cell(errors, a, b):
    """RMSE(`a`) - RMSE(`b`) on one log with its 95 % interval by batch means over 10
    stretches (scripts/log_paired.py): 'difference [low, high]'."""
    m, h, _ = LOG_PAIRED.compare(errors[a], errors[b])
    return interval(m, h)


def log_paired_rows(pairs, errors_of):
    """One row per plaza log and beacon set: `a` - `b` for each (label, errors key, a, b)
    of `pairs`, the errors from `errors_of(n, beacons, key)`."""
    rows = header("log", "beacons", *(label for label, *_ in pairs))
    for n in (1, 2):
        for b in PLAZA_SETS:
            cells = [log_paired_cell(errors_of(n, b, key), x, y) for _, key, x, y in pairs]
            rows.append(f"| plaza{n} | {b or 'all'} | " + " | ".join(cells) + " |")
    return rows


def plaza_paired(quick):
    """docs/reproductions/plaza.md: paired RMSE differences on each log, m, with 95 %
    intervals by batch means over 10 consecutive stretches (scripts/log_paired.py), from
    `onebeacon replay --out`'s trajectory.csv."""
    del quick  # real data: the same figures at any count
    pairs = [("ekf-cal - dead reckoning", None, "ekf-cal", "dead-reckoning"),
             ("ukf-cal - ekf-cal", None, "ukf-cal", "ekf-cal"),
             ("ekf-cal-oos - dead reckoning", None, "ekf-cal-oos", "dead-reckoning"),
             ("ekf-cal-oos - ekf-cal", None, "ekf-cal-oos", "ekf-cal")]
    return log_paired_rows(pairs, lambda n, b, _: trajectory_errors("replay", n, b))


def plaza_outliers(quick):
    """docs/logs.md: plaza1 with five gross range outliers (scripts/plaza_outliers.py)
    against plaza1 as logged, every estimator of the log but dead reckoning, and
    `ekf-bias` and `ekf-cal` with a Student-t update (`-t`, `robust = "student_t"`):
    RMSE, m, and the largest error with the outliers."""
    del quick  # real data: the same figures at any count
    log = ROOT / "data/plaza/plaza1.toml"
    blocks = ["".join(lines) for h, lines in ABLATION.blocks(log.read_text()) if h == "estimators"]
    t_variants = []
    for text in blocks:
        m = re.search(r'(?m)^name = "(ekf-bias|ekf-cal)"', text)
        if m:
            t_variants.append(text.replace(m.group(0), f'name = "{m.group(1)}-t"\nrobust = "student_t"', 1))
    with tempfile.TemporaryDirectory() as tmp:
        OUTLIERS.write(tmp, say=lambda _: None)
        estimators = Path(tmp) / "estimators.toml"
        estimators.write_text("\n".join(blocks + t_variants))
        runs = [{e["name"]: e for e in json.loads(cli("replay", str(path), "--estimators", str(estimators), "--json",
                                                      "--out", str(Path(tmp) / out)))["estimators"]}
                for path, out in ((log, "clean"), (Path(tmp) / "plaza1_outliers.toml", "outliers"))]
    clean, outliers = runs
    rows = header("estimator", "clean", "outliers", "max error with outliers")
    for name in clean:
        if name != "dead-reckoning":
            rows.append(f"| {name} | {clean[name]['rmse_m']:.2f} m | {outliers[name]['rmse_m']:.2f} m | "
                        f"{outliers[name]['max_error_m']:.1f} m |")
    return rows


# the tables of this module by the name that marks them in docs/
TABLES = {
    "plaza": plaza,
    "plaza-tune": plaza_tune,
    "plaza-paired": plaza_paired,
    "plaza-outliers": plaza_outliers,
    "plaza-no-odometry": plaza_no_odometry,
}
