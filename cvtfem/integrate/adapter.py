"""Any cvtfem method as a ``scipy.integrate.OdeSolver`` (spec §11.2, "export").

``solve_ivp(fun, t_span, y0, method=CvtfemSolver, cvtfem_method="rock4", rtol=...)`` works, and
step-by-step drivers that expect scipy's interface (``step()``, ``t``, ``y``, ``status``,
``dense_output()``, ``nfev``/``njev``/``nlu``) can use every playground method. Events and
discrete-state switches stay with :func:`cvtfem.integrate.solve` (solve_ivp cannot switch).
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import DenseOutput, OdeSolver

from cvtfem.errors import InputError
from cvtfem.integrate.base import StepFailure, hermite
from cvtfem.integrate.controller import SimpleController, error_norm
from cvtfem.integrate.driver import GROWTH_LIMIT, _initial_step
from cvtfem.integrate.guards import ErrorMonitor, GrowthGuard
from cvtfem.integrate.methods import METHODS
from cvtfem.integrate.stats import Stats
from cvtfem.integrate.system import as_system

__all__ = ["CvtfemSolver"]


class _Hermite(DenseOutput):
    def __init__(self, att, f1):
        super().__init__(att.t0, att.t0 + att.h)
        self.att, self.f1 = att, f1

    def _call_impl(self, t):
        return hermite(self.att, self.f1, t)


class CvtfemSolver(OdeSolver):
    """``OdeSolver`` running ``cvtfem_method`` with a fixed ``h`` or adaptive steps (``h=None``).

    Extra keywords: ``n2``, ``jac``, ``jac_sparsity``, ``growth_limit`` and ``error_check``
    (as in :func:`~cvtfem.integrate.solve`; a blow-up is a failed step whose message names
    method, component, t and h) and the method's own options.
    ``stats`` holds the full cvtfem counters; ``monitor`` the local-error monitor of fixed steps.
    """

    def __init__(self, fun, t0, y0, t_bound, vectorized=False, cvtfem_method: str = "dopri45",
                 h: float | None = None, rtol: float = 1e-6, atol: float = 1e-9, n2: int = 0,
                 jac=None, jac_sparsity=None, first_step=None, growth_limit: float | None = GROWTH_LIMIT,
                 error_check: int = 0, **options):
        if cvtfem_method not in METHODS:
            raise InputError("cvtfem_method", cvtfem_method, f"must be one of {sorted(METHODS)}")
        super().__init__(fun, t0, y0, t_bound, vectorized, support_complex=True)
        if self.direction < 0:
            raise InputError("t_bound", t_bound, "must be after t0 (forward integration only)")
        self.stats = Stats()
        system = as_system(self.fun, self.y, n2=n2, jac=jac, jac_sparsity=jac_sparsity)
        cls = METHODS[cvtfem_method]
        unknown = set(options) - cls.OPTIONS
        if unknown:
            raise InputError(sorted(unknown)[0], options[sorted(unknown)[0]],
                             f"is not an option of {cvtfem_method!r} (it accepts {sorted(cls.OPTIONS)})")
        self.stepper = cls(system, self.stats, **options)
        self.adaptive = h is None
        if self.adaptive and self.stepper.error_order is None:
            raise InputError("h", h, f"must be given: {cvtfem_method!r} has no error estimate")
        self.stepper.need_error = self.adaptive
        self.stepper.tolerances = (rtol, atol) if self.adaptive else None
        self.rtol, self.atol = rtol, atol
        self.ctrl = SimpleController(quantum=getattr(self.stepper, "STEP_QUANTUM", 1.0))
        span = abs(t_bound - t0)
        self.h_next = (first_step or _initial_step(self.stepper, t0, self.y, rtol, atol, span)
                       if self.adaptive else float(h))
        if growth_limit is not None and not growth_limit > 1:
            raise InputError("growth_limit", growth_limit, "must be a number > 1 or None")
        self.guard = GrowthGuard(growth_limit, self.y, atol, cvtfem_method, self.adaptive)
        self.monitor = ErrorMonitor(self.stepper, rtol, atol, 0 if self.adaptive else error_check)
        self._att = None
        self._sync()

    def _sync(self) -> None:
        """scipy's counters from the cvtfem ones (which also count Jacobian RHS calls)."""
        c = self.stats.counts
        self.nfev, self.njev, self.nlu = c["nfev"], c["njev"], c["nlu"]

    def _step_impl(self):
        t, x = self.t, self.y
        h_min = 16 * np.finfo(float).eps * max(abs(t), 1.0)
        while True:
            h = min(self.h_next, self.t_bound - t, self.stepper.max_step() if self.adaptive else np.inf)
            if self.t_bound - (t + h) < 1e-9 * h:    # absorb round-off: land on t_bound
                h = self.t_bound - t
            self.monitor.before()
            try:
                with np.errstate(over="ignore", invalid="ignore"):
                    att = self.stepper.attempt(t, x, h)
                ok = bool(np.all(np.isfinite(att.x1)))
                why = "non-finite state"
            except StepFailure as err:
                att, ok, why = None, False, str(err)
            if not self.adaptive:
                blow_up = self.guard.check(x, att.x1, h, att.f0) if ok else None
                if not ok or blow_up is not None:
                    self._sync()
                    where = f" at t = {t + h:.6g} s with fixed step h = {h:.3g} s"
                    return False, (why + where if blow_up is None else blow_up + where + self.guard.hint())
                break
            accept, h_new = (self.ctrl.propose(h, error_norm(att.err, x, att.x1, self.rtol, self.atol),
                                               self.stepper.error_order) if ok else (False, 0.25 * h))
            self.h_next = h_new
            if accept:
                blow_up = self.guard.check(x, att.x1, h, att.f0)
                if blow_up is not None:
                    self._sync()
                    return False, f"{blow_up} at t = {t + h:.6g} s with adaptive step h = {h:.3g} s{self.guard.hint()}"
                break
            self.stats.counts["nreject"] += 1
            if h_new < h_min:
                return False, f"step size underflow at t = {t:.6g} s" + (f": {why}" if not ok else "")
        self.stepper.accept(att)
        self.monitor.after(att)
        self.guard.update(att.x1)
        self.stats.counts["nsteps"] += 1
        self._att = att
        self.t_old, self.t, self.y = t, t + h, att.x1
        self._sync()
        return True, None

    def _dense_output_impl(self):
        att = self._att
        f1 = att.f1 if att.f1 is not None else self.stepper.f(att.t0 + att.h, att.x1)
        if att.f0 is None:
            att.f0 = self.stepper.f(att.t0, att.x0)
        return _Hermite(att, f1)
