"""Units at the CLI boundary: spin speeds from text with an explicit unit (``4000rpm``, ``0:4000rpm:51``)."""
from __future__ import annotations

import re

import numpy as np

from cvtfem.errors import InputError

#: Unit -> factor to rad/s.
UNITS = {"rpm": np.pi / 30, "rad/s": 1.0, "hz": 2 * np.pi}
_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def parse_speed(text: str, where: str = "--speed") -> float:
    """``"4000rpm"`` / ``"418.9 rad/s"`` / ``"50Hz"`` -> rad/s.

    Examples
    --------
    >>> round(parse_speed("3000rpm"), 6)
    314.159265
    """
    m = re.fullmatch(rf"\s*({_NUM})\s*([A-Za-z/]+)\s*", text)
    if not m or m.group(2).lower() not in UNITS:
        raise InputError(where, text, "must be a number with a unit: rpm, rad/s or Hz", "e.g. 4000rpm")
    return float(m.group(1)) * UNITS[m.group(2).lower()]


def parse_speeds(text: str, where: str = "--speeds") -> np.ndarray:
    """``"start:stop<unit>:count"`` -> ``count`` evenly spaced speeds in rad/s.

    Examples
    --------
    >>> parse_speeds("0:60rpm:3").round(6).tolist()
    [0.0, 3.141593, 6.283185]
    """
    m = re.fullmatch(rf"\s*({_NUM})\s*:\s*({_NUM})\s*([A-Za-z/]+)\s*:\s*(\d+)\s*", text)
    if not m or m.group(3).lower() not in UNITS:
        raise InputError(where, text, "must be START:STOP<unit>:COUNT with unit rpm, rad/s or Hz",
                         "e.g. 0:4000rpm:51")
    start, stop, count = float(m.group(1)), float(m.group(2)), int(m.group(4))
    if count < 2 or not stop > start:
        raise InputError(where, text, "needs STOP > START and COUNT >= 2")
    return np.linspace(start, stop, count) * UNITS[m.group(3).lower()]
