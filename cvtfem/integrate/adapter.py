"""Any cvtfem method as a ``scipy.integrate.OdeSolver`` (spec §11.2, "export").

``solve_ivp(fun, t_span, y0, method=CvtfemSolver, cvtfem_method="rock4", rtol=...)`` works, and
step-by-step drivers that expect scipy's interface (``step()``, ``t``, ``y``, ``status``,
``dense_output()``, ``nfev``/``njev``/``nlu``) can use every playground method. A thin adapter over
the one step loop (:class:`~cvtfem.integrate.stepping.Stepping`); events and discrete-state switches
are :func:`cvtfem.integrate.solve`'s (solve_ivp cannot switch).
"""
from __future__ import annotations

from scipy.integrate import DenseOutput, OdeSolver

from cvtfem.errors import InputError
from cvtfem.integrate.methods import METHODS
from cvtfem.integrate.stepping import GROWTH_LIMIT, NativeEngine, Stepping
from cvtfem.integrate.system import as_system

__all__ = ["CvtfemSolver"]


class _Dense(DenseOutput):
    def __init__(self, cand):
        super().__init__(cand.t0, cand.t1)
        self.cand = cand

    def _call_impl(self, t):
        return self.cand.dense(t)


class CvtfemSolver(OdeSolver):
    """``OdeSolver`` running ``cvtfem_method`` with a fixed ``h`` or adaptive steps (``h=None``).

    Extra keywords: ``n2``, ``jac``, ``jac_sparsity``, ``growth_limit`` and ``error_check``
    (as in :func:`~cvtfem.integrate.solve`; a blow-up is a failed step whose message names
    method, component, t and h) and the method's own options.
    ``stats`` holds the full cvtfem counters; ``monitor`` the local-error monitor of fixed steps;
    ``stepping`` the step loop (its :meth:`~Stepping.state` is the full memory).
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
        system = as_system(self.fun, self.y, n2=n2, jac=jac, jac_sparsity=jac_sparsity)
        cls = METHODS[cvtfem_method]
        unknown = set(options) - cls.OPTIONS
        if unknown:
            raise InputError(sorted(unknown)[0], options[sorted(unknown)[0]],
                             f"is not an option of {cvtfem_method!r} (it accepts {sorted(cls.OPTIONS)})")
        try:
            engine = NativeEngine(cvtfem_method, system, t0, self.y, t_bound, rtol, atol, h, None, error_check,
                                  first_step, options)
        except InputError as err:
            if err.where != "method":
                raise
            raise InputError("h", h, f"must be given: {cvtfem_method!r} has no error estimate") from None
        self.stepping = Stepping(engine, t0, self.y, t_bound, growth_limit=growth_limit)
        self.stepper, self.stats, self.monitor, self.guard = engine.stepper, engine.stats, engine.monitor, \
            self.stepping.guard
        self._sync()

    @property
    def h_next(self) -> float:
        """Size of the next step, s."""
        return self.stepping.h

    def _sync(self) -> None:
        """scipy's counters from the cvtfem ones (which also count Jacobian RHS calls)."""
        c = self.stats.counts
        self.nfev, self.njev, self.nlu = c["nfev"], c["njev"], c["nlu"]

    def _step_impl(self):
        run = self.stepping
        t = run.t
        taken = run.step()
        self._sync()
        if run.status == "failed":
            return False, run.message
        self.t_old, self.t, self.y = t, run.t, run.x
        return taken, None

    def _dense_output_impl(self):
        return _Dense(self.stepping.last)
