"""Step-size controllers (spec §6 ref-impl extras): fixed and error-based.

A controller maps ``(h, err_norm, q)`` to ``(accept, h_new)``; ``err_norm`` is the weighted
RMS norm of the error vector with scale ``atol + rtol*max(|x0|, |x1|)`` (spec §9.7).
Both error-based controllers apply Hairer's rule ``facmax = 1`` on the step after a rejection
(Hairer-Norsett-Wanner I, §II.4): a step that had to be shrunk is not grown again at once.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cvtfem.errors import InputError

__all__ = ["CONTROLLER_MEMORY", "FixedStep", "SimpleController", "PIController", "PredictiveController", "CONTROLLERS", "make_controller", "error_norm",
           "step_floor"]

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 5.0
#: what an error-based controller remembers between steps (a run's memory: checkpoints restore it)
CONTROLLER_MEMORY = ("rejected", "err_prev", "h_acc", "err_acc")
#: step-size floor in units of the spacing of doubles at the current time (scipy uses 10)
FLOOR_ULPS = 16


def error_norm(err: np.ndarray, x0: np.ndarray, x1: np.ndarray, rtol: float,
               atol: np.ndarray | float) -> float:
    """Weighted RMS norm of a local error vector (1 = exactly at tolerance)."""
    e = np.abs(err) / (atol + rtol * np.maximum(np.abs(x0), np.abs(x1)))
    return math.sqrt(float(e @ e) / e.size)


def step_floor(t: float) -> float:
    """Smallest step, s, worth attempting at time ``t``: ``FLOOR_ULPS`` spacings of doubles at ``|t|``
    (relative to the current time, as scipy's ``OdeSolver``; a smaller ``h`` barely moves ``t``)."""
    return FLOOR_ULPS * float(np.spacing(abs(t)))


@dataclass(frozen=True)
class FixedStep:
    """Every step has the same size ``h`` (the study protocol of spec §9.1)."""

    h: float

    def propose(self, h: float, err_norm: float | None, q: int | None) -> tuple[bool, float]:
        return True, self.h

    def memory(self) -> np.ndarray:
        """Nothing to remember (NaN in each :data:`CONTROLLER_MEMORY` slot)."""
        return np.full(len(CONTROLLER_MEMORY), np.nan)

    def restore(self, memory: np.ndarray) -> None:
        """Nothing to restore."""


@dataclass
class SimpleController:
    """Elementary (integral) controller ``h_new = h * SAFETY * (1/err)^(1/(q+1))``, factor-limited.

    ``quantum`` > 1 keeps ``h`` unchanged unless the proposed growth exceeds it (the ref-impl's
    "discreteness" of 1.3, which lets W-methods and const Newton reuse their LU).
    """

    quantum: float = 1.0
    h_max: float = np.inf
    rejected: bool = False   # the last attempt was rejected: no growth on the next accepted step

    def factor(self, err_norm: float, q: int) -> float:
        """Unlimited step-size factor for an attempt with error ``err_norm`` (> 0)."""
        return SAFETY * err_norm ** (-1.0 / (q + 1))

    def propose(self, h: float, err_norm: float, q: int, cap: float = np.inf) -> tuple[bool, float]:
        """``(accept, next h)`` after an attempt of size ``h`` with error norm ``err_norm``; ``cap``: the method's
        largest step, s (the quantum does not hold a step that could grow to it)."""
        if not np.isfinite(err_norm):
            self.rejected = True
            return False, h * MIN_FACTOR
        accept = err_norm <= 1.0
        factor = MAX_FACTOR if err_norm == 0.0 else self.factor(err_norm, q)
        if accept:   # an accepted step near the tolerance shrinks h (else the next one is rejected)
            factor = min(1.0 if self.rejected else MAX_FACTOR, max(MIN_FACTOR, factor))
            if 1.0 <= factor < self.quantum and h * factor < cap:
                factor = 1.0
            self.accepted(err_norm)
        else:
            factor = max(MIN_FACTOR, factor)
        self.rejected = not accept
        return accept, min(h * factor, self.h_max)

    def accepted(self, err_norm: float) -> None:
        """Hook: an attempt with error ``err_norm`` was accepted."""

    def memory(self) -> np.ndarray:
        """The :data:`CONTROLLER_MEMORY` values this controller has (NaN for the others)."""
        return np.array([float(getattr(self, k, np.nan)) for k in CONTROLLER_MEMORY])

    def restore(self, memory: np.ndarray) -> None:
        """Continue from :meth:`memory` (a checkpoint)."""
        for k, v in zip(CONTROLLER_MEMORY, memory):
            if hasattr(self, k) and not np.isnan(v):
                setattr(self, k, bool(v) if k == "rejected" else float(v))


@dataclass
class PIController(SimpleController):
    """PI controller ``h_new = h * SAFETY * err^(-0.7/k) * err_prev^(0.4/k)``, ``k = q + 1``
    (Gustafsson; Hairer-Wanner II §IV.2): the previous accepted error damps oscillating step
    sequences; rejections use the integral part only."""

    err_prev: float = 1.0

    def factor(self, err_norm: float, q: int) -> float:
        k = q + 1
        if self.rejected or err_norm > 1.0:
            return super().factor(err_norm, q)
        return SAFETY * err_norm ** (-0.7 / k) * max(self.err_prev, 1e-4) ** (0.4 / k)

    def accepted(self, err_norm: float) -> None:
        self.err_prev = err_norm


@dataclass
class PredictiveController(SimpleController):
    """Gustafsson's predictive controller (Hairer-Wanner II §IV.8, as in RADAU5 and RODAS): an accepted
    step also proposes ``h (h / h_acc) (err_acc / err^2)^(1/k)`` (the error's trend over the last two
    accepted steps, ``k = q + 1``) and the smaller proposal wins, so a run whose error grows from step to
    step (approaching a fast transient) shrinks ``h`` before a rejection, not after."""

    h_acc: float = 0.0
    err_acc: float = 1.0

    def propose(self, h: float, err_norm: float, q: int, cap: float = np.inf) -> tuple[bool, float]:
        accept, h_new = super().propose(h, err_norm, q, cap)
        if accept:
            if self.h_acc > 0.0:
                trend = SAFETY * (h / self.h_acc) * (self.err_acc / max(err_norm, 1e-10) ** 2) ** (1.0 / (q + 1))
                h_new = min(h_new, h * max(MIN_FACTOR, trend))
            self.h_acc, self.err_acc = h, max(1e-2, err_norm)
        return accept, h_new


CONTROLLERS = {"i": SimpleController, "pi": PIController, "predictive": PredictiveController}


def make_controller(name: str, quantum: float = 1.0) -> SimpleController:
    """The error-based controller ``name`` (``"i"`` elementary, ``"pi"`` proportional-integral,
    ``"predictive"`` Gustafsson's)."""
    if name not in CONTROLLERS:
        raise InputError("controller", name, f"must be one of {sorted(CONTROLLERS)}")
    return CONTROLLERS[name](quantum=quantum)
