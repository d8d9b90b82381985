#!/usr/bin/env python3
"""Counts of the workspace's structure, for a before/after comparison (issues 28, 54):
files over 600 lines of code, public items per crate, import cycles among each crate's
top-level modules and file-level loops inside each folder, the places that build a
navigator, the places that describe a vehicle's computer, the lines outside measure/
that compute a range, a bearing or a Doppler speed, the scoring implementations.
Test-only items (each `#[cfg(test)]` item), comments and string contents are left out,
as crates/onebeacon-sim/tests/layers.rs reads them.

    scripts/structure.py [REPO]      (default: the repository this script is in)
"""
import os
import re
import sys

repo = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
CRATES = ["onebeacon", "onebeacon-sim", "onebeacon-cli", "onebeacon-py"]


def module_of(rel):
    """The module path of a source file relative to its crate's src/."""
    parts = rel.removesuffix(".rs").split("/")
    return tuple(parts[:-1] if parts[-1] in ("mod", "lib", "main") else parts)


def sources(crate):
    """(path relative to src/, text) of each file of `crate` but the test-only ones: a
    file its parent declares only under `#[cfg(test)]`, and the files under it."""
    root = os.path.join(repo, "crates", crate, "src")
    found = []
    for dp, _, fs in os.walk(root):
        for f in sorted(fs):
            if f.endswith(".rs"):
                p = os.path.join(dp, f)
                found.append((os.path.relpath(p, root), open(p).read()))
    declared = {}
    for rel, text in sorted(found, key=lambda f: len(module_of(f[0]))):
        m = module_of(rel)
        if not m or m[-1] in declared.get(m[:-1], ()):
            declared[m] = set(re.findall(r"\bmod (\w+)\s*;", code(text)))
    return [(rel, text) for rel, text in found if module_of(rel) in declared]


LITERAL = re.compile(r'//[^\n]*|/\*.*?\*/|r(#*)".*?"\1|"(?:\\.|[^"\\])*"|\'(?:\\.|[^\\\'])\'', re.S)


def code(text):
    """The text without comments, literals' contents and test-only items, newlines kept."""
    def blank(m):
        t = m.group(0)
        keep = "\n" * t.count("\n")
        return keep if t.startswith("/") else '""' + keep if not t.startswith("'") else "' '"
    text = LITERAL.sub(blank, text)
    out, rest = [], text
    while "#[cfg(test)]" in rest:
        i = rest.index("#[cfg(test)]")
        out.append(rest[:i])
        item, depth, end = rest[i:], 0, len(rest) - i
        for j, ch in enumerate(item):
            if ch == "{":
                depth += 1
            elif ch == "}" and depth > 0:
                depth -= 1
                if depth == 0:
                    end = j + 1
                    break
            elif ch == ";" and depth == 0:
                end = j + 1
                break
        out.append("\n" * item[:end].count("\n"))
        rest = item[end:]
    return "".join(out) + rest


def loc(text):
    return sum(1 for l in code(text).split("\n") if l.strip())


def top(rel):
    t = rel.split("/")[0].removesuffix(".rs")
    return None if t in ("lib", "main") else t


CONSTRUCTORS = r"\b(PlanarNavigator::(?:new|with_beacon_offsets)|TrackingNavigator::new|ParticleTracker::new|GaussianTracker::new|IusblNavigator::new|Range6DofNavigator::new|SingleBeaconNavigator::new)\("
SCORING = r"\b(struct ErrorAccumulator|struct ErrorStats|fn quantile|fn score|fn error_and_nees|fn horizontal_error|fn percentile)\b"
# a vehicle's computer described: a controller, its settings or a stream configuration
# written out in the simulator
COMPUTER = r"\b(ControllerSpec::\w+\(|StreamConfig \{|FimGuidance::new|FimGuidanceConfig \{|BearingSpec \{|BehavioursSpec \{|IusblKeys \{|IusblConfig \{)"
# a range (a difference's norm), a bearing (atan2) or a Doppler speed (a projection on
# the line of sight) computed by an estimator outside measure/: the navigators, the
# filters, the smoother
EQUATION = r"(\.norm\(\)|atan2\(|line_of_sight|\.dot\(&?u\b)"
ESTIMATORS = ("onebeacon/src/nav/", "onebeacon/src/filter/", "onebeacon-sim/src/smooth/")


def folder_loops(crate):
    """Per folder, a cycle among the modules it holds (each with the files below it),
    a path to a name the folder's own file re-exports counting as one to its module."""
    files = []
    for rel, text in sources(crate):
        parts = rel.removesuffix(".rs").split("/")
        if parts[-1] in ("mod", "lib", "main"):
            parts.pop()
        c = code(text)
        children = set(re.findall(r"\bmod (\w+)\s*;", c))
        files.append((parts, c, children))

    def absolute(p, module, children):
        parts = [x for x in p.split("::") if x]
        base = list(module)
        if not parts:
            return None
        if parts[0] == "crate":
            base, parts = [], parts[1:]
        elif parts[0] == "super":
            while parts and parts[0] == "super":
                base.pop() if base else None
                parts = parts[1:]
        elif parts[0] == "self":
            parts = parts[1:]
        elif parts[0] not in children:
            return None
        return base + parts

    def uses(c):
        out = []
        for m in re.finditer(r"(?:^|[\s{;)])use ([^;]*);", c):
            expand(m.group(1), "", out)
        return out

    def expand(tree, prefix, out):
        tree = tree.strip()
        if "{" in tree:
            o = tree.index("{")
            head = tree[:o].strip().removesuffix("::")
            inner = tree[o + 1 : tree.rindex("}")]
            prefix = prefix + head + "::" if head else prefix
            depth, start = 0, 0
            for i, ch in enumerate(inner):
                depth += ch == "{"
                depth -= ch == "}"
                if ch == "," and depth == 0:
                    expand(inner[start:i], prefix, out)
                    start = i + 1
            expand(inner[start:], prefix, out)
        elif tree:
            path, _, alias = tree.partition(" as ")
            path = prefix + path.strip()
            out.append((path, alias.strip() or path.split("::")[-1]))

    def paths(module, c, children):
        found = [absolute(p, module, children) for p, _ in uses(c)]
        found += [absolute(p, module, children) for p in re.findall(r"\b(?:crate|super|self)(?:::\w+)+", c)]
        return [p for p in found if p]

    folders = {tuple(m[:n]) for m, _, _ in files for n in range(len(m))}
    out = []
    for folder in sorted(folders):
        d = len(folder)
        inside = [(m, c, ch) for m, c, ch in files if len(m) > d and tuple(m[:d]) == folder]
        nodes = {m[d] for m, _, _ in inside}
        reexports = {}
        for m, c, ch in files:
            if tuple(m) == folder:
                for p, name in uses(c):
                    a = absolute(p, m, ch)
                    if a and len(a) > d + 1 and tuple(a[:d]) == folder and a[d] in nodes:
                        reexports[name] = a[d]
        g = {}
        for m, c, ch in inside:
            edges = g.setdefault(m[d], set())
            for a in paths(m, c, ch):
                if len(a) > d and tuple(a[:d]) == folder:
                    to = a[d] if a[d] in nodes else reexports.get(a[d])
                    if to and to != m[d]:
                        edges.add(to)
        for cyc in scc(g):
            out.append(f"{'/'.join(folder) or 'crate'}: {' <-> '.join(cyc)}")
    return out


def scc(g):
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(g.get(v, ())):
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

    for v in sorted(g):
        if v not in index:
            visit(v)
    return out


big, builders, scorers, computers, equations, loops = [], [], [], {}, {}, []
for crate in CRATES:
    public = 0
    for rel, text in sources(crate):
        if rel.endswith("tests.rs"):
            continue
        name = f"{crate}/src/{rel}"
        n = loc(text)
        if n > 600:
            big.append(f"{name} ({n})")
        c = code(text)
        public += len(re.findall(r"^\s*pub (?:fn|struct|enum|trait|const|type|mod|static|use)\b", c, re.M))
        # a place: a module that calls a navigator constructor (with its functions)
        for m in re.finditer(CONSTRUCTORS, c):
            fn = re.findall(r"fn (\w+)", c[: m.start()])
            builders.append((name, fn[-1] if fn else "?"))
        if crate == "onebeacon-sim":
            for m in re.finditer(COMPUTER, c):
                fn = re.findall(r"fn (\w+)", c[: m.start()])
                computers.setdefault(name, set()).add(fn[-1] if fn else "?")
        if name.startswith(ESTIMATORS):
            k = len(re.findall(EQUATION, c))
            if k:
                equations[name] = k
        scorers += [f"{name}: {m}" for m in re.findall(SCORING, c)]
    loops += [f"{crate}: {l}" for l in folder_loops(crate)]
    print(f"{crate}: {public} public items")
print(f"import loops (top level and inside folders): {len(loops)}: {'; '.join(loops)}")
print(f"files over 600 lines of code (tests, comments and blank lines left out): {len(big)}: {', '.join(big)}")
places = {}
for module, fn in builders:
    places.setdefault(module, set()).add(fn)
listed = ", ".join(f"{m} ({', '.join(sorted(f))})" for m, f in sorted(places.items()))
print(f"modules that build navigators: {len(places)}: {listed}")
listed = ", ".join(f"{m} ({', '.join(sorted(f))})" for m, f in sorted(computers.items()))
print(f"simulator modules that describe a vehicle's computer: {len(computers)}: {listed}")
listed = ", ".join(f"{m} ({k})" for m, k in sorted(equations.items()))
print(f"estimator files outside measure/ computing ranges, bearings or Doppler ({sum(equations.values())} lines): {len(equations)}: {listed}")
print(f"scoring implementations: {len(scorers)}: {'; '.join(scorers)}")
