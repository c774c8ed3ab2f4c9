"""Event location (spec §1.2, §11.7): sign changes, earliest crossing, simultaneous events.

Two locators: ``"linear"`` interpolates indicators and state over the step (the source's
scheme, ``theta = e0/(e0 - e1)``, ``x* = (1-theta) x0 + theta x1``); ``"dense"`` refines the
crossing with Brent's method on the step's dense output (default).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from cvtfem.errors import InputError

__all__ = ["EventLocator", "crossings"]

SIMULTANEOUS_RTOL = 1e-9   # crossings closer than this fraction of h count as simultaneous
INTERIOR = (1e-6, 1e-3, 1 / 64, 1 / 8, 1 / 2)   # samples for indicators restarting at 0


def crossings(g0: np.ndarray, g1: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Mask of indicators whose sign changed in the allowed direction (0 never fires again)."""
    up = (g0 < 0) & (g1 >= 0)
    down = (g0 > 0) & (g1 <= 0)
    return (up & (direction >= 0)) | (down & (direction <= 0))


class EventLocator:
    """Stores indicators at the step start and finds the earliest crossing in a step."""

    def __init__(self, system, stats, mode: str = "dense") -> None:
        if mode not in ("dense", "linear"):
            raise InputError("event_location", mode, "must be 'dense' or 'linear'")
        self.system, self.stats, self.mode = system, stats, mode
        self.g0: np.ndarray | None = None
        self.side: np.ndarray | None = None
        self._ga: np.ndarray | None = None

    def g(self, t: float, x: np.ndarray) -> np.ndarray:
        self.stats.counts["nevfun"] += 1
        return np.asarray(self.system.events(t, x), dtype=float)

    def start(self, t: float, x: np.ndarray, fired: np.ndarray | None = None) -> None:
        """Indicators at a step start; fired ones are set to exactly 0 and remember the side
        they came from (``side``), so that they neither re-fire at once nor get missed."""
        self.g0 = self.g(t, x)
        self.side = np.zeros(len(self.g0))
        if fired is not None:
            self.g0[fired] = 0.0
            self.side[fired] = np.sign(self._ga[fired])

    def locate(self, t0, x0, t1, x1, dense):
        """Earliest crossing in ``[t0, t1]``: ``(t*, x*, fired mask, g1)`` or ``None``.

        ``dense(t)`` evaluates the step's interpolant. An indicator that is exactly 0 at the
        step start (it fired there) is sampled at interior points: back on its pre-event side,
        the sample becomes the bracket start; already across again, the crossing is bracketed
        in ``[t0, sample]`` (a bounce-and-return inside one step is not missed).
        """
        g1 = self.g(t1, x1)
        h = t1 - t0
        ga, ta = self.g0.copy(), np.full(len(g1), t0)
        gb, tb = g1.copy(), np.full(len(g1), t1)
        zero = ga == 0.0
        for frac in INTERIOR if zero.any() else ():
            tq = t0 + frac * h
            gq = self.g(tq, dense(tq))
            new = zero & (gq != 0.0)
            back = new & ((self.side == 0) | (np.sign(gq) == self.side))
            ahead = new & ~back
            ga[back], ta[back] = gq[back], tq
            ga[ahead] = self.side[ahead] * np.finfo(float).tiny
            gb[ahead], tb[ahead] = gq[ahead], tq
            zero &= ~new
            if not zero.any():
                break
        cross = crossings(ga, gb, self.system.event_direction)
        self._ga = ga
        if not cross.any():
            self.g0 = g1
            return None
        idx = np.flatnonzero(cross)
        if self.mode == "linear":
            theta = ga[idx] / (ga[idx] - gb[idx])
            t_k = ta[idx] + theta * (tb[idx] - ta[idx])
        else:
            t_k = np.array([self._refine(k, ta[k], ga[k], tb[k], gb[k], dense) for k in idx])
        t_star = float(t_k.min())
        fired = np.zeros_like(cross)
        fired[idx[t_k <= t_star + SIMULTANEOUS_RTOL * abs(h)]] = True
        if self.mode == "linear":
            th = (t_star - t0) / h
            x_star = (1 - th) * x0 + th * x1
        else:
            x_star = dense(t_star)
        return t_star, x_star, fired, g1

    def _refine(self, k, ta, ga, tb, gb, dense):
        """Brent's method on ``e_k(t, dense(t))`` over ``[ta, tb]`` (signs differ there)."""
        if gb == 0.0:
            return tb

        def fun(t):
            return ga if t == ta else gb if t == tb else self.g(t, dense(t))[k]

        return brentq(fun, ta, tb, xtol=4 * np.finfo(float).eps * max(abs(tb), 1e-300), rtol=1e-15)
