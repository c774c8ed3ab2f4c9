"""Run scipy's ``solve_ivp`` methods through :func:`cvtfem.integrate.solve` (spec §11.2).

The result has the same type and ``stats`` keys as native runs; ``nfev`` is counted by a
wrapper (scipy's own count excludes nothing it calls through ``fun``), ``njev``/``nlu`` come
from scipy; ``nsolve``, ``nnewton``, ``nreject`` and ``nfev_jac`` (its Jacobian RHS calls
are inside ``nfev``) are not reported by scipy and are -1.
"""
from __future__ import annotations

import time
import warnings

from scipy.integrate import solve_ivp

from cvtfem.integrate.stats import Stats

__all__ = ["solve_scipy"]

SCIPY_OPTIONS = {"RK23": set(), "RK45": set(), "DOP853": set(), "LSODA": {"jac"},
                 "Radau": {"jac", "jac_sparsity"}, "BDF": {"jac", "jac_sparsity"}}


def solve_scipy(fun, t_span, y0, method, h, rtol, atol, events, jac, jac_sparsity, t_eval, options):
    """Call ``solve_ivp``; ``h`` becomes ``first_step``. Returns an ``OdeResult``."""
    from cvtfem.integrate.driver import IgnoredOptionWarning, OdeResult

    for name, value in (("jac", jac), ("jac_sparsity", jac_sparsity)):
        if value is not None and name not in SCIPY_OPTIONS[method]:
            warnings.warn(f"option `{name}` is ignored by scipy method {method!r}",
                          IgnoredOptionWarning, stacklevel=3)
    stats = Stats()

    def counted(t, y):
        stats.counts["nfev"] += 1
        return fun(t, y)

    kw = dict(options)
    if h is not None:
        kw["first_step"] = h
    if "jac" in SCIPY_OPTIONS[method]:
        if jac is not None:
            kw["jac"] = jac
        if jac_sparsity is not None:
            kw["jac_sparsity"] = jac_sparsity
    if isinstance(events, tuple) and len(events) == 3 and not callable(events[1]):
        events = _split_events(*events)
    wall = time.perf_counter()
    sol = solve_ivp(counted, t_span, y0, method=method, t_eval=t_eval, events=events, rtol=rtol,
                    atol=atol, **kw)
    stats.times["t_total"] = time.perf_counter() - wall
    c = stats.counts
    c["njev"], c["nlu"] = int(sol.njev), int(sol.nlu)
    c["nsteps"] = len(sol.t) - 1 if t_eval is None else -1
    for key in ("nsolve", "nnewton", "nreject", "nfev_jac"):
        c[key] = -1
    t_ev = sol.t_events if sol.t_events is not None else []
    y_ev = sol.y_events if sol.y_events is not None else []
    c["nevents"] = int(sum(len(v) for v in t_ev))
    return OdeResult(sol.t, sol.y, stats.as_dict(), int(sol.status), sol.message, list(t_ev),
                     list(y_ev), method)


def _split_events(indicators, direction, terminal):
    """One ``solve_ivp`` event callable per component of a vector indicator function."""
    out = []
    for k in range(len(direction)):
        def ev(t, y, k=k):
            return indicators(t, y)[k]
        ev.direction, ev.terminal = float(direction[k]), bool(terminal[k])
        out.append(ev)
    return out
