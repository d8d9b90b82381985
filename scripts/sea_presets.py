#!/usr/bin/env python3
"""The values of the -sea presets, where each comes from, and what the unsourced ones cost.

Every value of an error source of scenarios/*-sea.toml (each `[sea.*]` table, and a
passive_usbl world's `[current]`) carries a comment that starts with "source:" (a paper's
section, table or figure; a datasheet; a fit on a shipped log with its command) or with
"unsourced"; the comment may go on over lines of their own below the value.

  scripts/sea_presets.py count            per preset: values, sourced, unsourced (exit 1
                                          when a value says neither, naming it)
  scripts/sea_presets.py list [--unsourced]   every value: preset, key, value, status
  scripts/sea_presets.py ablate PRESET [--runs N] [--estimator NAME] [--abstract-pings] [--bin BIN] [--out DIR]
        each unsourced value of scenarios/PRESET.toml set to its default (the key removed:
        off for every key but `loss_burst_mean`, whose default loses each message alone;
        a list the preset cannot lose alone, as a cast's depths, takes its table with it),
        halved where the preset is refused without it (as `false_max_range_m` while
        `false_prob` is set), kept, and doubled (a direction turned by 180 deg instead; a
        probability whose double reaches 1 and a list are not doubled; a variant the
        key's range refuses is said so): `onebeacon mc
        --json` on the preset's base cell (its sweep dropped) for each, with its runs (or
        --runs), the same seeds in every variant. Prints the estimator's (default: the
        preset's first) mean error, m, as set (95 % interval of the mean), and each
        variant's change from it, paired by run (95 % interval), and writes them to
        DIR/ablate.json (default /tmp/sea_presets_PRESET). A fleet preset (rypkema's) runs
        `onebeacon fleet --runs 1 --seed S --json` once per run (S: the preset's seed plus
        the run's index) and takes each estimator's fleet-wide mean error as the run's;
        --abstract-pings draws its pings the abstract way (`signal.model`: seconds a run
        instead of half a minute).
"""
import argparse
import json
import pathlib
import re
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import sea_ablation  # noqa: E402  (its blocks, is_source and summary)
from paired import paired  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
VALUE = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*=\s*(.*?)\s*(?:#\s*(.*))?$")


class Unmarked(Exception):
    """A value whose comment says neither "source:" nor "unsourced"."""


def values(path):
    """The error sources' values of the preset at `path`: a list of dicts (table, key,
    value as written, status "sourced" / "unsourced", comment)."""
    out = []
    for header, lines in sea_ablation.blocks(path.read_text()):
        if not sea_ablation.is_source(header):
            continue
        for line in lines[1:]:
            stripped = line.strip()
            if stripped.startswith("#") and out and out[-1]["table"] == header and out[-1]["open"]:
                out[-1]["comment"] += " " + stripped.lstrip("#").strip()
                continue
            if out:
                out[-1]["open"] = False
            m = VALUE.match(stripped)
            if not m:
                continue
            key, value, comment = m.group(1), m.group(2), (m.group(3) or "").strip()
            if comment.startswith("source:"):
                status = "sourced"
            elif comment.startswith("unsourced"):
                status = "unsourced"
            else:
                raise Unmarked(f"{path.name}: [{header}] {key} = {value}: its comment starts with neither "
                               f"'source:' nor 'unsourced' ({comment or 'no comment'})")
            out.append(dict(table=header, key=key, value=value, status=status, comment=comment, open=True))
    for v in out:
        del v["open"]
    return out


def presets():
    """The -sea presets' paths, by name."""
    return sorted((ROOT / "scenarios").glob("*-sea.toml"))


def counts():
    """[(preset, values, sourced, unsourced)] over every -sea preset."""
    rows = []
    for p in presets():
        vs = values(p)
        sourced = sum(v["status"] == "sourced" for v in vs)
        rows.append((p.stem, len(vs), sourced, len(vs) - sourced))
    return rows


def variants(text, value, removable=True):
    """The ablation variants of one unsourced value in the preset text `text` (its sweep
    dropped): [(label, toml)]: "default" (the key removed; a list that is not
    `removable` alone takes its table with it) or, for a scalar that is not removable,
    "x0.5"; "as set"; and, where it makes sense, "x2" or "+180 deg"."""
    parts = [(h, ls) for h, ls in sea_ablation.blocks(text) if h != "sweep"]

    def edit(new_line, drop_table=False):
        out = ""
        for header, lines in parts:
            if header != value["table"]:
                out += "".join(lines)
                continue
            if drop_table:
                continue
            skip = False
            for line in lines:
                m = VALUE.match(line.strip())
                if m and m.group(1) == value["key"]:
                    skip = True
                    if new_line is not None:
                        out += new_line + "\n"
                    continue
                if skip and line.strip().startswith("#"):
                    continue
                skip = False
                out += line
        return out

    key = value["key"]
    try:
        x = float(value["value"])
    except ValueError:
        x = None
    if removable:
        rows = [("default", edit(None))]
    elif x is None:
        rows = [(f"without [{value['table']}]", edit(None, drop_table=True))]
    else:
        rows = [("x0.5", edit(f"{key} = {x / 2!r}"))]
    rows.append(("as set", edit(f"{key} = {value['value']}")))
    if x is None:
        return rows
    if key == "toward_deg":
        rows.append(("+180 deg", edit(f"{key} = {(x + 180.0) % 360.0}")))
    elif not (key.endswith("_prob") and 2 * x >= 1.0):
        rows.append(("x2", edit(f"{key} = {2 * x!r}")))
    return rows


def ablate(preset, runs=None, binary=str(ROOT / "target/release/onebeacon"), out=None, progress=True,
           estimator=None, transform=None):
    """Runs every unsourced value's variants of scenarios/PRESET.toml (identical variants
    once). Returns the estimator's name (`estimator`, default the preset's first) and
    [(table, key, value, as_set, changes)]. `transform`, when given, rewrites the preset's text
    before its variants are made (`abstract_pings`, or a shorter mission):
    as_set its (mean error, 95 % half-width, NEES, runs) with the preset as it is, changes
    [(label, mean change of the run means, 95 % half-width, runs)] paired by run."""
    path = ROOT / "scenarios" / f"{preset}.toml"
    if not path.is_file():
        sys.exit(f"{preset}: no such preset (scenarios/*-sea.toml: {', '.join(p.stem for p in presets())})")
    text = path.read_text()
    if transform:
        text = transform(text)
    out = pathlib.Path(out or f"/tmp/sea_presets_{preset}")
    out.mkdir(parents=True, exist_ok=True)
    first, rows, cache = estimator, [], {}

    def cells(toml):
        if toml not in cache:
            cache[toml] = run(toml, out / f"variant-{len(cache)}.toml", runs, binary)
        return cache[toml]

    unsourced = [v for v in values(path) if v["status"] == "unsourced"]
    for i, v in enumerate(unsourced):
        found = {}
        todo = variants(text, v)
        if cells(todo[0][1]) is None:  # refused without the key alone
            todo = variants(text, v, removable=False)
        for label, toml in todo:
            got = cells(toml)
            if got is None:
                if label == "as set":
                    sys.exit(f"{preset}: onebeacon refused the preset itself (see {out})")
                found[label] = None  # a value outside what the key takes (a salinity of 60 ppt)
                continue
            first = first or got[0]["estimator"]
            found[label] = next((c for c in got if c["estimator"] == first), None)
            if found[label] is None:
                sys.exit(f"{preset}: no estimator `{first}` (it has {', '.join(c['estimator'] for c in got)})")
        base = found.pop("as set")
        changes = [(label, *paired(c["run_mean_errors_m"], base["run_mean_errors_m"])) if c else (label, None, None, 0)
                   for label, c in found.items()]
        rows.append((v["table"], v["key"], v["value"], sea_ablation.summary(base), changes))
        if progress:
            print(f"{preset} {i + 1}/{len(unsourced)}: [{v['table']}] {v['key']}", file=sys.stderr, flush=True)
    (out / "ablate.json").write_text(json.dumps({"estimator": first, "rows": rows}, indent=1))
    return first, rows


def abstract_pings(text):
    """A fleet preset's text with its pings drawn the abstract way (`signal.model`)."""
    return re.sub(r'(?m)^model = "channel"', 'model = "abstract"', text)


def run(toml, path, runs, binary):
    """`onebeacon mc PATH --json [--runs N]` on `toml`: its cells, or None when refused. A
    fleet: `onebeacon fleet PATH --runs 1 --seed S --json` for each run, as mc's cells (per
    estimator its fleet-wide mean error of each run, and the mean of their NEES)."""
    path.write_text(toml)
    if not re.search(r'(?m)^kind\s*=\s*"fleet"', toml):
        done = onebeacon(binary, "mc", str(path), "--json", *(["--runs", str(runs)] if runs else []))
        return done and json.loads(done)["cells"]
    setting = lambda key, default: int(m.group(1)) if (m := re.search(rf"(?m)^{key}\s*=\s*(\d+)", toml)) else default
    by = {}
    for i in range(runs or setting("runs", 1)):
        done = onebeacon(binary, "fleet", str(path), "--runs", "1", "--seed", str(setting("seed", 1) + i), "--json",
                         "--out", str(path.with_suffix("")) + "-fleet")  # its plots and tracks
        if done is None:
            return None
        for p in json.loads(done)["statistics"]["fleet"]:
            by.setdefault(p["label"].removeprefix("fleet/"), []).append(p)
    return [{"estimator": e, "run_mean_errors_m": [p["mean_m"] for p in ps],
             "nees_mean_all_runs": sum(p["nees_mean"] for p in ps) / len(ps)} for e, ps in by.items()]


def onebeacon(binary, *args):
    """The stdout of `onebeacon ARGS`, or None when it refuses its input (exit 2); any
    other failure ends the script with its stderr."""
    done = subprocess.run([binary, *args], capture_output=True, text=True)
    if done.returncode == 2:
        return None
    if done.returncode != 0:
        sys.exit(f"onebeacon {' '.join(args)} failed ({done.returncode}): {done.stderr.strip()}")
    return done.stdout


def change(entry):
    """A variant's paired change: "+1.23 (+-0.45) m" (the interval's half-width), or
    "refused" when the value is outside what its key takes."""
    label, mean, half, _ = entry
    return f"{label} refused (outside the key's range)" if mean is None else f"{label} {mean:+.2f} (+-{half:.2f})"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    sub.add_parser("count")
    ls = sub.add_parser("list")
    ls.add_argument("--unsourced", action="store_true")
    ab = sub.add_parser("ablate")
    ab.add_argument("preset")
    ab.add_argument("--runs", type=int)
    ab.add_argument("--estimator")
    ab.add_argument("--abstract-pings", action="store_true")
    ab.add_argument("--bin", default=str(ROOT / "target/release/onebeacon"))
    ab.add_argument("--out")
    a = ap.parse_args()
    try:
        if a.command == "count":
            rows = counts()
            print("| preset | values | sourced | unsourced |\n|---|---|---|---|")
            for name, n, s, u in rows:
                print(f"| {name} | {n} | {s} | {u} |")
            n, s = sum(r[1] for r in rows), sum(r[2] for r in rows)
            print(f"| all | {n} | {s} ({100 * s / n:.0f} %) | {n - s} |")
        elif a.command == "list":
            for p in presets():
                for v in values(p):
                    if not a.unsourced or v["status"] == "unsourced":
                        print(f"{p.stem}\t[{v['table']}] {v['key']} = {v['value']}\t{v['status']}\t{v['comment']}")
        else:
            first, rows = ablate(a.preset, a.runs, a.bin, a.out, estimator=a.estimator,
                                 transform=abstract_pings if a.abstract_pings else None)
            print(f"{a.preset}, base cell, {first}: mean error as set, m (95 % interval of the mean); "
                  "each variant's change from it, paired by run, m (95 %)")
            for table, key, value, (mean, half, _, n), changes in rows:
                print(f"[{table}] {key} = {value}: as set {mean:.2f} (+-{half:.2f}), {n} runs; "
                      + "; ".join(change(c) for c in changes))
    except Unmarked as e:
        sys.exit(str(e))


if __name__ == "__main__":
    main()
