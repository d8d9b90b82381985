"""docs/smooth.md's tables: the smoother on the plaza logs."""

import json

from .common import cli_on_toml, header
from .plaza import NO_ODOMETRY_CALIBRATION, PLAZA_SETS, log_paired_rows, log_run, plaza1_without_odometry, \
    trajectory_errors

# the constant-velocity models of smooth-track: the white acceleration, m/s^1.5
TRACK_ACCELS = (0.05, 0.1, 0.3, 1)


def smooth_plaza(quick):
    """docs/smooth.md: `onebeacon smooth data/plaza/plazaN.toml [--beacons B]` with its
    default calibration, `--calibrate none` and `--like ekf-cal-oos`: RMSE, m, of dead
    reckoning, the two filters and their RTS passes, and of each smoother (its mean NEES)."""
    del quick  # real data: the same figures at any count
    filters = ["dead-reckoning", "ekf-cal", "ekf-cal+rts", "ekf-cal-oos", "ekf-cal-oos+rts"]
    rows = header("log", "beacons", "dead reckoning", "ekf-cal", "+ RTS", "ekf-cal-oos", "+ RTS",
                  "smooth, no calibration (NEES)", "smooth (NEES)", "smooth like ekf-cal-oos (NEES)")
    for n in (1, 2):
        for b in PLAZA_SETS:
            runs = [log_run("smooth", n, b, *extra)[0] for extra in ((), ("--calibrate", "none"),
                                                                     ("--like", "ekf-cal-oos"))]
            cells = [f"{runs[0][f]['rmse_m']:.2f}" for f in filters]
            cells += [f"{r['smoother']['rmse_m']:.2f} ({r['smoother']['nees_mean']:.1f})" for r in (runs[1], runs[0], runs[2])]
            rows.append(f"| plaza{n} | {b or 'all'} | " + " | ".join(cells) + " |")
    return rows


def smooth_paired(quick):
    """docs/smooth.md: paired RMSE differences on each log, m, with 95 % intervals by batch
    means over 10 consecutive stretches (scripts/log_paired.py), from `onebeacon smooth
    --out`'s trajectory.csv: the smoother with its defaults, without calibration variables
    and `--like ekf-cal-oos`, and the filters' RTS pass."""
    del quick  # real data: the same figures at any count
    like = ("--like", "ekf-cal-oos")
    pairs = [("smoother - dead reckoning", (), "smoother", "dead-reckoning"),
             ("smoother - ekf-cal", (), "smoother", "ekf-cal"),
             ("smoother, no calibration - ekf-cal", ("--calibrate", "none"), "smoother", "ekf-cal"),
             ("smoother like ekf-cal-oos - dead reckoning", like, "smoother", "dead-reckoning"),
             ("ekf-cal + RTS - ekf-cal", (), "ekf-cal+rts", "ekf-cal"),
             ("ekf-cal + RTS - dead reckoning", (), "ekf-cal+rts", "dead-reckoning")]
    return log_paired_rows(pairs, lambda n, b, extra: trajectory_errors("smooth", n, b, *extra))


def smooth_track(quick):
    """docs/smooth.md: plaza1 without its odometry (ranges and truth only), the
    constant-velocity tracker with offset and scale states at each white acceleration of
    TRACK_ACCELS, and `onebeacon smooth LOG --like` it: RMSE, m, of the tracker and of the
    smoother (its mean NEES), all four beacons, 0 and 1, 5 and 6."""
    del quick  # real data: the same figures at any count
    log = plaza1_without_odometry()
    for i, accel in enumerate(TRACK_ACCELS):
        keys = {"track_accel_sigma_m_s2": accel, **NO_ODOMETRY_CALIBRATION}
        log += f'\n[[estimators]]\nname = "cv{i}"\nkind = "range-ekf"\n' + "".join(f"{k} = {v}\n" for k, v in keys.items())
    sets = {"all 4": None, "0 and 1": "0,1", "5 and 6": "5,6"}
    rows = header("white acceleration, m/s^1.5", *(f"{label}: {f}" for label in sets for f in ("tracker", "smoother (NEES)")))
    for i, accel in enumerate(TRACK_ACCELS):
        cells = []
        for b in sets.values():
            summary = json.loads(cli_on_toml("smooth", log, "--json", "--like", f"cv{i}",
                                             *(["--beacons", b] if b else []), out=True))
            runs = {e["name"]: e for e in summary["estimators"]}
            s = runs["smoother"]
            cells += [f"{runs[f'cv{i}']['rmse_m']:.1f}", f"{s['rmse_m']:.1f} ({s['nees_mean']:.0f})"]
        rows.append(f"| {accel} | " + " | ".join(cells) + " |")
    return rows


# the tables of this module by the name that marks them in docs/
TABLES = {
    "smooth-track": smooth_track,
    "smooth-paired": smooth_paired,
    "smooth-plaza": smooth_plaza,
}
