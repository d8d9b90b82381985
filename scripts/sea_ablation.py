#!/usr/bin/env python3
"""Each error source of a scenario's sea alone: what it costs each of its filters.

Reads a scenario file (a `-sea` built-in's, e.g. scenarios/hoff2024-sea.toml), finds its
error sources (each `[sea.*]` table, and `[current]` where the world has one), and runs
`onebeacon mc --json` on variants of it: none of them, each alone, all of them. The sweep
is dropped, so each variant is one cell (the scenario's base cell); runs and seed are the
scenario's (or --runs). Prints a table of every estimator's mean error (with the spread
of its runs' means as a 95 % interval of the mean, Student's t, every run counted) and NEES per variant, and writes it as
Markdown to OUT_DIR/ablation.md with each variant's mc.json beside it.

Usage: scripts/sea_ablation.py SCENARIO.toml [--runs N] [--bin BIN] [--out OUT_DIR]
       (default target/release/onebeacon, /tmp/ablation_NAME)
"""
import argparse
import json
import math
import pathlib
import re
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from paired import t975  # noqa: E402  (one table of Student's t)

ROOT = pathlib.Path(__file__).resolve().parent.parent


def blocks(text):
    """The file as (header, lines) blocks: the preamble (header None), then one block per
    table or array-of-tables header."""
    out, header, lines = [], None, []
    for line in text.splitlines(keepends=True):
        m = re.match(r"\s*\[\[?([^\]]+)\]\]?\s*(#.*)?$", line)
        if m:
            out.append((header, lines))
            header, lines = m.group(1).strip(), []
        lines.append(line)
    out.append((header, lines))
    return out


def is_source(header):
    return header is not None and (header.startswith("sea.") or header == "current")


def variant(parts, keep):
    """The file with only the sources in `keep` and its sweep dropped."""
    text = ""
    for header, lines in parts:
        if header == "sweep" or (is_source(header) and header not in keep):
            continue
        text += "".join(lines)
    return text


def ablate(scenario, runs=None, binary=str(ROOT / "target/release/onebeacon"), out=None):
    """Runs the variants of the scenario file `scenario`: none of its sources, each alone,
    all. Returns the variants' labels, the estimators, and per (label, estimator) the mean
    of the run means, the half-width of its 95 % interval, the mean NEES over every run and
    the run count; and `out`, where each variant's TOML and mc.json went (default
    /tmp/ablation_NAME)."""
    path = pathlib.Path(scenario)
    try:
        text = path.read_text()
    except OSError as e:
        sys.exit(f"{scenario}: {e.strerror}")
    parts = blocks(text)
    sources = [h for h, _ in parts if is_source(h)]
    if not sources:
        sys.exit(f"{scenario}: no [sea.*] or [current] table: nothing to ablate")
    name = re.search(r'^name\s*=\s*"([^"]+)"', text, re.M)
    out = pathlib.Path(out or f"/tmp/ablation_{name.group(1) if name else path.stem}")
    out.mkdir(parents=True, exist_ok=True)
    rows = [("none", [])] + [(s, [s]) for s in sources] + [("all", sources)]
    table = {}
    for label, keep in rows:
        toml = out / f"{label}.toml"
        toml.write_text(variant(parts, keep))
        cmd = [binary, "mc", str(toml), "--json"] + (["--runs", str(runs)] if runs else [])
        print(f"{label}: {' '.join(cmd)}", file=sys.stderr, flush=True)
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"{label}: onebeacon failed: {run.stderr.strip()}")
        (out / f"{label}.json").write_text(run.stdout)
        for c in json.loads(run.stdout)["cells"]:
            table[(label, c["estimator"])] = summary(c)
    estimators = list(dict.fromkeys(e for _, e in table))
    return [label for label, _ in rows], estimators, table, out


def summary(c):
    """An mc cell's mean of the run means, the half-width of its 95 % interval, the mean
    NEES over every run and the run count."""
    errs = c["run_mean_errors_m"]
    n = len(errs)
    mean = sum(errs) / n
    sd = math.sqrt(sum((e - mean) ** 2 for e in errs) / (n - 1)) if n > 1 else float("nan")
    half = t975(n - 1) * sd / math.sqrt(n) if n > 1 else float("nan")
    return (mean, half, c["nees_mean_all_runs"], n)


def cell(entry):
    """One table cell: mean error (+- the 95 % half-width) / mean NEES."""
    mean, ci, nees, _ = entry
    return f"{mean:.2f} (+-{ci:.2f}) / {nees:.1f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario")
    ap.add_argument("--runs", type=int)
    ap.add_argument("--bin", default=str(ROOT / "target/release/onebeacon"))
    ap.add_argument("--out")
    a = ap.parse_args()
    labels, estimators, table, out = ablate(a.scenario, a.runs, a.bin, a.out)
    head = "| sources | " + " | ".join(f"{e}: mean error, m (95 % CI) / NEES" for e in estimators) + " |"
    lines = [head, "|" + "---|" * (len(estimators) + 1)]
    for label in labels:
        lines.append(f"| {label} | " + " | ".join(cell(table[(label, e)]) for e in estimators) + " |")
    runs = next(iter(table.values()))[3]
    md = f"{pathlib.Path(a.scenario).name}, base cell, {runs} runs (scripts/sea_ablation.py)\n\n" + "\n".join(lines) + "\n"
    (out / "ablation.md").write_text(md)
    print(md)


if __name__ == "__main__":
    main()
