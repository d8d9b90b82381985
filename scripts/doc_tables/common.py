"""What every table's generator shares: the binary, its campaigns (run once per script
run, at RUNS' count), the table's header and the formats of its cells."""

import functools
import importlib.util
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path


ROOT = Path(__file__).resolve().parents[2]


def _script(name):
    """The module of scripts/NAME.py (their functions, one way to do each thing)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / f"scripts/{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


PAIRED = _script("paired")
SEA_SOURCES = _script("sea_sources")
OUTLIERS = _script("plaza_outliers")
LOG_PAIRED = _script("log_paired")
ABLATION = _script("sea_ablation")
PRESETS = _script("sea_presets")


def binary():
    """The onebeacon binary: $ONEBEACON_CLI, else the release build."""
    return os.environ.get("ONEBEACON_CLI", str(ROOT / "target/release/onebeacon"))


def cli(*args, progress=False):
    """Runs the binary; its stdout as text. A failure stops the script with its stderr.
    With `progress` the binary's stderr (its progress lines) goes to ours as it comes."""
    done = subprocess.run([binary(), *args], stdout=subprocess.PIPE,
                          stderr=None if progress else subprocess.PIPE, text=True)
    if done.returncode != 0:
        why = "its error above" if progress else done.stderr.strip()
        sys.exit(f"reproduce: onebeacon {' '.join(args)} failed ({done.returncode}): {why}")
    return done.stdout


# runs per cell of each campaign behind the docs' tables: (--quick, full)
RUNS = {
    "garin2024": (20, 300),
    "garin2024-sea": (20, 300),
    "garin2024-beacon": (20, 300),
    "garin2024-at-sea": (20, 300),
    "sousa": (2, 10),
    "sousa-sea": (2, 10),
    "sousa-pair": (2, 10),
    "sousa-spiral": (2, 10),
    "hoff2024-sea": (2, 10),
    "hoff2024-literal": (2, 10),
    "hoff2024-sea-long": (2, 300),
    "hoff2024-sea-floors": (2, 60),
    "hoff2024-untold-floor": (2, 20),
    # --quick also cuts the missions to 15 min and the particles to 5e4
    "hoff2024": (2, 20),
    "hoff2024-kinematic": (2, 20),
    "hoff2024-consistency": (2, 10),
    "hoff2024-current": (2, 10),
    "hoff2024-pair": (2, 10),
    # scripts/sea_ablation.py's runs per variant
    "garin2024-sea-ablation": (10, 100),
    "sousa-sea-ablation": (2, 10),
    "hoff2024-sea-ablation": (2, 10),
    # scripts/sea_presets.py ablate's runs per variant
    "garin2024-sea-unsourced": (4, 100),
    "sousa-sea-unsourced": (2, 10),
    "hoff2024-sea-unsourced": (2, 10),
    "rypkema-m1-sea-unsourced": (2, 8),
    "rypkema-m6-sea-unsourced": (2, 8),
    # scripts/sea_sources.py's runs per cell
    "sea-clock": (2, 10),
    "sea-link": (2, 10),
    "sea-sound-speed": (2, 10),
    # fleet worlds: --quick also draws pings the abstract way (signal.model)
    "rypkema": (1, 2),
    "rypkema-reference": (1, 4),
    "rypkema-sea": (1, 4),
    "rypkema-dead-reckoning": (1, 8),
}


def cli_on_toml(command, toml, *args, out=False, progress=False):
    """`onebeacon COMMAND FILE ARGS...` on the scenario text `toml`, written to a temporary
    file (and `--out` a directory beside it when `out`): its stdout (`progress`: as cli)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scenario.toml"
        path.write_text(toml)
        return cli(command, str(path), *args, *(["--out", str(Path(tmp) / "out")] if out else []),
                   progress=progress)


def mc_text(toml, runs, *args, progress=False):
    """The cells of `onebeacon mc FILE --runs RUNS --json ARGS...` on the scenario text
    `toml` (`progress`: as cli)."""
    return json.loads(cli_on_toml("mc", toml, "--runs", str(runs), "--json", *args, progress=progress))["cells"]


@functools.cache
def mc(scenario, quick):
    """The cells of `onebeacon mc SCENARIO --runs N --json` at RUNS' count, run once per
    script run; the JSON is also kept as target/reproduce/mc/SCENARIO[-quick].json."""
    runs = RUNS[scenario][0 if quick else 1]
    text = cli("mc", scenario, "--runs", str(runs), "--json", progress=not quick)
    kept = ROOT / "target/reproduce/mc" / f"{scenario}{'-quick' if quick else ''}.json"
    kept.parent.mkdir(parents=True, exist_ok=True)
    kept.write_text(text)
    return json.loads(text)["cells"]


def blocks_kept(path, keep):
    """The TOML file `path` with only its blocks (the preamble, then one per table or
    array-of-tables header: scripts/sea_ablation.py's `blocks`) for which `keep(header,
    block text)` holds."""
    return "".join(text for head, text in ((h, "".join(lines)) for h, lines in ABLATION.blocks(path.read_text()))
                   if keep(head, text))


def header(*columns):
    """A table's header row and its separator."""
    return ["|" + "|".join(f" {c} " if c else " " for c in columns) + "|", "|" + "---|" * len(columns)]


def figure(x, digits=None):
    """`x` with `digits` decimals, or with three significant figures (at least the units)."""
    return f"{x:.{digits if digits is not None else max(0, 2 - int(math.log10(max(abs(x), 1))))}f}"


def nees_figure(x):
    """A mean NEES: as `figure`, or from 1000 on as 1.8e4 (a lost filter's NEES runs to 1e16)."""
    return figure(x) if x < 1000 else re.sub(r"e\+0*", "e", f"{x:.1e}")


def spread(values, digits=None):
    """'low-high' of `values`, each a figure()."""
    return f"{figure(min(values), digits)}-{figure(max(values), digits)}"


def interval(m, h, digits=2):
    """A difference `m` with its 95 % half-width `h`: 'mean [low, high]', signed."""
    return f"{m:+.{digits}f} [{m - h:+.{digits}f}, {m + h:+.{digits}f}]"


def paired_cell(a, b, digits=2):
    """`a` - `b` paired by run (scripts/paired.py): 'mean [low, high]' of the 95 % interval."""
    m, h, _ = PAIRED.paired(a["run_mean_errors_m"], b["run_mean_errors_m"])
    return interval(m, h, digits)


def verdict_counts(pairs):
    """For each (a, b) of mc cells, `a` - `b` paired by run: the cells where `a` is lower /
    ties / is higher ('3 / 12 / 1'), and the mean differences."""
    counts, means = {"lower": 0, "tie": 0, "higher": 0}, []
    for a, b in pairs:
        m, h, _ = PAIRED.paired(a["run_mean_errors_m"], b["run_mean_errors_m"])
        counts[PAIRED.verdict(m, h)] += 1
        means.append(m)
    return " / ".join(str(n) for n in counts.values()), means
