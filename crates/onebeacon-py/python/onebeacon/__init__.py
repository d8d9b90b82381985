"""onebeacon: navigation of underwater vehicles from one acoustic beacon.

The same engine as the ``onebeacon`` command line, from Python, with numpy arrays:

- scenarios: ``scenarios()`` lists the built-ins; ``Scenario.builtin(name)``,
  ``Scenario.from_file(path)``, ``Scenario.from_toml(text)``, ``Scenario.from_dict(d)``;
  every function taking a scenario also takes a name, a path or a dict;
- ``run(scenario)``: one recorded run, ``(trajectory, summary)``;
- ``mc(scenario)``: Monte Carlo over the sweep, the cells of ``onebeacon mc --json``;
- ``replay(log)``: a real log through its estimators, ``(trajectory, summary)``;
- ``smooth(log)``: a log smoothed over every pose after the dive, ``(poses, summary)``;
- ``rts(log)``: each Gaussian filter's Rauch-Tung-Striebel pass, ``{name: (estimates, summary)}``;
- ``Navigator(config)``: the estimators step by step, for a backseat node;
- ``dsp.process(samples, fs)``: the acoustic receiver chain on one capture.

Bad input raises ``InputError`` (a ``ValueError``) with the CLI's one-line message.
"""

from ._native import (
    InputError,
    Navigator,
    Scenario,
    __version__,
    mc,
    replay,
    rts,
    run,
    scenarios,
    smooth,
)
from . import dsp

__all__ = [
    "InputError",
    "Navigator",
    "Scenario",
    "__version__",
    "dsp",
    "mc",
    "replay",
    "rts",
    "run",
    "scenarios",
    "smooth",
]
