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
  scripts/paired.py MC_JSON --before OLD_MC_JSON
Every other entry of the varied key is compared with --base within each cell; negative
means lower error than the base. With --before, every cell of MC_JSON against the same
cell of OLD_MC_JSON: the same scenario, seed and runs from another build (what a change
that moves the bits does to each figure), the mean error and (where both campaigns carry
run_nees) the NEES paired by run; negative means lower than before.
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


def cell_key(c) -> tuple:
    """A cell's place in a campaign: its sweep values, vehicle and estimator."""
    return (json.dumps(c["sweep"], sort_keys=True), c["vehicle"], c["estimator"])


def before_and_after(new: dict, old: dict) -> list:
    """Every cell of the campaign `new` against the same cell of `old` (two builds' `mc`
    JSON of one scenario, seed and run count), paired by run: (cell key, new mean error,
    old mean error, mean difference, its 95 % half-width, n, new NEES, old NEES, whether
    the runs are the same to the bit, the NEES's paired (difference, half-width, n) or
    None when a campaign has no run_nees). A ValueError names what does not match."""
    for field in ("scenario", "seed", "runs"):
        if new.get(field) != old.get(field):
            raise ValueError(f"the two campaigns differ in {field}: {new.get(field)!r} and {old.get(field)!r}")
    before = {cell_key(c): c for c in old["cells"]}
    missing = [k for k in map(cell_key, new["cells"]) if k not in before]
    if missing or len(before) != len(new["cells"]):
        raise ValueError(f"the two campaigns hold different cells (first not in both: {(missing or list(before))[0]})")
    rows = []
    for c in new["cells"]:
        o = before[cell_key(c)]
        m, h, n = paired(c["run_mean_errors_m"], o["run_mean_errors_m"])
        nees = paired(c["run_nees"], o["run_nees"]) if "run_nees" in c and "run_nees" in o else None
        rows.append((cell_key(c), c["mean_error_m"], o["mean_error_m"], m, h, n, c["nees_mean"], o["nees_mean"],
                     c["run_mean_errors_m"] == o["run_mean_errors_m"], nees))
    return rows


def print_before_and_after(path: str, before_path: str) -> None:
    """`before_and_after` as a Markdown table."""
    new, old = json.load(open(path)), json.load(open(before_path))
    try:
        rows = before_and_after(new, old)
    except ValueError as e:
        print(f"paired.py: {path} against {before_path}: {e}", file=sys.stderr)
        sys.exit(2)
    print(f"{new['scenario']}, {new['runs']} runs per cell, seed {new['seed']}: this build - the one before, paired by run")
    print("| cell | vehicle | estimator | mean error, m (before) | difference, m [95 %] | verdict | NEES (before) "
          "| NEES difference [95 %] |")
    print("|---|---|---|---|---|---|---|---|")
    for (sweep, vehicle, est), m_new, m_old, m, h, n, nees_new, nees_old, same, nees in rows:
        label = " ".join(f"{k}={x}" for k, x in json.loads(sweep).items()) or "-"
        if same:
            diff, word = "same, to the bit", "same"
        elif n < 2:
            diff, word = f"{m_new - m_old:+.4f} (no interval: {n} run)", "-"
        else:
            diff, word = f"{m:+.4f} [{m - h:+.4f}, {m + h:+.4f}]", verdict(m, h)
        nees_diff = "-" if nees is None or not nees[2] > 1 else f"{nees[0]:+.3f} [{nees[0] - nees[1]:+.3f}, {nees[0] + nees[1]:+.3f}]"
        print(f"| {label} | {vehicle} | {est} | {m_new:.4f} ({m_old:.4f}) | {diff} | {word} "
              f"| {figure(nees_new)} ({figure(nees_old)}) | {nees_diff} |")


def figure(x) -> str:
    """A NEES, or '-' where an estimator has none (null in the JSON)."""
    return "-" if x is None else f"{x:.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mc_json")
    ap.add_argument("--vary", help="a sweep key, or 'estimator'")
    ap.add_argument("--base", help="the value of the varied key compared against")
    ap.add_argument("--estimator", help="only this estimator (when varying a sweep key)")
    ap.add_argument("--before", metavar="OLD_MC_JSON", help="the same campaign from another build")
    args = ap.parse_args()
    if args.before is not None:
        if args.vary or args.base or args.estimator:
            ap.error("--before compares every cell: drop --vary, --base and --estimator")
        return print_before_and_after(args.mc_json, args.before)
    if not (args.vary and args.base):
        ap.error("give --vary and --base (or --before OLD_MC_JSON)")
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
