#!/usr/bin/env python3
"""Counts of the workspace's structure, for a before/after comparison (issue 28):
files over 600 lines, public items per crate, import cycles among each crate's
top-level modules, the places that build a navigator, the scoring implementations.
Test modules (after `#[cfg(test)]`) and comments are left out.

    scripts/structure.py [REPO]      (default: the repository this script is in)
"""
import os
import re
import sys

repo = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
CRATES = ["onebeacon", "onebeacon-sim", "onebeacon-cli", "onebeacon-py"]


def sources(crate):
    root = os.path.join(repo, "crates", crate, "src")
    for dp, _, fs in os.walk(root):
        for f in sorted(fs):
            if f.endswith(".rs"):
                p = os.path.join(dp, f)
                yield os.path.relpath(p, root), open(p).read()


def code(text):
    text = text.split("#[cfg(test)]")[0]
    return "\n".join(l.split("//")[0] for l in text.split("\n"))


def top(rel):
    t = rel.split("/")[0].removesuffix(".rs")
    return None if t in ("lib", "main") else t


def cycles(crate):
    g = {}
    for rel, text in sources(crate):
        t = top(rel)
        if t:
            g.setdefault(t, set()).update(d for d in re.findall(r"crate::(\w+)", code(text)) if d != t)
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in g:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in list(g):
        if v not in index:
            visit(v)
    mutual = sorted({tuple(sorted((a, b))) for a in g for b in g[a] if b in g and a in g[b]})
    return out, mutual


CONSTRUCTORS = r"\b(PlanarNavigator::(?:new|with_beacon_offsets)|TrackingNavigator::new|ParticleTracker::new|GaussianTracker::new|IusblNavigator::new|Range6DofNavigator::new|SingleBeaconNavigator::new)\("
SCORING = r"\b(struct ErrorAccumulator|struct ErrorStats|fn quantile|fn score|fn error_and_nees|fn horizontal_error|fn percentile)\b"

big, builders, scorers = [], [], []
for crate in CRATES:
    public = 0
    for rel, text in sources(crate):
        n = text.count("\n")
        if n > 600:
            big.append(f"{crate}/src/{rel} ({n})")
        c = code(text)
        public += len(re.findall(r"^\s*pub (?:fn|struct|enum|trait|const|type|mod|static|use)\b", c, re.M))
        # a place: a module that calls a navigator constructor (with its functions)
        for m in re.finditer(CONSTRUCTORS, c):
            fn = re.findall(r"fn (\w+)", c[: m.start()])
            builders.append((f"{crate}/src/{rel}", fn[-1] if fn else "?"))
        scorers += [f"{crate}/src/{rel}: {m}" for m in re.findall(SCORING, c)]
    cyc, mutual = cycles(crate)
    print(f"{crate}: {public} public items; import cycles {len(cyc)} {cyc}; mutual imports {len(mutual)} {mutual}")
print(f"files over 600 lines: {len(big)}: {', '.join(big)}")
places = {}
for module, fn in builders:
    places.setdefault(module, set()).add(fn)
listed = ", ".join(f"{m} ({', '.join(sorted(f))})" for m, f in sorted(places.items()))
print(f"modules that build navigators from specs: {len(places)}: {listed}")
print(f"scoring implementations: {len(scorers)}: {'; '.join(scorers)}")
