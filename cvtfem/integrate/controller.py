"""Step-size controllers (spec §6 ref-impl extras): fixed and error-based.

A controller maps ``(h, err_norm, q)`` to ``(accept, h_new)``; ``err_norm`` is the weighted
RMS norm of the error vector with scale ``atol + rtol*max(|x0|, |x1|)`` (spec §9.7).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FixedStep", "SimpleController", "error_norm"]

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 5.0


def error_norm(err: np.ndarray, x0: np.ndarray, x1: np.ndarray, rtol: float,
               atol: np.ndarray | float) -> float:
    """Weighted RMS norm of a local error vector (1 = exactly at tolerance)."""
    scale = atol + rtol * np.maximum(np.abs(x0), np.abs(x1))
    return float(np.sqrt(np.mean(np.abs(err / scale) ** 2)))


@dataclass(frozen=True)
class FixedStep:
    """Every step has the same size ``h`` (the study protocol of spec §9.1)."""

    h: float

    def propose(self, h: float, err_norm: float | None, q: int | None) -> tuple[bool, float]:
        return True, self.h


@dataclass(frozen=True)
class SimpleController:
    """Elementary controller ``h_new = h * SAFETY * (1/err)^(1/(q+1))``, factor-limited.

    ``quantum`` > 1 keeps ``h`` unchanged unless the proposed growth exceeds it (the ref-impl's
    "discreteness" of 1.3, which lets W-methods and const Newton reuse their LU).
    """

    quantum: float = 1.0
    h_max: float = np.inf

    def propose(self, h: float, err_norm: float, q: int) -> tuple[bool, float]:
        if not np.isfinite(err_norm):
            return False, h * MIN_FACTOR
        if err_norm == 0.0:
            factor = MAX_FACTOR
        else:
            factor = SAFETY * err_norm ** (-1.0 / (q + 1))
        accept = err_norm <= 1.0
        if accept:
            factor = min(MAX_FACTOR, max(1.0, factor))
            if factor < self.quantum:
                factor = 1.0
        else:
            factor = max(MIN_FACTOR, factor)
        return accept, min(h * factor, self.h_max)
