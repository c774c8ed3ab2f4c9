"""``solve``: the ``solve_ivp``-style driver (spec §6, §11.2). Validates, loops, collects.

No numerics live here: steps come from a :class:`~cvtfem.integrate.base.Stepper`, step sizes
from a controller, event times from an :class:`~cvtfem.integrate.events.EventLocator`.
"""
from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from cvtfem.errors import InputError, NumericalError
from cvtfem.integrate.base import StepFailure, hermite
from cvtfem.integrate.controller import FixedStep, SimpleController, error_norm
from cvtfem.integrate.events import EVENT_SAMPLES, EventLocator
from cvtfem.integrate.guards import ErrorMonitor, GrowthGuard
from cvtfem.integrate.methods import METHODS, SCIPY_METHODS, UNAVAILABLE, all_options
from cvtfem.integrate.stats import Stats
from cvtfem.integrate.system import as_system

__all__ = ["solve", "OdeResult", "IgnoredOptionWarning"]
log = logging.getLogger(__name__)

MESSAGES = {0: "The solver successfully reached the end of the integration interval.",
            1: "A termination event occurred."}


ZENO_GAP = 1e-9     # events closer than this fraction of the span ...
ZENO_GAP_H = 1e-6   # ... or of the step count towards Zeno accumulation
ZENO_COUNT = 3      # that many in a row stop the run
GROWTH_LIMIT = 1e8  # default growth guard (see `solve` and :mod:`cvtfem.integrate.guards`)


class IgnoredOptionWarning(UserWarning):
    """An option was given that the chosen method does not use."""


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


def _check_options(method: str, accepted: frozenset, options: dict) -> dict:
    known = all_options()
    for key in options:
        if key not in known:
            raise InputError(key, options[key], f"is not an option of any method; known: {sorted(known)}")
    use = {k: v for k, v in options.items() if k in accepted}
    for key in sorted(set(options) - set(use)):
        warnings.warn(f"option `{key}` is ignored by method {method!r} (it accepts {sorted(accepted)})",
                      IgnoredOptionWarning, stacklevel=3)
    return use


def solve(fun, t_span, y0, method: str = "dopri45", h: float | None = None, rtol: float = 1e-6,
          atol: float = 1e-9, events=None, jac=None, jac_sparsity=None, t_eval=None, *, n2: int = 0,
          switch=None, adaptive: bool | None = None, event_location: str = "dense",
          max_steps: int = 10_000_000, max_events: int = 100_000, raise_on_failure: bool = False,
          growth_limit: float | None = GROWTH_LIMIT, event_samples: int = EVENT_SAMPLES,
          error_check: int = 0, **options) -> OdeResult:
    """Integrate ``x' = F(t, x)`` over ``t_span`` with one of the playground's methods.

    Parameters
    ----------
    fun : callable ``fun(t, y)``, :class:`OdeSystem`, or a model with ``rhs`` and ``n2``
    t_span : (t0, tf), s, ``tf > t0``
    y0 : (n,) initial state
    method : str
        ``euler rk4 dopri45 dopri56 dopri78 gbs gbs-smooth euler-extrapolation sw24 w1
        w1-extrapolation theta trapezoidal implicit-euler rkc`` or a scipy name
        (``RK23 RK45 DOP853 Radau BDF LSODA``, run by ``scipy.integrate.solve_ivp``).
    h : float, s
        Fixed step (spec §9.1); with ``adaptive=True`` only the first step.
    rtol, atol : tolerances of the error control (used when adaptive).
    events : callable(s) ``e(t, y)`` with optional ``.direction``/``.terminal`` attributes, or
        ``(indicators, direction, terminal)``.
    jac, jac_sparsity : analytic Jacobian or its sparsity pattern (implicit/W methods).
    t_eval : times to report (dense output); default every step.
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
    if method in SCIPY_METHODS:
        from cvtfem.integrate.scipy_bridge import solve_scipy
        if switch is not None:
            raise InputError("switch", switch, f"is not supported by scipy method {method!r}",
                             "solve_ivp cannot change a discrete state; use a native method")
        for key, val, default in (("adaptive", adaptive, None),
                                  ("event_location", event_location, "dense"),
                                  ("event_samples", event_samples, EVENT_SAMPLES),
                                  ("growth_limit", growth_limit, GROWTH_LIMIT),
                                  ("error_check", error_check, 0)):
            if val != default:
                warnings.warn(f"option `{key}` is ignored by scipy method {method!r}",
                              IgnoredOptionWarning, stacklevel=2)
        return solve_scipy(fun, (t0, tf), y0, method, h, rtol, atol, events, jac, jac_sparsity,
                           t_eval, options)
    if method in UNAVAILABLE:
        raise InputError("method", method, "is not available in this build", UNAVAILABLE[method])
    if method not in METHODS:
        raise InputError("method", method, f"must be one of {sorted(METHODS) + sorted(SCIPY_METHODS)}")
    system = as_system(fun, y0, n2=n2, jac=jac, jac_sparsity=jac_sparsity, events=events, switch=switch)
    cls = METHODS[method]
    stats = Stats()
    stepper = cls(system, stats, **_check_options(method, cls.OPTIONS, options))
    if adaptive is None:
        adaptive = h is None
    stepper.need_error = adaptive
    stepper.tolerances = (rtol, atol) if adaptive else None
    if adaptive and stepper.error_order is None:
        raise InputError("method", method, "has no error estimate, so it needs a fixed step `h`")
    if not adaptive and h is None:
        raise InputError("h", h, "must be given for a fixed-step run")
    ctrl = SimpleController(quantum=getattr(stepper, "STEP_QUANTUM", 1.0)) if adaptive else FixedStep(h)
    if adaptive and h is None:
        h = _initial_step(stepper, t0, y0, rtol, atol, tf - t0)
    if growth_limit is not None and not growth_limit > 1:
        raise InputError("growth_limit", growth_limit, "must be a number > 1 or None")
    if not (isinstance(error_check, (int, np.integer)) and error_check >= 0):
        raise InputError("error_check", error_check, "must be a whole number of steps >= 0 (0: off)")
    guard = GrowthGuard(growth_limit, y0, atol, method, adaptive)
    monitor = ErrorMonitor(stepper, rtol, atol, 0 if adaptive else error_check)
    return _integrate(stepper, ctrl, system, t0, tf, y0, h, rtol, atol, t_eval, event_location,
                      max_steps, max_events, raise_on_failure, stats, method, adaptive, guard,
                      event_samples, monitor)


def _initial_step(stepper, t0, y0, rtol, atol, span):
    """Hairer's starting step guess, one extra RHS call (as scipy's ``select_initial_step``)."""
    f0 = stepper.f(t0, y0)
    scale = atol + rtol * np.abs(y0)
    d0, d1 = np.sqrt(np.mean(np.abs(y0 / scale) ** 2)), np.sqrt(np.mean(np.abs(f0 / scale) ** 2))
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, span)
    f1 = stepper.f(t0 + h0, y0 + h0 * f0)
    d2 = np.sqrt(np.mean(np.abs((f1 - f0) / scale) ** 2)) / h0
    q = stepper.error_order or stepper.order
    h1 = max(1e-6, h0 * 1e-3) if max(d1, d2) <= 1e-15 else (0.01 / max(d1, d2)) ** (1 / (q + 1))
    return min(100 * h0, h1, span)


def _integrate(stepper, ctrl, system, t0, tf, y0, h, rtol, atol, t_eval, event_location,
               max_steps, max_events, raise_on_failure, stats, method, adaptive, guard,
               event_samples=EVENT_SAMPLES, monitor=None):
    wall = time.perf_counter()
    st = stats.counts
    t, x = t0, y0.copy()
    ts, ys = ([t0], [x.copy()]) if t_eval is None else ([], [])
    i_eval = 0
    locator = EventLocator(system, stats, event_location, event_samples) if system.n_events else None
    if locator is not None:
        locator.start(t, x)
    t_events = [[] for _ in range(system.n_events)]
    y_events = [[] for _ in range(system.n_events)]
    status, message = 0, MESSAGES[0]
    h_min = 16 * np.finfo(float).eps * max(abs(t0), abs(tf))
    last_event, zeno = -np.inf, 0
    while t < tf:
        if st["nsteps"] >= max_steps:
            status, message = -1, f"`max_steps` = {max_steps} reached at t = {t:.6g} s"
            break
        h_try = min(h, tf - t, stepper.max_step()) if adaptive else min(h, tf - t)
        if tf - (t + h_try) < 1e-9 * h_try:
            h_try = tf - t
        if monitor is not None:
            monitor.before()
        try:
            with np.errstate(over="ignore", invalid="ignore"):   # detected below, reported
                att = stepper.attempt(t, x, h_try)
            failure = None if np.all(np.isfinite(att.x1)) else "non-finite state"
            if failure is None and not adaptive:
                failure = guard.check(x, att.x1, h_try, att.f0)
        except StepFailure as err:
            att, failure = None, str(err)
        if adaptive:
            if failure is not None:
                accept, h_new = False, 0.25 * h_try
            else:
                en = error_norm(att.err, x, att.x1, rtol, atol)
                accept, h_new = ctrl.propose(h_try, en, stepper.error_order)
                blow_up = guard.check(x, att.x1, h_try, att.f0) if accept else None
                if blow_up is not None:
                    status = -1
                    message = f"{blow_up} at t = {t + h_try:.6g} s with adaptive step h = {h_try:.3g} s{guard.hint()}"
                    break
            if not accept:
                st["nreject"] += 1
                h = h_new
                if h < h_min:
                    status = -1
                    message = f"step size underflow (h = {h:.3g} s) at t = {t:.6g} s" + (
                        f": {failure}" if failure else "")
                    break
                continue
        else:
            h_new = h
            if failure is not None:
                nonfin = [] if att is None else np.flatnonzero(~np.isfinite(att.x1))
                bad = f" in component {int(nonfin[0])}" if len(nonfin) else ""
                status, message = -1, f"{failure}{bad} at t = {t + h_try:.6g} s with fixed step h = {h:.3g} s"
                if failure.startswith("instability"):
                    message += guard.hint()
                break
        st["nsteps"] += 1
        t1, x1 = t + h_try, att.x1
        f1 = None

        def dense(tq, att=att):
            nonlocal f1
            if f1 is None:
                if att.f1 is None:        # kept: accept() caches it as the next step's F0
                    att.f1 = stepper.f(att.t0 + att.h, att.x1)
                f1 = att.f1
            if att.f0 is None:
                att.f0 = stepper.f(att.t0, att.x0)
            return hermite(att, f1, tq)

        hit = None if locator is None else locator.locate(t, x, t1, x1, dense)
        if hit is not None:
            t1, x1, fired, _ = hit
            st["nevents"] += 1
            st["ntruncated"] += 1
        stepper.accept(att)
        if monitor is not None:
            monitor.after(att)
        if t_eval is not None:
            j = i_eval + np.searchsorted(t_eval[i_eval:], t1, side="right")
            if j > i_eval:
                ts.extend(t_eval[i_eval:j])
                ys.extend(dense(t_eval[i_eval:j]).T)
                i_eval = j
        else:
            ts.append(t1)
            ys.append(x1.copy())
        t, x, h = t1, x1, h_new
        guard.update(x)
        if hit is not None:
            for k in np.flatnonzero(fired):
                t_events[k].append(t)
                y_events[k].append(x.copy())
            if system.switch is not None:
                new = system.switch(t, x.copy(), fired)
                if new is not None:
                    x = np.array(new, dtype=x.dtype)
                    guard.update(x)
            stepper.reset()
            if monitor is not None:
                monitor.reset()
            locator.start(t, x, fired)
            if np.any(fired & system.event_terminal):
                status, message = 1, MESSAGES[1]
                break
            gap = max(ZENO_GAP * (tf - t0), ZENO_GAP_H * h_try)
            zeno = zeno + 1 if t - last_event < gap else 0
            last_event = t
            if zeno >= ZENO_COUNT:
                status, message = -1, (f"{ZENO_COUNT + 1} events less than {gap:.3g} s apart "
                                       f"accumulate at t = {t:.12g} s (Zeno behaviour)")
                break
            if st["nevents"] >= max_events:
                status, message = -1, f"`max_events` = {max_events} reached at t = {t:.6g} s (Zeno?)"
                break
    stats.times["t_total"] = time.perf_counter() - wall
    extra = {}
    if monitor is not None and monitor.active:
        extra = monitor.stats()
        warn = monitor.warning()
        if warn is not None and status >= 0:
            message += f" Warning: {warn}."
            log.warning("%s: %s", method, warn)
    if status < 0:
        log.warning("%s: %s", method, message)
        if raise_on_failure:
            raise NumericalError(message, t=t, component=method)
    y = np.array(ys).T if ys else np.empty((len(y0), 0))
    return OdeResult(np.array(ts), y, {**stats.as_dict(), **extra}, status, message,
                     [np.array(v) for v in t_events], [np.array(v) for v in y_events], method)
