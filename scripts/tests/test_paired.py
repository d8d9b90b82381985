"""scripts/paired.py's Welch interval (two worlds' runs, unpaired): the closed form of equal
variances and sizes, and its coverage against its nominal 95 % on unequal variances; its
binomial upper bound against closed forms."""
import math
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import paired  # noqa: E402


def test_equal_variances_and_sizes_give_the_pooled_interval():
    # a and b: variance 2.5 each, 5 values: standard error sqrt(0.5 + 0.5) = 1, Welch's
    # degrees of freedom 2 n - 2 = 8, half-width t(0.975, 8) = 2.306
    m, h, dof = paired.welch([1, 2, 3, 4, 5], [2, 3, 4, 5, 6])
    assert m == -1 and abs(dof - 8) < 1e-12 and abs(h - 2.306) < 1e-12


def test_the_interval_covers_the_true_difference_95_times_in_100():
    # 5 runs against 5 with standard deviations 1 and 4 (a world whose runs spread more):
    # Welch's degrees of freedom come out near 4. 2000 trials: a 95 % interval covers the
    # truth in 1900 +- 3 binomial sd (29) of them (this seed: 1912). The normal's 1.96
    # covers 1791 and fails; Student's t at the pooled 2 n - 2 = 8 degrees of freedom
    # covers 1866 and fails.
    rng = random.Random(11)
    trials, covered = 2000, 0
    for _ in range(trials):
        a = [rng.gauss(1.0, 1.0) for _ in range(5)]
        b = [rng.gauss(0.5, 4.0) for _ in range(5)]
        m, h, _ = paired.welch(a, b)
        covered += abs(m - 0.5) <= h
    sd = math.sqrt(trials * 0.95 * 0.05)
    assert abs(covered - 0.95 * trials) <= 3 * sd, f"{covered} of {trials} intervals cover the truth"


def test_the_binomial_upper_bound_meets_its_closed_forms():
    # none seen in n: (1 - p)^n = 0.05, p = 1 - 0.05^(1/n) (300 runs: 0.99 %, near the
    # "rule of three" 3 / n); n - 1 seen in n: 1 - p^n = 0.05, p = 0.95^(1/n)
    assert abs(paired.binomial_upper(0, 300) - (1 - 0.05 ** (1 / 300))) < 1e-12
    assert abs(paired.binomial_upper(9, 10) - 0.95 ** (1 / 10)) < 1e-12
    # a middle value against a brute-force scan of the binomial's tail
    n, k = 300, 3
    tail = lambda p: sum(math.comb(n, i) * p ** i * (1 - p) ** (n - i) for i in range(k + 1))
    scan = next(j / 1e5 for j in range(1, 100000) if tail(j / 1e5) <= 0.05)
    assert abs(paired.binomial_upper(k, n) - scan) <= 1e-5


def campaign(errors, seed=1, scenario="s", nees=2.0):
    """An `mc` JSON of one cell per estimator: its run mean errors, their mean, every
    run's NEES `nees`."""
    return {"scenario": scenario, "seed": seed, "runs": len(next(iter(errors.values()))),
            "cells": [{"sweep": {"guidance": "det"}, "vehicle": "auv", "estimator": e, "run_mean_errors_m": r,
                       "mean_error_m": sum(r) / len(r), "nees_mean": nees, "run_nees": [nees] * len(r)}
                      for e, r in errors.items()]}


def test_a_build_against_the_one_before_pairs_the_same_cells_run_by_run():
    old = campaign({"pf": [1.0, 2.0, 3.0, 4.0], "ekf": [5.0, 6.0, 7.0, 8.0]})
    # pf: every run 0.25 m lower, the differences 0.2, 0.3, 0.2, 0.3 (mean 0.25, sd
    # sqrt(1/300)): half-width t(0.975, 3) sd / 2 = 3.182 x 0.02887; ekf unchanged
    new = campaign({"ekf": [5.0, 6.0, 7.0, 8.0], "pf": [0.8, 1.7, 2.8, 3.7]}, nees=2.5)
    rows = {key[2]: row for key, *row in paired.before_and_after(new, old)}
    _, _, m, h, n, _, _, same, nees = rows["pf"]
    assert abs(m + 0.25) < 1e-12 and n == 4 and not same
    assert abs(h - 3.182 * math.sqrt(1 / 300) / 2) < 1e-12
    assert paired.verdict(m, h) == "lower"
    assert nees == (0.5, 0.0, 4)  # every run's NEES 0.5 higher: no spread
    assert rows["ekf"][-2] and rows["ekf"][2] == 0.0


def test_two_campaigns_that_differ_in_seed_runs_or_cells_are_refused():
    old = campaign({"pf": [1.0, 2.0]})
    for new, what in ((campaign({"pf": [1.0, 2.0]}, seed=2), "seed"), (campaign({"pf": [1.0, 2.0, 3.0]}), "runs"),
                      (campaign({"ekf": [1.0, 2.0]}), "cells")):
        try:
            paired.before_and_after(new, old)
        except ValueError as e:
            assert what in str(e), e
        else:
            raise AssertionError(f"a campaign of another {what} was compared")
