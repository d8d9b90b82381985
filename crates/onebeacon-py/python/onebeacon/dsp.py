"""The acoustic receiver chain on captures from any recorder."""

from typing import Any, Dict, Optional, Union
import os

import numpy as np

from ._native import InputError, dsp_process as _process


def process(
    samples: "np.ndarray",
    fs: float,
    config: Optional[Union[str, "os.PathLike[str]", Dict[str, Any]]] = None,
) -> Dict[str, Any]:
    """Runs the receiver chain on one capture, as ``onebeacon dsp process --json``.

    ``samples``: a 2-d array, one row per element of the receiving array, starting at the
    transmit epoch (any real dtype; converted to float64). ``fs``: its sample rate, Hz
    (it overrides the configuration's ``capture.fs_hz``). ``config``: the ping
    configuration (array geometry, waveform, sound speed) as a TOML file's path or a
    dict with its keys; None for the defaults of ``onebeacon dsp simulate``.

    Returns a dict with ``detected``, ``detection_statistic``, ``detection_threshold``,
    ``range_m``, ``azimuth_deg``, ``inclination_deg``, ``mode`` (1-4, chirps),
    ``radial_speed_m_s`` (garin frames) and ``consistent``; estimates are None when
    nothing was detected.
    """
    a = np.asarray(samples)
    if a.dtype.kind not in "biuf":
        raise InputError(
            f"samples has dtype {a.dtype}; a real number type is allowed (bool, int, uint, float): "
            "take the real part or the magnitude of complex samples yourself"
        )
    if a.ndim not in (1, 2):
        raise InputError(f"samples has {a.ndim} dimensions; 1 (one element) or 2 (one row per element) are allowed")
    if a.ndim == 1:
        a = a[np.newaxis, :]
    return _process(np.ascontiguousarray(a, dtype=np.float64), float(fs), config)


__all__ = ["process"]
