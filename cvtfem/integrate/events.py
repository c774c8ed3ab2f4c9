"""Event location (spec §1.2, §11.7): sign changes, earliest crossing, simultaneous events.

Two locators: ``"linear"`` interpolates indicators and state over the step (the source's
scheme, ``theta = e0/(e0 - e1)``, ``x* = (1-theta) x0 + theta x1``); ``"dense"`` (default)
scans the step's dense output at ``SCAN`` interior points for the first sign change and
refines it with Brent's method, so the earliest of several crossings in one step is found.
In dense mode every step also samples the indicators at ``event_samples`` (default
``EVENT_SAMPLES`` = 4) equally spaced interior points, so an even number of crossings inside
one step (no sign change between the step's ends) is detected as well; ``event_samples = 0``
restores the end-point-only detection of the source. Crossings closer together than the sample
spacing ``h / (event_samples + 1)`` can still cancel out and be missed.

After an event the fired indicators restart at exactly 0; their sign just after the restart
(sampled at ``INTERIOR`` fractions of the step, as CVODE does) becomes the new reference, so a
pass-through crossing does not re-fire and a rebound is detected when it comes back. An
indicator that is exactly 0 at the initial state counts as coming from the other side, so
leaving it in the firing direction is an event at ``t0``.

Methods without a continuous extension of their own pass ``precise(t)`` (a step of the method itself to
``t``, :meth:`~cvtfem.integrate.base.Stepper.solution_at`): detection and scan stay on the cheap
interpolant, Brent's method then runs on the method's own solution (bracket widened where the
interpolant's error moved the sign change out of it), and the state at the event is that solution. A
cubic Hermite interpolant across a long step of an order-8 method errs by about h^4 |x^(4)| / 384
(dopri78 at rtol 1e-10: 3e-4 in the event time, and the run went on from that state).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from cvtfem.errors import InputError

__all__ = ["EventLocator", "crossings"]

SIMULTANEOUS_RTOL = 1e-9   # crossings closer than this fraction of h count as simultaneous
INTERIOR = (1e-10, 1e-6, 1e-3, 1 / 64, 1 / 8, 1 / 2)   # samples for indicators restarting at 0
EVENT_SAMPLES = 4          # interior samples per step that detect even crossings (dense mode)
SCAN = 8                   # sub-intervals scanned for the earliest crossing (dense mode)
TINY = np.finfo(float).tiny


def _root_past(fun, ta: float, tb: float) -> float:
    """Root of ``fun`` in ``[ta, tb]`` (signs differ) by Brent's method to a few ulps, moved by ulps towards
    ``tb`` until ``fun`` has left the side of ``ta`` (or is 0): the state at the event is then past the
    crossing, so the restarted indicator's reference sign is the new side (a state a few 1e-16 short of
    it made the trapezoidal rule's tiny restart steps fire the same crossing again)."""
    side = np.sign(fun(ta))
    t = brentq(fun, ta, tb, xtol=4 * np.finfo(float).eps * max(abs(tb), 1e-300), rtol=1e-15)
    step = float(np.spacing(abs(t)))
    while t < tb and np.sign(fun(t)) == side:
        t = min(t + step, tb)
        step *= 2
    return t


def crossings(g0: np.ndarray, g1: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Mask of indicators whose sign changed in the allowed direction (0 never fires again)."""
    up = (g0 < 0) & (g1 >= 0)
    down = (g0 > 0) & (g1 <= 0)
    return (up & (direction >= 0)) | (down & (direction <= 0))


class EventLocator:
    """Stores indicators at the step start and finds the earliest crossing in a step."""

    def __init__(self, system, stats, mode: str = "dense", samples: int = EVENT_SAMPLES) -> None:
        if mode not in ("dense", "linear"):
            raise InputError("event_location", mode, "must be 'dense' or 'linear'")
        if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 0:
            raise InputError("event_samples", samples, "must be an integer >= 0")
        self.system, self.stats, self.mode, self.samples = system, stats, mode, int(samples)
        self.g0: np.ndarray | None = None
        self.side: np.ndarray | None = None
        self._ga: np.ndarray | None = None

    def g(self, t: float, x: np.ndarray) -> np.ndarray:
        self.stats.counts["nevfun"] += 1
        return np.asarray(self.system.events(t, x), dtype=float)

    def start(self, t: float, x: np.ndarray, fired: np.ndarray | None = None) -> None:
        """Indicators at a step start; fired ones restart at exactly 0 and remember the side
        they came from (``side``; 0 = unknown, e.g. an exact zero at the initial state)."""
        self.g0 = self.g(t, x)
        self.side = np.zeros(len(self.g0))
        if fired is not None:
            self.g0[fired] = 0.0
            self.side[fired] = np.sign(self._ga[fired])

    def _brackets(self, t0, t1, g1, dense):
        """Per-indicator bracket ``(ta, ga, tb, gb)``, resolving indicators that start at 0."""
        m = len(g1)
        ga, ta = self.g0.copy(), np.full(m, t0)
        gb, tb = g1.copy(), np.full(m, t1)
        zero = ga == 0.0
        direction = self.system.event_direction
        for frac in INTERIOR if zero.any() else ():
            tq = t0 + frac * (t1 - t0)
            gq = self.g(tq, dense(tq))
            new = zero & (gq != 0.0)
            virtual = -np.sign(gq) * TINY            # a fresh zero comes from the other side
            fire_at_t0 = new & (self.side == 0) & crossings(virtual, gq, direction)
            ga[fire_at_t0], gb[fire_at_t0], tb[fire_at_t0] = virtual[fire_at_t0], gq[fire_at_t0], tq
            rest = new & ~fire_at_t0                 # the sign after the restart is the reference
            ga[rest], ta[rest] = gq[rest], tq
            zero &= ~new
            if not zero.any():
                break
        return ta, ga, tb, gb

    def locate(self, t0, x0, t1, x1, dense, precise=None):
        """Earliest crossing in ``[t0, t1]``: ``(t*, x*, fired mask, g1)`` or ``None``.

        ``dense(t)`` evaluates the step's interpolant; ``precise(t)`` (optional) the method's own solution,
        on which crossings are refined.
        """
        g1 = self.g(t1, x1)
        h = t1 - t0
        ta, ga, tb, gb = self._brackets(t0, t1, g1, dense)
        direction = self.system.event_direction
        cross = crossings(ga, gb, direction)
        extra = None
        if self.mode == "dense" and self.samples and not cross.any():
            # no end-point sign change: sample the interior for an even number of crossings
            ts = t0 + h * np.arange(1, self.samples + 1) / (self.samples + 1)
            xs = dense(ts)                                   # (n, samples), one interpolation
            gs = np.array([self.g(t, xs[:, i]) for i, t in enumerate(ts)])
            extra = (ts, gs)
            if np.all(ta == t0) and np.all(tb == t1):    # common case, vectorised
                seq = np.vstack([ga, gs, gb])
                cross = crossings(seq[:-1], seq[1:], direction).any(axis=0)
            else:
                cross = crossings(*self._first(ta, ga, tb, gb, ts, gs)[1::2], direction)
        if not cross.any():
            self.g0 = g1
            return None
        outer = (ta.copy(), ga.copy(), tb.copy(), gb.copy())
        if self.mode == "dense":   # scan the interpolant for the first sign change
            ta, ga, tb, gb = self._scan(ta, ga, tb, gb, dense, extra)
            cross = crossings(ga, gb, direction)
        idx = np.flatnonzero(cross)
        if not len(idx):
            self.g0 = g1
            return None
        if self.mode == "linear":
            t_k = ta[idx] + ga[idx] / (ga[idx] - gb[idx]) * (tb[idx] - ta[idx])
        elif precise is not None:
            t_k = np.array([self._refine_precise(k, (ta[k], ga[k], tb[k], gb[k]), [o[k] for o in outer], precise)
                            for k in idx])
        else:
            t_k = np.array([self._refine(k, ta[k], ga[k], tb[k], gb[k], dense) for k in idx])
        t_star = float(t_k.min())
        fired = np.zeros_like(cross)
        fired[idx[t_k <= t_star + SIMULTANEOUS_RTOL * abs(h)]] = True
        self._ga = ga
        if self.mode == "linear":
            th = (t_star - t0) / h
            x_star = (1 - th) * x0 + th * x1
        else:
            x_star = dense(t_star) if precise is None else precise(t_star)
        return t_star, x_star, fired, g1

    def _scan(self, ta, ga, tb, gb, dense, extra=None):
        """Narrow each bracket to its first sub-interval with a sign change (``SCAN`` samples
        on the common part of the brackets, merged with the detection samples ``extra``;
        indicators without an end-point change are checked too, which catches a double
        crossing inside the step)."""
        lo, hi = float(ta.max()), float(tb.min())
        ts = lo + (hi - lo) * np.arange(1, SCAN) / SCAN if hi > lo else np.empty(0)
        gs = np.array([self.g(t, dense(t)) for t in ts]).reshape(len(ts), len(ga))
        if extra is not None:
            ts, gs = np.concatenate([ts, extra[0]]), np.concatenate([gs, extra[1]])
            order = np.argsort(ts, kind="stable")
            ts, gs = ts[order], gs[order]
        if not len(ts):
            return ta, ga, tb, gb
        return self._first(ta, ga, tb, gb, ts, gs)

    def _first(self, ta, ga, tb, gb, ts, gs):
        """Per indicator, the first crossing along ``ta, ts (inside (ta, tb)), tb``:
        ``(ta, ga, tb, gb)`` narrowed to it (unchanged where there is none)."""
        direction = self.system.event_direction
        ta, ga, tb, gb = ta.copy(), ga.copy(), tb.copy(), gb.copy()
        prev_t, prev_g = ta.copy(), ga.copy()
        done = np.zeros(len(ga), bool)
        for t, g in zip(ts, gs):
            inside = ~done & (t > prev_t) & (t < tb)
            hit = inside & crossings(prev_g, g, direction)
            ta[hit], ga[hit], tb[hit], gb[hit] = prev_t[hit], prev_g[hit], t, g[hit]
            done |= hit
            upd = inside & ~hit
            prev_t[upd], prev_g[upd] = t, g[upd]
        last = ~done & crossings(prev_g, gb, direction)
        ta[last], ga[last] = prev_t[last], prev_g[last]
        return ta, ga, tb, gb

    def _refine_precise(self, k, inner, outer, precise):
        """Brent's method on ``e_k(t, precise(t))``, from the interpolant's bracket ``inner`` widened
        (doubling, at most to ``outer``, the bracket before the scan, whose ends are the step's own
        values) until the method's own solution changes sign in it."""
        ta, _, tb, _ = inner
        oa, oga, ob, ogb = outer

        def fun(t):
            return oga if t == oa else ogb if t == ob else self.g(t, precise(t))[k]

        width = tb - ta
        while True:
            fa, fb = fun(ta), fun(tb)
            if fb == 0.0:
                return tb
            if np.sign(fa) != np.sign(fb) or (ta == oa and tb == ob):
                break
            width *= 2
            ta, tb = max(oa, ta - width), min(ob, tb + width)
        if np.sign(fa) == np.sign(fb):   # no change on the method's own solution: keep the interpolant's
            return inner[0] + inner[1] / (inner[1] - inner[3]) * (inner[2] - inner[0])
        return _root_past(fun, ta, tb)

    def _refine(self, k, ta, ga, tb, gb, dense):
        """Brent's method on ``e_k(t, dense(t))`` over ``[ta, tb]`` (signs differ there)."""
        if gb == 0.0:
            return tb

        def fun(t):
            return ga if t == ta else gb if t == tb else self.g(t, dense(t))[k]

        return _root_past(fun, ta, tb)
