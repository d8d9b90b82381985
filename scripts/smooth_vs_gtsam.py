#!/usr/bin/env python3
"""onebeacon's smoother side by side with GTSAM 4.3 on the plaza logs (docs/smooth.md).

For plaza1 and plaza2, all beacons and each alone: RMSE against the ground truth of dead
reckoning, two of the log's filters as shipped (ekf-cal, with noise chosen on both logs,
and ekf-cal-oos, with noise fitted on the other log) and their Rauch-Tung-Striebel passes
(`+rts`, from `smooth`), `onebeacon smooth` without calibration variables, with its
default ones (range and turn scale) and weighing as ekf-cal-oos (`--like`), and GTSAM's batch
LM (`../shared/bench/gtsam_smooth.py`: range scale 1, and the scale as a graph variable,
`--scale est`). Then the time of one solve, back to back, in rounds: `onebeacon smooth`
with the range scale as a variable (its solve, log reading apart) against GTSAM's LM with
its built-in factors on ranges divided by the fitted scale (`--scale fit`, its solve).

Usage, from the project root (GTSAM: `pip install gtsam==4.3.0 numpy` in PY's environment):
  python3 scripts/smooth_vs_gtsam.py [--bin target/release/onebeacon] [--python PY]
      [--rounds 3] [--no-est] [--out DIR]
Writes DIR/results.jsonl (one line per run) and prints three markdown tables: RMSE, LM
iterations with the same factors (no kernel; range scale 1, and the scale as a variable
with GTSAM's prior of 0.1, `--like` an estimator written to DIR/same_factors.toml), and
time.
"""
import argparse, json, os, statistics, subprocess, sys

BENCH = os.path.join('..', 'shared', 'bench', 'gtsam_smooth.py')
LOGS = {'plaza1': [None, 0, 1, 5, 6], 'plaza2': [None, 0, 1, 5, 6]}
FILTERS = ['dead-reckoning', 'ekf-cal', 'ekf-cal+rts', 'ekf-cal-oos', 'ekf-cal-oos+rts']


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def ours(a, log, beacon, *flags):
    cmd = [a.bin, 'smooth', f'data/plaza/{log}.toml', '--json', '--out', os.path.join(a.out, 'smooth')]
    if beacon is not None:
        cmd += ['--beacons', str(beacon)]
    s = run(cmd + list(flags))
    return {e['name']: e for e in s['estimators']}


def gtsam(a, log, beacon, *flags):
    cmd = [a.python, BENCH, log, '--beacons', 'all' if beacon is None else str(beacon)] + list(flags)
    return run(cmd)


# an estimator whose weighing `smooth --like` copies: the range scale's prior as GTSAM's
# bench gives it (0.1), every other noise at the log's
SAME_FACTORS = '''[[estimators]]
name = "dead-reckoning"
kind = "dead-reckoning"

[[estimators]]
name = "gtsam-bench"
kind = "range-ekf"
estimate_range_scale = true
range_scale_sigma = 0.1
'''


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--bin', default='target/release/onebeacon')
    ap.add_argument('--python', default=sys.executable)
    ap.add_argument('--rounds', type=int, default=3)
    ap.add_argument('--no-est', action='store_true', help='skip GTSAM with the scale as a variable (slow: a Python factor)')
    ap.add_argument('--out', default='out/smooth_vs_gtsam')
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    results = open(os.path.join(a.out, 'results.jsonl'), 'w')
    same = os.path.join(a.out, 'same_factors.toml')
    with open(same, 'w') as f:
        f.write(SAME_FACTORS)
    rows, its = [], []
    for log, beacons in LOGS.items():
        for b in beacons:
            print(f'{log} beacons {"all" if b is None else b} ...', file=sys.stderr, flush=True)
            cal = ours(a, log, b)
            nocal = ours(a, log, b, '--calibrate', 'none')
            oos = ours(a, log, b, '--like', 'ekf-cal-oos')
            g1 = gtsam(a, log, b)
            ge = None if a.no_est else gtsam(a, log, b, '--scale', 'est')
            rec = {'log': log, 'beacons': 'all' if b is None else b,
                   **{f: cal[f]['rmse_m'] for f in FILTERS},
                   'smooth_nocal': nocal['smoother']['rmse_m'], 'smooth_nocal_nees': nocal['smoother']['nees_mean'],
                   'smooth': cal['smoother']['rmse_m'], 'smooth_nees': cal['smoother']['nees_mean'],
                   'smooth_nees_band': cal['smoother']['nees_band'],
                   'smooth_oos': oos['smoother']['rmse_m'], 'smooth_oos_nees': oos['smoother']['nees_mean'],
                   'gtsam_lm': g1['rmse'], 'gtsam_lm_scale_est': ge['rmse'] if ge else None}
            results.write(json.dumps(rec) + '\n')
            rows.append(rec)
            # LM iterations with the same factors: no kernel, scale 1 / the scale a variable
            plain = ours(a, log, b, '--calibrate', 'none', '--kernel', 'none')['smoother']
            scaled = None if a.no_est else ours(a, log, b, '--estimators', same, '--like', 'gtsam-bench',
                                                 '--calibrate', 'range_scale', '--kernel', 'none')['smoother']
            it = {'log': log, 'beacons': 'all' if b is None else b,
                  'ours': (plain['iterations'], plain['cost']['final']), 'gtsam': (g1['iterations'], g1['error']),
                  'ours_est': scaled and (scaled['iterations'], scaled['cost']['final']),
                  'gtsam_est': ge and (ge['iterations'], ge['error'])}
            results.write(json.dumps({'iterations': it}) + '\n')
            its.append(it)
    f = lambda v: '-' if v is None else f'{v:.2f}'
    print('| log | beacons | dead reckoning | ekf-cal | + RTS | ekf-cal-oos | + RTS | smooth, no calibration (NEES) '
          '| smooth (NEES) | smooth like ekf-cal-oos (NEES) | GTSAM LM | GTSAM LM, scale variable |')
    print('|---|---|---|---|---|---|---|---|---|---|---|---|')
    for r in rows:
        print(f"| {r['log']} | {r['beacons']} | {f(r['dead-reckoning'])} | {f(r['ekf-cal'])} | {f(r['ekf-cal+rts'])} "
              f"| {f(r['ekf-cal-oos'])} | {f(r['ekf-cal-oos+rts'])} | {f(r['smooth_nocal'])} ({r['smooth_nocal_nees']:.1f}) | {f(r['smooth'])} ({r['smooth_nees']:.1f}) "
              f"| {f(r['smooth_oos'])} ({r['smooth_oos_nees']:.1f}) | {f(r['gtsam_lm'])} | {f(r['gtsam_lm_scale_est'])} |")
    print()
    print('| log | beacons | smooth, scale 1: iterations (final cost) | GTSAM LM | ratio '
          '| smooth, scale a variable | GTSAM LM | ratio |')
    print('|---|---|---|---|---|---|---|---|')
    g = lambda p: '-' if p is None else f'{p[0]} ({p[1]:.2f})'
    q = lambda o, t: '-' if o is None or t is None else f'{o[0] / t[0]:.2f}'
    for r in its:
        print(f"| {r['log']} | {r['beacons']} | {g(r['ours'])} | {g(r['gtsam'])} | {q(r['ours'], r['gtsam'])} "
              f"| {g(r['ours_est'])} | {g(r['gtsam_est'])} | {q(r['ours_est'], r['gtsam_est'])} |")
    # time, back to back
    times = {}
    for _ in range(a.rounds):
        for log in LOGS:
            s = ours(a, log, None, '--calibrate', 'range_scale', '--kernel', 'none')['smoother']
            g = gtsam(a, log, None, '--scale', 'fit')
            times.setdefault(log, {'ours': [], 'ours_read': [], 'gtsam': [], 'gtsam_build': []})
            t = times[log]
            t['ours'].append(s['solve_s'])
            t['ours_read'].append(s['build_s'])
            t['gtsam'].append(g['solve_s'])
            t['gtsam_build'].append(g['build_s'])
            results.write(json.dumps({'log': log, 'ours_solve_s': s['solve_s'], 'ours_read_s': s['build_s'],
                                      'gtsam_solve_s': g['solve_s'], 'gtsam_build_s': g['build_s'],
                                      'ours_rmse': s['rmse_m'], 'gtsam_rmse': g['rmse']}) + '\n')
    print()
    print(f'| log | smooth solve, s (min / median of {a.rounds}) | + reading the log and building | '
          'GTSAM LM solve, s | + building | ratio of solves (medians) |')
    print('|---|---|---|---|---|---|')
    for log, t in times.items():
        mo, mg = statistics.median(t['ours']), statistics.median(t['gtsam'])
        print(f"| {log} | {min(t['ours']):.3f} / {mo:.3f} | {statistics.median(t['ours_read']):.3f} "
              f"| {min(t['gtsam']):.3f} / {mg:.3f} | {statistics.median(t['gtsam_build']):.3f} | {mg / mo:.1f}x |")


if __name__ == '__main__':
    main()
