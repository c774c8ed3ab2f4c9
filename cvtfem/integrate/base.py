"""Base of every one-step method, in the spirit of ``scipy.integrate.OdeSolver`` (spec §6).

A stepper turns ``(t, x, h)`` into an :class:`Attempt` (new state, optional error vector);
the driver decides acceptance, events and output, and calls :meth:`Stepper.accept`.
RHS calls go through :meth:`Stepper.f`, which counts and times them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from cvtfem.integrate.stats import Stats
from cvtfem.integrate.system import OdeSystem

__all__ = ["Attempt", "Stepper", "StepFailure", "hermite", "proportional_ratio", "PROPORTIONAL_C"]

#: rtol_int = PROPORTIONAL_C rtol^(3/2) for the order-2 methods trapezoidal and rkc (sw24: 1): the achieved
#: error is then 0.3-5 rtol on HIRES, Van der Pol (eps 1e-6), Robertson and the oscillator.
PROPORTIONAL_C = 0.5


class StepFailure(Exception):
    """A step could not be computed (Newton divergence, singular matrix); the driver
    rejects it (adaptive) or stops with a failure status (fixed step)."""


@dataclass
class Attempt:
    """One attempted step ``t0 -> t0 + h``.

    ``err`` is the local error estimate vector (None for methods without one); ``f0`` and
    ``f1`` are ``F`` at both ends when already known (for dense output and FSAL); ``interp(t)``
    is the method's own continuous extension when it has one (else the cubic Hermite one is used).
    """

    t0: float
    x0: np.ndarray
    h: float
    x1: np.ndarray
    err: np.ndarray | None = None
    f0: np.ndarray | None = None
    f1: np.ndarray | None = None
    interp: Callable[[float], np.ndarray] | None = None


class Stepper:
    """A one-step method; subclasses implement :meth:`attempt`.

    Class attributes: ``order`` (propagated order), ``error_order`` (order ``q`` of the
    solution the error estimate refers to, None without estimate; the controller uses
    exponent ``1/(q+1)``), ``OPTIONS`` (keyword options the method accepts).
    """

    name = "stepper"
    order = 1
    error_order: int | None = None
    OPTIONS: frozenset[str] = frozenset()
    stages = 1
    #: Default step-size controller of adaptive runs (:mod:`cvtfem.integrate.controller`).
    controller = "i"
    #: Set by the driver: False in fixed-step runs, so methods skip optional error estimates.
    need_error = True
    #: Set by the driver in adaptive runs: ``(rtol, atol)`` (implicit methods tie Newton to it).
    tolerances: tuple | None = None
    #: Events are refined on :meth:`solution_at` (a step of the method itself to the event time) instead
    #: of the cubic Hermite interpolant: explicit methods without a continuous extension of their own.
    substep_dense = False

    def __init__(self, system: OdeSystem, stats: Stats | None = None) -> None:
        self.system = system
        self.stats = stats if stats is not None else Stats()
        self._cache: tuple[float, np.ndarray, np.ndarray] | None = None
        self._start: tuple[float, np.ndarray, np.ndarray] | None = None

    def f(self, t: float, x: np.ndarray) -> np.ndarray:
        """Counted, timed ``F(t, x)``; repeated calls at the last point are served from cache."""
        c = self._cache
        if c is not None and c[0] == t and np.array_equal(c[1], x):
            return c[2]
        st = self.stats
        st.counts["nfev"] += 1
        with st.timer("t_rhs"):
            y = np.asarray(self.system.fun(t, x))
        self._cache = (t, x.copy(), y)
        return y

    def f0(self, t: float, x: np.ndarray) -> np.ndarray:
        """``F`` at a step start, kept across rejected attempts and set by FSAL methods."""
        c = self._start
        if c is not None and c[0] == t and np.array_equal(c[1], x):
            return c[2]
        y = self.f(t, x)
        self._start = (t, x.copy(), y)
        return y

    def attempt(self, t: float, x: np.ndarray, h: float) -> Attempt:  # pragma: no cover
        raise NotImplementedError

    def accept(self, att: Attempt) -> None:
        """Commit an accepted step; an FSAL slope becomes the cached ``F`` at the new point."""
        if att.f1 is not None:
            self._start = (att.t0 + att.h, att.x1.copy(), att.f1)

    def reset(self) -> None:
        """Forget the history (after an event switch changes the state or ``phi``)."""

    def memory_fields(self) -> tuple[tuple[str, int], ...]:
        """``((name, size), ...)`` of :meth:`state`: here ``F`` at the current point (``f_start``, known
        after FSAL steps and dense output; NaN otherwise), so a resumed run makes the same RHS calls."""
        return (("f_start", self.system.n),)

    def state(self, t: float, x: np.ndarray) -> dict[str, np.ndarray]:
        """The method's step-to-step memory at the accepted point ``(t, x)`` (see :meth:`memory_fields`)."""
        for c in (self._start, self._cache):
            if c is not None and c[0] == t and np.array_equal(c[1], x):
                return {"f_start": np.array(c[2], dtype=float)}
        return {"f_start": np.full(self.system.n, np.nan)}

    def restore(self, state: dict[str, np.ndarray], t: float, x: np.ndarray) -> None:
        """Continue from :meth:`state` in a stepper freshly built at ``(t, x)``. Methods that keep no more
        restart the rest (W-methods: their LU; stabilized methods: the spectral-radius estimate)."""
        f_start = state["f_start"]
        if not np.all(np.isnan(f_start)):
            self._start = (t, np.array(x), np.array(f_start))

    def solution_at(self, att: Attempt, t: float) -> np.ndarray:
        """The method's own solution at ``t`` in the step ``att``: one step of size ``t - t0`` from its start
        (``x0``, ``x1`` at the ends), so of the method's order; a continuous extension for event location
        (RHS calls are counted). Methods whose attempts change no memory but the stage count may use it."""
        if t == att.t0:
            return att.x0
        if t == att.t0 + att.h:
            return att.x1
        need, stages = self.need_error, self.stages
        self.need_error = False
        try:
            return self.attempt(att.t0, att.x0, t - att.t0).x1
        finally:
            self.need_error, self.stages = need, stages

    def tolerance_ratio(self, rtol: float) -> float:
        """``rtol_int / rtol``: adaptive runs control the local error against ``rtol_int`` and
        ``atol_int = atol rtol_int / rtol`` (1 here; low-order methods map, see :func:`proportional_ratio`)."""
        return 1.0

    def max_step(self) -> float:
        """Largest step, s, worth attempting now (adaptive runs cap their proposals there); no cap here."""
        return np.inf


def proportional_ratio(rtol: float, order: int = 2, c: float = PROPORTIONAL_C) -> float:
    """``rtol_int / rtol`` that makes an order-``p`` method's global error proportional to ``rtol``.

    Holding the local error ``O(h^(p+1))`` at ``tol`` gives a global error ``~ tol^(p/(p+1))``; with
    ``rtol_int = c rtol^((p+1)/p)`` (RADAU5's tolerance map, Hairer-Wanner II, IV.8, for its order)
    ``h ~ rtol^(1/p)`` and the global error ``~ rtol``. The constant ``c`` is measured per method
    (docs/integrators.md, "Tolerance proportionality"); the ratio never exceeds 1.
    """
    return min(1.0, c * rtol ** (1.0 / order))


def hermite(att: Attempt, f1: np.ndarray, t: np.ndarray | float) -> np.ndarray:
    """Cubic Hermite interpolant of a step, ``(n,)`` or ``(n, len(t))``; order 3 in ``h``."""
    h = att.h
    s = (np.asarray(t, dtype=float) - att.t0) / h
    h00 = (1 + 2 * s) * (1 - s) ** 2
    h10 = s * (1 - s) ** 2
    h01 = s * s * (3 - 2 * s)
    h11 = s * s * (s - 1)
    x0, x1, f0 = att.x0, att.x1, att.f0
    if np.ndim(s) == 0:
        return h00 * x0 + h10 * h * f0 + h01 * x1 + h11 * h * f1
    return (np.outer(x0, h00) + np.outer(h * f0, h10) + np.outer(x1, h01) + np.outer(h * f1, h11))
