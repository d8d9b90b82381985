#!/usr/bin/env python3
"""Paired comparisons of estimators on one real log: from the `trajectory.csv` that
`onebeacon replay --out DIR` or `onebeacon smooth --out DIR` writes, the difference of
each estimator's RMSE against the ground truth from a base estimator's, with a 95 %
confidence interval by batch means.

One log is one run: its whole-log RMSE difference has no spread of its own. The log's
rows are cut into K consecutive stretches of (nearly) equal row counts (default 10); in
each, the mean squared error of A minus that of B. Those K differences average (weighted
by rows) to the whole log's MSE difference; their 95 % interval is Student's t with K - 1
degrees of freedom (batch means). Divided by RMSE(A) + RMSE(B) it is an interval on the
RMSE difference, centred on the whole log's, since (a^2 - b^2) / (a + b) = a - b (the
divisor taken as fixed). An interval that holds zero is a tie on this log. Consecutive
stretches of one log are not independent draws (a drift carries over), so the interval
says how steady the difference is along this log, not what another log would give; docs
state such a comparison as "on this log".

Usage:
  scripts/log_paired.py DIR/trajectory.csv --base dead-reckoning [--against ekf-cal,smoother]
      [--stretches 10]
Negative: A's error is lower than the base's.
"""
import argparse
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paired import t975, verdict  # noqa: E402  (one table of Student's t, one verdict)

SUFFIX = "_error_m"


def errors(path):
    """Each estimator's position error per row of a trajectory.csv, by estimator name."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        head = next(reader, None)
        if not head:
            raise ValueError(f"{path}: empty")
        cols = {name[: -len(SUFFIX)]: i for i, name in enumerate(head) if name.endswith(SUFFIX)}
        if not cols:
            raise ValueError(f"{path}: no `<estimator>{SUFFIX}` columns (is it a replay or smooth trajectory.csv?)")
        out = {name: [] for name in cols}
        for row in reader:
            for name, i in cols.items():
                out[name].append(float(row[i]))
    return out


def mse(values):
    finite = [v for v in values if math.isfinite(v)]
    return sum(v * v for v in finite) / len(finite) if finite else float("nan")


def rmse(values):
    return math.sqrt(mse(values))


def compare(a, b, stretches=10):
    """RMSE(a) - RMSE(b) over the whole log, its 95 % half-width by batch means over
    `stretches` consecutive stretches (module doc), and the number of stretches."""
    n = len(a)
    if n < 2 * stretches:
        raise ValueError(f"{n} rows: fewer than 2 per stretch for {stretches} stretches")
    cuts = [round(j * n / stretches) for j in range(stretches + 1)]
    d = [mse(a[lo:hi]) - mse(b[lo:hi]) for lo, hi in zip(cuts, cuts[1:])]
    w = [(hi - lo) / n for lo, hi in zip(cuts, cuts[1:])]
    m = sum(wi * di for wi, di in zip(w, d))
    sd = math.sqrt(sum((x - m) ** 2 for x in d) / (stretches - 1))
    ra, rb = rmse(a), rmse(b)
    return ra - rb, t975(stretches - 1) * sd / math.sqrt(stretches) / (ra + rb), stretches


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("trajectory_csv")
    ap.add_argument("--base", required=True, help="the estimator compared against")
    ap.add_argument("--against", help="comma-separated estimators (default: every other one)")
    ap.add_argument("--stretches", type=int, default=10, help="consecutive stretches of the log (at least 2)")
    args = ap.parse_args()
    if args.stretches < 2:
        sys.exit(f"log_paired: --stretches {args.stretches}: at least 2")
    try:
        err = errors(args.trajectory_csv)
    except (OSError, ValueError) as e:
        print(f"log_paired: {e}", file=sys.stderr)
        sys.exit(2)
    names = args.against.split(",") if args.against else [n for n in err if n != args.base]
    unknown = [n for n in [args.base, *names] if n not in err]
    if unknown:
        print(f"log_paired: no estimator {', '.join(unknown)} in {args.trajectory_csv}; it has: {', '.join(err)}",
              file=sys.stderr)
        sys.exit(2)
    print(f"{'estimator':24} {'RMSE m':>8} {'- ' + args.base:>16} {'95 % CI':>18} {'K':>3}  verdict")
    for name in names:
        try:
            m, h, k = compare(err[name], err[args.base], args.stretches)
        except ValueError as e:
            print(f"log_paired: {e}", file=sys.stderr)
            sys.exit(2)
        print(f"{name:24} {rmse(err[name]):8.3f} {m:+16.3f} {f'[{m - h:+.3f}, {m + h:+.3f}]':>18} "
              f"{k:3d}  {verdict(m, h)}")


if __name__ == "__main__":
    main()
