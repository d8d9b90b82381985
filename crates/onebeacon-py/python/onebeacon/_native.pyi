"""Type stubs of onebeacon's extension module (see the package's docstring)."""

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class InputError(ValueError):
    """Input the caller can fix; the message is the CLI's one line."""

class Scenario:
    """A parsed, validated scenario (docs/scenarios.md has every key)."""

    @staticmethod
    def builtin(name: str) -> "Scenario": ...
    @staticmethod
    def from_file(path: Union[str, "os.PathLike[str]"]) -> "Scenario": ...
    @staticmethod
    def from_toml(text: str, source: str = "scenario TOML") -> "Scenario": ...
    @staticmethod
    def from_dict(d: Dict[str, Any]) -> "Scenario": ...
    def to_dict(self) -> Dict[str, Any]: ...
    def to_toml(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def runs(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def cells(self) -> List[Dict[str, Union[float, str]]]: ...
    @property
    def tracks(self) -> List[str]: ...
    @property
    def vehicles(self) -> List[str]: ...
    def __eq__(self, other: object) -> bool: ...

ScenarioLike = Union[Scenario, str, "os.PathLike[str]", Dict[str, Any]]
Trajectory = Dict[str, npt.NDArray[np.float64]]

def scenarios() -> List[Dict[str, str]]: ...
def run(scenario: ScenarioLike, seed: Optional[int] = None, run: int = 0) -> Tuple[Trajectory, Dict[str, Any]]: ...
def mc(
    scenario: ScenarioLike,
    runs: Optional[int] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> List[Dict[str, Any]]: ...
def replay(
    log: Union[str, "os.PathLike[str]"],
    beacons: Optional[Sequence[int]] = None,
    estimators: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Tuple[Trajectory, Dict[str, Any]]: ...

def smooth(
    log: Union[str, "os.PathLike[str]"],
    beacons: Optional[Sequence[int]] = None,
    like: Optional[str] = None,
    calibrate: Optional[Sequence[str]] = None,
    kernel: Optional[str] = None,
) -> Tuple[Dict[str, npt.NDArray[np.float64]], Dict[str, Any]]: ...

def rts(
    log: Union[str, "os.PathLike[str]"],
    beacons: Optional[Sequence[int]] = None,
) -> Dict[str, Tuple[Dict[str, npt.NDArray[np.float64]], Dict[str, Any]]]: ...

class Navigator:
    """The estimators of a stream configuration, fed one measurement at a time."""

    def __init__(self, config: Union[str, "os.PathLike[str]"]) -> None: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def started(self) -> bool: ...
    def feed(self, item: Union[Dict[str, Any], str]) -> Optional[Dict[str, Any]]: ...
    def estimates(self) -> List[Dict[str, Any]]: ...

def dsp_process(
    samples: npt.NDArray[np.float64],
    fs: float,
    config: Optional[Union[str, "os.PathLike[str]", Dict[str, Any]]] = None,
) -> Dict[str, Any]: ...
