"""Operating regimes: targets as functions of time (spec sections 6.1-6.2, Table 1.2).

A regime holds the driving torque ``M1(t)``, the target input speed ``w1d(t)`` and the target
ratio ``i_d(t)``; one of them ramps linearly over ``ramp_time`` for the non-stationary kinds.
"""
from __future__ import annotations

from dataclasses import dataclass

from cvtfem.errors import InputError

KINDS = ("stationary", "torque-ramp", "speed-ramp", "ratio-change")


@dataclass(frozen=True)
class Regime:
    """Targets of a run.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    input_speed : float, rad/s
    torque : float, N m
    ratio : float
    end_value : float
        End value of the ramped quantity (rad/s, N m or -), ignored for "stationary".
    ramp_time : float, s
    t_start : float, s
        Start of the ramp.
    """

    kind: str
    input_speed: float
    torque: float
    ratio: float
    end_value: float = 0.0
    ramp_time: float = 0.0
    t_start: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError("regime.kind", self.kind, "must be one of " + ", ".join(KINDS))
        if self.kind != "stationary" and not (self.ramp_time > 0 and self.end_value > 0):
            raise InputError("regime.ramp_time", self.ramp_time,
                             f"must be positive, with a positive `end_value`, for a `{self.kind}` regime")

    def _ramp(self, t: float, start: float) -> float:
        s = min(max((t - self.t_start) / self.ramp_time, 0.0), 1.0)
        return start + s * (self.end_value - start)

    def targets(self, t: float) -> tuple[float, float, float]:
        """``(w1d rad/s, M1 N m, i_d)`` at time t (s)."""
        w1, M1, i = self.input_speed, self.torque, self.ratio
        if self.kind == "torque-ramp":
            M1 = self._ramp(t, M1)
        elif self.kind == "speed-ramp":
            w1 = self._ramp(t, w1)
        elif self.kind == "ratio-change":
            i = self._ramp(t, i)
        return w1, M1, i

    def ratio_range(self) -> tuple[float, float]:
        """Smallest and largest target ratio over the run."""
        if self.kind == "ratio-change":
            return min(self.ratio, self.end_value), max(self.ratio, self.end_value)
        return self.ratio, self.ratio
