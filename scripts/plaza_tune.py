#!/usr/bin/env python3
"""Tunes the plaza estimators on one log and tests them on the other (issue 12):
`onebeacon tune` on plaza1 and on plaza2, then `onebeacon replay --estimators` of each
tuned file on both logs, with all beacons and each single beacon. Prints markdown
tables of RMSE and mean NEES per estimator (in-sample: tuned and tested on the same
log; out-of-sample: tested on the other).

    python3 scripts/plaza_tune.py [DIR] [--bin PATH] [--keys K1,K2] [--each-beacon]

--keys and --each-beacon are passed to `onebeacon tune` (default: its four keys, all
beacons together).

Only the standard library is used; the binary defaults to target/release/onebeacon."""
import json, os, subprocess, sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")

def run(binary, *args):
    out = subprocess.run([binary, *args], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"{' '.join(args)}: {out.stderr.strip()}")
    return json.loads(out.stdout)

def main():
    args = sys.argv[1:]
    binary = os.path.join(ROOT, "target", "release", "onebeacon")
    if "--bin" in args:
        i = args.index("--bin")
        binary = args[i + 1]
        del args[i:i + 2]
    extra = []
    if "--keys" in args:
        i = args.index("--keys")
        extra += ["--keys", args[i + 1]]
        del args[i:i + 2]
    if "--each-beacon" in args:
        args.remove("--each-beacon")
        extra.append("--each-beacon")
    out = args[0] if args else os.path.join(ROOT, "out", "plaza-tune")
    logs = {n: os.path.join(ROOT, "data", "plaza", f"{n}.toml") for n in ["plaza1", "plaza2"]}
    tuned = {}
    for name, log in logs.items():
        d = os.path.join(out, f"tune-{name}")
        run(binary, "tune", log, "--out", d, "--json", *extra)
        tuned[name] = os.path.join(d, "estimators.toml")
    for test, log in logs.items():
        beacons = sorted(int(b) for b in run(binary, "replay", log, "--json", "--out", os.path.join(out, "probe"))["beacons"])
        sets = [None] + [[b] for b in beacons]
        for tuned_on in ["untuned", "plaza1", "plaza2"]:
            sample = "" if tuned_on == "untuned" else (" (in-sample)" if tuned_on == test else " (out-of-sample)")
            print(f"\n### {test}, estimators {'as shipped' if tuned_on == 'untuned' else 'tuned on ' + tuned_on}{sample}\n")
            header = "| estimator | " + " | ".join("all beacons" if s is None else f"beacon {s[0]}" for s in sets) + " |"
            print(header)
            print("|---" * (len(sets) + 1) + "|")
            rows = {}
            for s in sets:
                cmd = ["replay", log, "--json", "--out", os.path.join(out, f"r-{test}-{tuned_on}-{'all' if s is None else s[0]}")]
                if tuned_on != "untuned":
                    cmd += ["--estimators", tuned[tuned_on]]
                if s is not None:
                    cmd += ["--beacons", str(s[0])]
                for e in run(binary, *cmd)["estimators"]:
                    nees = e["nees_mean"]
                    rows.setdefault(e["name"], []).append(f"{e['rmse_m']:.2f} m, NEES {nees:.1f}" if nees is not None else f"{e['rmse_m']:.2f} m")
            for name, cells in rows.items():
                print(f"| {name} | " + " | ".join(cells) + " |")

main()
