"""scripts/sea_presets.py: every value of the shipped -sea presets says where it comes from;
a value that says neither is refused by name; the ablation's variants change the one
value they name and nothing else."""
import os
import pathlib
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import sea_presets  # noqa: E402

PRESET = """name = "x-sea"
[mission]
duration_s = 60.0

[sea.link]
loss_prob = 0.6            # unsourced: lost,
                           # in bursts
multipath_excess_m = 10.0  # source: a paper, sec. 1
                           # (its Table 2)
false_prob = 0.02          # unsourced

[sea.current]
toward_deg = 300.0         # unsourced
speed_m_s = 0.1            # source: a datasheet

[sweep]
t_com_s = [3.0, 6.0]
"""


def write(tmp_path, text):
    path = tmp_path / "x-sea.toml"
    path.write_text(text)
    return path


def test_every_shipped_preset_value_is_marked():
    # the presets as shipped: values() raises on the first unmarked one
    found = {p.stem: sea_presets.values(p) for p in sea_presets.presets()}
    assert len(found) == 5 and all(found.values())
    for name, vs in found.items():
        assert {v["status"] for v in vs} <= {"sourced", "unsourced"}, name


def test_values_read_marks_and_their_continued_comments(tmp_path):
    vs = sea_presets.values(write(tmp_path, PRESET))
    assert [(v["table"], v["key"], v["status"]) for v in vs] == [
        ("sea.link", "loss_prob", "unsourced"), ("sea.link", "multipath_excess_m", "sourced"),
        ("sea.link", "false_prob", "unsourced"), ("sea.current", "toward_deg", "unsourced"),
        ("sea.current", "speed_m_s", "sourced")]
    assert vs[1]["comment"] == "source: a paper, sec. 1 (its Table 2)"


@pytest.mark.parametrize("comment", ["# a fifth lost", "", "# Source: capitalised"])
def test_an_unmarked_value_is_refused_by_name(tmp_path, comment):
    text = PRESET.replace("false_prob = 0.02          # unsourced", f"false_prob = 0.02 {comment}")
    with pytest.raises(sea_presets.Unmarked, match=r"\[sea.link\] false_prob = 0.02"):
        sea_presets.values(write(tmp_path, text))


def test_the_variants_change_one_value(tmp_path):
    vs = {v["key"]: v for v in sea_presets.values(write(tmp_path, PRESET))}
    as_set = dict(sea_presets.variants(PRESET, vs["loss_prob"]))["as set"]
    assert "[sweep]" not in as_set and "loss_prob = 0.6\n" in as_set

    def lines(toml):
        return [line.strip() for line in toml.splitlines() if line.strip()]

    def diff(label, key, removable=True):
        got = dict(sea_presets.variants(PRESET, vs[key], removable))
        return sorted(set(lines(got["as set"])) ^ set(lines(got[label])))

    # removed with its comment's second line (every variant, "as set" too, rewrites the
    # value's line alone); 0.6 is not doubled (1.2 is no probability)
    assert [label for label, _ in sea_presets.variants(PRESET, vs["loss_prob"])] == ["default", "as set"]
    assert diff("default", "loss_prob") == ["loss_prob = 0.6"] and "in bursts" not in as_set
    assert diff("x2", "multipath_excess_m") == ["multipath_excess_m = 10.0", "multipath_excess_m = 20.0"]
    assert diff("x0.5", "multipath_excess_m", removable=False) == [
        "multipath_excess_m = 10.0", "multipath_excess_m = 5.0"]
    assert diff("+180 deg", "toward_deg") == ["toward_deg = 120.0", "toward_deg = 300.0"]
    assert diff("x2", "false_prob") == ["false_prob = 0.02", "false_prob = 0.04"]


def test_a_refused_variant_is_said_so_and_the_rest_is_kept(tmp_path, monkeypatch):
    # a fake `onebeacon mc`: the filter errs 1.0 m a run (+-0.1) with the false detections
    # as set, 1.5 m without them, and the binary refuses (None) a share of 0.04
    def fake_run(toml, path, runs, binary):
        if "false_prob = 0.04" in toml:
            return None
        err = 1.0 if "false_prob = 0.02\n" in toml else 1.5
        return [{"estimator": "ekf", "run_mean_errors_m": [err, err + 0.1, err - 0.1], "nees_mean_all_runs": 2.0}]

    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "x-sea.toml").write_text(PRESET)
    monkeypatch.setattr(sea_presets, "ROOT", tmp_path)
    monkeypatch.setattr(sea_presets, "run", fake_run)
    first, rows = sea_presets.ablate("x-sea", 3, "onebeacon", tmp_path / "out", progress=False)
    assert first == "ekf" and [r[1] for r in rows] == ["loss_prob", "false_prob", "toward_deg"]
    _, _, value, (mean, _, _, runs), changes = rows[1]
    assert (value, mean, runs) == ("0.02", 1.0, 3)
    assert [sea_presets.change(c) for c in changes] == ["default +0.50 (+-0.00)", "x2 refused (outside the key's range)"]


def test_a_fleet_preset_runs_once_per_seed_and_pairs_the_runs(tmp_path):
    # a fake `onebeacon`: `fleet FILE --runs 1 --seed S --json` errs S m, plus 2 m with the
    # losses of the preset as set (absent, the default, they cost nothing); it is called
    # once per run with the preset's seed plus the run's index, its pings made abstract
    fake = tmp_path / "onebeacon"
    fake.write_text("""#!/usr/bin/env python3
import json, sys
args = sys.argv[1:]
assert args[0] == "fleet" and args[2:4] == ["--runs", "1"] and args[6] == "--json" and args[7] == "--out", args
toml = open(args[1]).read()
assert 'model = "abstract"' in toml
seed = int(args[5])
err = seed + (2.0 if "loss_prob = 0.2" in toml else 0.4 if "loss_prob = 0.4" in toml else 0.0)
print(json.dumps({"statistics": {"fleet": [{"label": "fleet/iusbl", "mean_m": err, "nees_mean": 1.0}]}}))
""")
    fake.chmod(0o755)
    preset = 'kind = "fleet"\nname = "f-sea"\nseed = 7\nruns = 3\n\n[signal]\nmodel = "channel"\n\n' \
             '[sea.link]\nloss_prob = 0.2          # unsourced\n'
    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "f-sea.toml").write_text(preset)
    import unittest.mock
    with unittest.mock.patch.object(sea_presets, "ROOT", tmp_path):
        first, rows = sea_presets.ablate("f-sea", None, str(fake), tmp_path / "out", progress=False,
                                         transform=sea_presets.abstract_pings)
    (table, key, value, (mean, _, nees, runs), changes) = rows[0]
    # seeds 7, 8, 9: 9, 10, 11 m as set; the default (no losses) 2 m less, doubled 1.6 m less
    assert (first, table, key, runs, mean, nees) == ("iusbl", "sea.link", "loss_prob", 3, 10.0, 1.0)
    assert [sea_presets.change(c) for c in changes] == ["default -2.00 (+-0.00)", "x2 -1.60 (+-0.00)"]
