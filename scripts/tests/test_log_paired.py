"""scripts/log_paired.py: its RMSE difference against a brute force, its interval's
coverage against its nominal 95 % on errors of known RMSE."""
import math
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import log_paired  # noqa: E402


def rayleigh(rng, sigma, n):
    """Horizontal errors of a 2-D Gaussian of sigma per axis: RMSE sigma * sqrt(2)."""
    return [math.hypot(rng.gauss(0, sigma), rng.gauss(0, sigma)) for _ in range(n)]


def test_the_difference_is_the_whole_logs_rmse_difference():
    rng = random.Random(1)
    a, b = rayleigh(rng, 1.0, 997), rayleigh(rng, 1.3, 997)
    brute = math.sqrt(sum(x * x for x in a) / len(a)) - math.sqrt(sum(x * x for x in b) / len(b))
    m, h, k = log_paired.compare(a, b, 10)
    assert abs(m - brute) < 1e-12 and h > 0 and k == 10


def test_the_interval_covers_the_true_difference_95_times_in_100():
    # independent rows, true difference sqrt(2) (1.0 - 1.1); 2000 logs of 200 rows: a 95 %
    # interval covers the truth in 1900 +- 3 binomial sd (29) of them. The normal's 1.96
    # in place of Student's t at 9 dof covers 92 % and fails.
    rng = random.Random(7)
    truth = math.sqrt(2) * (1.0 - 1.1)
    trials, covered = 2000, 0
    for _ in range(trials):
        m, h, _ = log_paired.compare(rayleigh(rng, 1.0, 200), rayleigh(rng, 1.1, 200), 10)
        covered += abs(m - truth) <= h
    sd = math.sqrt(trials * 0.95 * 0.05)
    assert abs(covered - 0.95 * trials) <= 3 * sd, f"{covered} of {trials} intervals cover the truth"


def test_a_log_too_short_for_its_stretches_is_refused():
    try:
        log_paired.compare([1.0] * 15, [1.0] * 15, 10)
    except ValueError as e:
        assert "15 rows" in str(e)
    else:
        raise AssertionError("15 rows cut into 10 stretches was accepted")
