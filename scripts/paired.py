#!/usr/bin/env python3
"""Paired comparisons from an `mc` JSON: for each pair of (cell, estimator) entries that
differ only in one sweep key or in the estimator, the per-run differences of the mean
error (run i against run i: the same seed's draws), their mean, and the 95 % confidence
interval of that mean (Student's t with n - 1 degrees of freedom). A difference whose
interval excludes zero is what a doc may call "better"; one whose interval holds zero is
a tie at this run count.

Usage:
  scripts/paired.py MC_JSON --vary guidance --base circle [--estimator range-ekf]
  scripts/paired.py MC_JSON --vary estimator --base range-ekf
Every other entry of the varied key is compared with --base within each cell; negative
means lower error than the base.
"""
import argparse
import json
import math
import sys

# two-sided 97.5 % quantiles of Student's t, 1 to 30 degrees of freedom, then the normal's
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145,
        2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048,
        2.045, 2.042]


def t975(dof: int) -> float:
    return T975[dof - 1] if dof <= len(T975) else 1.960


def paired(a: list, b: list) -> tuple:
    """Mean of a - b over runs where both are finite, its 95 % half-width, and n."""
    d = [x - y for x, y in zip(a, b) if x is not None and y is not None]
    n = len(d)
    if n < 2:
        return (float("nan"), float("nan"), n)
    m = sum(d) / n
    sd = math.sqrt(sum((x - m) ** 2 for x in d) / (n - 1))
    return (m, t975(n - 1) * sd / math.sqrt(n), n)


def welch(a: list, b: list) -> tuple:
    """mean(a) - mean(b) of two independent samples, the half-width of its 95 % interval
    (Welch: Student's t at the Welch-Satterthwaite degrees of freedom, rounded down), and
    those degrees of freedom. For runs of two different worlds, which do not pair."""
    na, nb = len(a), len(b)
    ma, mb = sum(a) / na, sum(b) / nb
    va = sum((x - ma) ** 2 for x in a) / (na - 1) / na
    vb = sum((x - mb) ** 2 for x in b) / (nb - 1) / nb
    dof = (va + vb) ** 2 / (va ** 2 / (na - 1) + vb ** 2 / (nb - 1))
    return (ma - mb, t975(max(1, int(dof))) * math.sqrt(va + vb), dof)


def binomial_upper(k: int, n: int) -> float:
    """The one-sided 95 % upper bound of a share seen k times in n (Clopper-Pearson: the p
    at which k or fewer in n has probability 0.05), by bisection."""
    if k >= n:
        return 1.0
    low, high = 0.0, 1.0
    for _ in range(60):
        p = (low + high) / 2
        at_most_k = sum(math.comb(n, i) * p ** i * (1 - p) ** (n - i) for i in range(k + 1))
        low, high = (p, high) if at_most_k > 0.05 else (low, p)
    return (low + high) / 2


def verdict(mean: float, half: float) -> str:
    """'tie' when the interval mean +- half holds zero, else 'lower' or 'higher'."""
    return "tie" if not abs(mean) > half else ("lower" if mean < 0 else "higher")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mc_json")
    ap.add_argument("--vary", required=True, help="a sweep key, or 'estimator'")
    ap.add_argument("--base", required=True, help="the value of the varied key compared against")
    ap.add_argument("--estimator", help="only this estimator (when varying a sweep key)")
    args = ap.parse_args()
    cells = json.load(open(args.mc_json))["cells"]
    if any("run_mean_errors_m" not in c for c in cells):
        sys.exit(f"{args.mc_json}: no run_mean_errors_m (written by onebeacon from issue 29 on); re-run mc")

    def value(c):
        return c["estimator"] if args.vary == "estimator" else str(c["sweep"].get(args.vary))

    def rest(c):
        sweep = {k: v for k, v in c["sweep"].items() if k != args.vary}
        est = None if args.vary == "estimator" else c["estimator"]
        return (json.dumps(sweep, sort_keys=True), c["vehicle"], est)

    if args.vary != "estimator" and not any(args.vary in c["sweep"] for c in cells):
        sys.exit(f"no sweep key {args.vary!r}; keys: {sorted(cells[0]['sweep'])} or 'estimator'")
    groups = {}
    for c in cells:
        if args.estimator and c["estimator"] != args.estimator:
            continue
        groups.setdefault(rest(c), {})[value(c)] = c
    print(f"{'cell':48} {args.vary + ' vs ' + args.base:28} {'mean diff m':>11} {'95 % CI':>20} {'n':>4}  verdict")
    for key, by in sorted(groups.items()):
        if args.base not in by:
            continue
        base = by[args.base]
        for v, c in sorted(by.items()):
            if v == args.base:
                continue
            m, h, n = paired(c["run_mean_errors_m"], base["run_mean_errors_m"])
            sweep, vehicle, est = key
            label = " ".join(f"{k}={x}" for k, x in json.loads(sweep).items()) + (f" {est}" if est else "")
            print(f"{label:48} {v:28} {m:+11.3f} {f'[{m - h:+.3f}, {m + h:+.3f}]':>20} {n:4d}  {verdict(m, h)}")


if __name__ == "__main__":
    main()
