"""``solve``: the ``solve_ivp``-style driver (spec §6, §11.2). Validates, loops, collects.

No numerics live here: every step comes from the one step loop
(:class:`~cvtfem.integrate.stepping.Stepping`), with any registered method.
"""
from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from cvtfem.blas import single_thread_blas
from cvtfem.errors import InputError, NumericalError
from cvtfem.integrate.events import EVENT_SAMPLES
from cvtfem.integrate.methods import METHODS, SCIPY_METHODS, IgnoredOptionWarning
from cvtfem.integrate.stepping import GROWTH_LIMIT, Stepping, make_engine
from cvtfem.integrate.system import as_system

__all__ = ["solve", "OdeResult", "IgnoredOptionWarning"]
log = logging.getLogger(__name__)

MESSAGES = {0: "The solver successfully reached the end of the integration interval.",
            1: "A termination event occurred."}
#: counters scipy's methods do not report (-1 in ``stats``)
SCIPY_UNCOUNTED = ("nsolve", "nnewton", "nreject", "nfev_jac")


@dataclass
class OdeResult:
    """Solution of :func:`solve`, shaped like ``solve_ivp``'s.

    ``t`` (n_t,), ``y`` (n, n_t), ``stats`` (counters and timers, see
    :mod:`cvtfem.integrate.stats`), ``status`` (0 end reached, 1 terminal event, -1 failure),
    ``message``, ``t_events``/``y_events`` (one array per indicator).
    """

    t: np.ndarray
    y: np.ndarray
    stats: dict
    status: int
    message: str
    t_events: list = field(default_factory=list)
    y_events: list = field(default_factory=list)
    method: str = ""

    @property
    def success(self) -> bool:
        return self.status >= 0


def solve(fun, t_span, y0, method: str = "dopri45", h: float | None = None, rtol: float = 1e-6,
          atol: float = 1e-9, events=None, jac=None, jac_sparsity=None, t_eval=None, *, n2: int = 0,
          switch=None, adaptive: bool | None = None, event_location: str = "dense",
          max_steps: int = 10_000_000, max_events: int = 100_000, raise_on_failure: bool = False,
          growth_limit: float | None = GROWTH_LIMIT, event_samples: int = EVENT_SAMPLES,
          error_check: int = 0, controller: str | None = None, split=None, **options) -> OdeResult:
    """Integrate ``x' = F(t, x)`` over ``t_span`` with one of the playground's methods.

    Parameters
    ----------
    fun : callable ``fun(t, y)``, :class:`OdeSystem`, or a model with ``rhs`` and ``n2``
    t_span : (t0, tf), s, ``tf > t0``
    y0 : (n,) initial state
    method : str
        A registered name (:mod:`cvtfem.integrate.methods`): ``euler rk4 dopri45 dopri56 dopri78
        gbs gbs-smooth euler-extrapolation sw24 w1 w1-extrapolation theta trapezoidal
        implicit-euler rkc rock2 rock4 dumka3`` or a scipy name (``RK23 RK45 DOP853 Radau BDF
        LSODA``: scipy's ``OdeSolver`` steps, with our guards, events and switch).
    h : float, s
        Fixed step (spec §9.1); with ``adaptive=True`` (and for scipy methods) only the first step.
    rtol, atol : tolerances of the error control (used when adaptive).
    events : callable(s) ``e(t, y)`` with optional ``.direction``/``.terminal`` attributes, or
        ``(indicators, direction, terminal)``.
    jac, jac_sparsity : analytic Jacobian or its sparsity pattern (implicit/W methods).
    t_eval : times to report (the step's dense output, evaluated one time at a time, as
        ``cvtfem run`` samples its outputs); default every step.
    n2 : number of second-order pairs in ``y = [u, v, z]``.
    switch : ``switch(t, y, fired) -> y_new | None`` discrete-state automaton at events.
    event_location : ``"dense"`` (Brent on the interpolant) or ``"linear"`` (source's scheme).
    event_samples : int
        Dense mode: indicators are also sampled at this many equally spaced interior points of
        every step (default 4), so an even number of crossings inside one step is found;
        0 detects sign changes between the step's end points only (the source's scheme).
        Crossings closer together than ``h / (event_samples + 1)`` can still be missed.
    growth_limit : float or None
        A run stops with an "instability" status (-1) at the first (accepted) step whose state
        norm ``max|x1|`` exceeds ``growth_limit`` times the reference ``max(largest max|x| so
        far, max|h F0|, max(atol))`` (default 1e8: far above any stable or accurate step's
        growth, far below the amplification of a step far beyond the stability limit; adaptive
        runs too, as a backstop for a fooled error estimate). ``None`` disables the guard;
        then only a non-finite state stops a run.
    error_check : int
        Fixed-step runs: estimate the local error every ``error_check`` steps (embedded
        estimate, or step doubling for explicit RK methods without one; 0: off) and warn in
        ``message`` when it exceeded rtol/atol; counters ``nerr_checks``, ``nfev_err_check``,
        ``err_check_max`` in ``stats``.
    controller : str or None
        Step-size controller of native adaptive runs: ``"i"`` (elementary), ``"pi"`` (proportional-
        integral, smoother step sequences at a stability limit) or ``"predictive"`` (Gustafsson, shrinks
        ``h`` when the error grows from step to step); None: the method's default (``"predictive"``
        for ``rodas4``, ``rodas5p`` and ``radau5``, else ``"i"``). All take no growth right after a rejection.
    split : :class:`~cvtfem.integrate.system.StiffSplit` or None
        The RHS split into an explicit and a stiff part, for the splitting method ``strang-friction``; a model
        passed as ``fun`` gives its own (its ``stiff_split``).
    **options : method options (``d``, ``alpha``, ``newton``, ``stages``, ``sequence`` ...);
        an option the method ignores warns with :class:`IgnoredOptionWarning`.
    """
    t0, tf = (float(v) for v in t_span)
    if not (np.isfinite(t0) and np.isfinite(tf) and tf > t0):
        raise InputError("t_span", t_span, "must be two finite times with t_span[1] > t_span[0]")
    y0 = np.array(y0, dtype=np.result_type(np.asarray(y0).dtype, float))
    if y0.ndim != 1 or not np.all(np.isfinite(y0)):
        raise InputError("y0", y0, "must be a 1-D array of finite numbers")
    if h is not None and not (np.isfinite(h) and h > 0):
        raise InputError("h", h, "must be a positive step size in s")
    if not rtol > 0 or np.any(np.asarray(atol) < 0):
        raise InputError("rtol/atol", (rtol, atol), "rtol must be positive and atol non-negative")
    if t_eval is not None:
        t_eval = np.asarray(t_eval, dtype=float)
        if t_eval.ndim != 1 or np.any(np.diff(t_eval) < 0) or t_eval[0] < t0 or t_eval[-1] > tf:
            raise InputError("t_eval", "array", "must be sorted and lie within t_span")
    if method not in METHODS and method not in SCIPY_METHODS:
        raise InputError("method", method, f"must be one of {sorted(METHODS) + sorted(SCIPY_METHODS)}")
    system = as_system(fun, y0, n2=n2, jac=jac, jac_sparsity=jac_sparsity, events=events, switch=switch, split=split)
    scipy = method in SCIPY_METHODS
    if scipy:
        from cvtfem.integrate.scipy_bridge import SCIPY_OPTIONS

        for name, value in (("jac", jac), ("jac_sparsity", jac_sparsity)):
            if value is not None and name not in SCIPY_OPTIONS[method]:
                warnings.warn(f"option `{name}` is ignored by scipy method {method!r}",
                              IgnoredOptionWarning, stacklevel=2)
        for key, val, default in (("adaptive", adaptive, None), ("error_check", error_check, 0),
                                  ("controller", controller, None)):
            if val != default:
                warnings.warn(f"option `{key}` is ignored by scipy method {method!r}",
                              IgnoredOptionWarning, stacklevel=2)
    with single_thread_blas():   # the same bits on every machine (cvtfem.blas)
        engine = make_engine(method, system, t0, y0, tf, rtol, atol, h, adaptive, error_check, options=options,
                             controller=controller)
        run = Stepping(engine, t0, y0, tf, growth_limit=growth_limit, event_location=event_location,
                       event_samples=event_samples, max_steps=max_steps, max_events=max_events)
        wall = time.perf_counter()
        ts, ys = ([t0], [y0.copy()]) if t_eval is None else ([], [])
        i_eval = 0
        while run.status == "running":
            if not run.step():
                break
            t1 = run.last.t1
            if t_eval is not None:
                while i_eval < len(t_eval) and t_eval[i_eval] <= t1:
                    ts.append(t_eval[i_eval])
                    ys.append(run.dense(t_eval[i_eval]))
                    i_eval += 1
            else:
                ts.append(t1)
                ys.append(run.last.x1.copy())
        stats = engine.stats
        stats.times["t_total"] = time.perf_counter() - wall
        engine.counts()   # scipy's own counters into stats
    status = {"finished": 0, "event": 1, "failed": -1}[run.status]
    message = MESSAGES[status] if status >= 0 else run.message
    extra = engine.report()
    warn = engine.warning()
    if warn is not None and status >= 0:
        message += f" Warning: {warn}."
        log.warning("%s: %s", method, warn)
    if status < 0:
        log.warning("%s: %s", method, message)
        if raise_on_failure:
            raise NumericalError(message, t=run.t, component=method)
    out = {**stats.as_dict(), **extra}
    if scipy:
        out.update(dict.fromkeys(SCIPY_UNCOUNTED, -1))
    y = np.array(ys).T if ys else np.empty((len(y0), 0))
    return OdeResult(np.array(ts), y, out, status, message,
                     [np.array(v) for v in run.t_events], [np.array(v) for v in run.y_events], method)
