"""Run guards shared by :func:`~cvtfem.integrate.solve`, :class:`~cvtfem.integrate.CvtfemSolver`
and ``cvtfem run``: a one-step growth guard and a local-error monitor for fixed steps.

Growth guard. A step fails when its ``max|x1|`` exceeds ``limit`` times the reference
``max(largest max|x| so far, max|h F0|, max(atol))``. A stable step grows ``|x|`` by a bounded
factor and a step far outside the stability region by ``|R(h lambda)|`` (4e18 for RK4 at
``h lambda = -1e5``). In adaptive runs the error control already rejects such steps; the guard
is the backstop for an estimate that is fooled (a stage pattern that cancels in the embedded
difference, a loose tolerance). A correct solution cannot trip it: exponential growth
``e^(lambda h)`` of 1e8 in one step needs ``lambda h > 18``, where no method's step is within
any ``rtol < 1`` (the error control rejects it), and growth spread over many steps (``y' = y``
for 60 s, ``e^60``) is compared with the largest ``|x|`` so far, which grows with it.

Local-error monitor. Fixed-step runs have no error control; every ``every`` steps the
monitor estimates the local error of one step: from the method's embedded estimate when it has
one (computed only on those steps), else by step doubling for explicit Runge-Kutta methods
(one extra step of ``2h`` from the state two steps back, Richardson:
``err_h = (x_hh - x_2h) / (2^(p+1) - 2)``), and keeps the largest weighted RMS norm
(1 = at the run's rtol/atol).
"""
from __future__ import annotations

import numpy as np

from cvtfem.integrate.controller import error_norm

__all__ = ["GrowthGuard", "ErrorMonitor", "norm_max"]


def norm_max(x) -> float:
    """``max|x|`` (0 for an empty array)."""
    return float(np.max(np.abs(x))) if np.size(x) else 0.0


class GrowthGuard:
    """One-step growth guard of a run (see the module docstring); ``limit`` None disables it."""

    def __init__(self, limit: float | None, x0, atol, method: str, adaptive: bool) -> None:
        self.limit, self.method, self.adaptive = limit, method, adaptive
        self.largest, self.floor = norm_max(x0), norm_max(atol)

    def check(self, x0, x1, h: float, f0=None) -> str | None:
        """Why the step ``x0 -> x1`` (size ``h``, slope ``f0`` at its start if known) is a
        blow-up, else None. Call :meth:`update` with each accepted state."""
        if self.limit is None:
            return None
        scale = max(self.largest, self.floor, 0.0 if f0 is None else norm_max(h * f0))
        grown = norm_max(x1)
        if not (grown > self.limit * scale and grown > 0):
            return None
        start = norm_max(x0)
        factor = grown / start if start > 0 else grown / scale
        k = int(np.argmax(np.abs(x1)))
        kind = "accepted step" if self.adaptive else "step"
        return (f"instability ({self.method}): |x| grew by a factor {factor:.3g} in one {kind} (component "
                f"{k}), from {start:.3g} to {grown:.3g} (more than growth_limit = {self.limit:.3g} times the "
                f"largest |x| so far)")

    def hint(self) -> str:
        """What to do, appended to the message after time and step."""
        if self.adaptive:
            return (": the error estimate did not reject it (a blow-up, or a discontinuity the embedded "
                    "estimate cannot see); tighten rtol/atol or limit the step (growth_limit=None disables "
                    "this check)")
        return (": h is beyond the method's stability region; reduce h or use an implicit or stabilized "
                "method (growth_limit=None disables this check)")

    def update(self, x) -> None:
        self.largest = max(self.largest, norm_max(x))


class ErrorMonitor:
    """Local-error estimate of a fixed-step run every ``every`` steps (see the module docstring).

    Call :meth:`before` ahead of each step and :meth:`after` with each accepted attempt;
    :meth:`reset` after an event switch. ``worst`` is the largest norm (1 = at tolerance),
    ``t_worst`` its time, ``checks`` the number of estimates, ``nfev`` the RHS calls spent.
    """

    def __init__(self, stepper, rtol: float, atol, every: int) -> None:
        from cvtfem.integrate.rk import ExplicitRK

        self.stepper, self.rtol, self.atol, self.every = stepper, rtol, atol, int(every)
        if stepper.error_order is not None:
            self.mode = "embedded"
        elif isinstance(stepper, ExplicitRK):
            self.mode = "doubling"
        else:
            self.mode = "none"   # implicit/W methods without estimate: extra steps would disturb their LU
        self.worst, self.t_worst, self.checks, self.nfev = 0.0, float("nan"), 0, 0
        self._n = 0
        self._first = None

    @property
    def active(self) -> bool:
        return self.every > 0 and self.mode != "none"

    def before(self) -> None:
        """Ask the method for its embedded estimate on the steps that are checked."""
        if self.every > 0 and self.mode == "embedded":
            self.stepper.need_error = self._n % self.every == self.every - 1

    def after(self, att) -> None:
        if not self.every > 0 or self.mode == "none":
            return
        self._n += 1
        if self.mode == "embedded":   # explicit RK pairs compute it anyway; others only when asked
            if self._n % self.every == 0 and att.err is not None:
                self._record(error_norm(att.err, att.x0, att.x1, self.rtol, self.atol), att.t0 + att.h)
            self.stepper.need_error = False
            return
        phase = self._n % self.every
        if phase == self.every - 1:         # the first of the two steps that are doubled
            self._first = att
        elif phase == 0 and self._first is not None:
            first, self._first = self._first, None
            if abs(first.h - att.h) <= 1e-9 * att.h and np.array_equal(first.x1, att.x0):
                self._double(first, att)

    def _double(self, first, second) -> None:
        st = self.stepper
        keep = (st._cache, st._start)
        n0 = st.stats.counts["nfev"]
        big = st.attempt(first.t0, first.x0, 2 * first.h)
        st._cache, st._start = keep
        self.nfev += st.stats.counts["nfev"] - n0
        err = (second.x1 - big.x1) / (2.0 ** (st.order + 1) - 2.0)
        self._record(error_norm(err, second.x0, second.x1, self.rtol, self.atol), second.t0 + second.h)

    def _record(self, en: float, t: float) -> None:
        self.checks += 1
        if not en <= self.worst:
            self.worst, self.t_worst = en, t

    def snapshot(self) -> np.ndarray:
        """``[steps seen, worst, t_worst, checks, nfev]`` for a checkpoint (see :meth:`restore`)."""
        return np.array([self._n, self.worst, self.t_worst, self.checks, self.nfev], dtype=float)

    def restore(self, v) -> None:
        """Continue from a :meth:`snapshot` (a pending doubled pair is not kept)."""
        self._n, self.worst, self.t_worst = int(v[0]), float(v[1]), float(v[2])
        self.checks, self.nfev = int(v[3]), int(v[4])

    def reset(self) -> None:
        """Forget a pending doubled pair (an event switched the state)."""
        self._first = None

    def warning(self) -> str | None:
        """One line when the largest estimate exceeded the tolerance, else None."""
        if not self.worst > 1.0:
            return None
        return (f"fixed step too large for the tolerance: estimated local error {self.worst:.3g} x (rtol = "
                f"{self.rtol:g}, atol = {norm_max(self.atol):g}) at t = {self.t_worst:.6g} s ({self.mode} "
                f"estimate, {self.checks} checks); reduce h or use an adaptive method")

    def stats(self) -> dict:
        """Counters for a result's stats: checks, RHS calls spent, the largest norm."""
        return {"nerr_checks": self.checks, "nfev_err_check": self.nfev, "err_check_max": self.worst}
