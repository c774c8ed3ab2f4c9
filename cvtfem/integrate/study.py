"""Study tools (spec §3.3, §9.4, §9.6): stability regions, effective order, work-precision.

Everything here runs the real steppers: a stability region is one step of ``h = 1`` on
``x' = diag(z) x`` for a whole grid of complex ``z`` at once (brute force, spec §3.3, valid
for extrapolated, W- and stabilized methods too); local errors are single steps compared
with a reference.
"""
from __future__ import annotations

import statistics
import time

import numpy as np
import scipy.sparse as sp

from cvtfem.integrate.driver import solve
from cvtfem.integrate.methods import SCIPY_METHODS

__all__ = ["amplification", "real_stability_length", "local_errors", "effective_order",
           "work_precision", "signed_log", "signed_log_inverse"]


def amplification(method: str, z: np.ndarray, **options) -> np.ndarray:
    """``|R(z)|``: one step ``h = 1`` of ``method`` on ``x' = z x``, all ``z`` at once.

    The Jacobian ``diag(z)`` is given analytically, so implicit and W-methods use it exactly.
    """
    z = np.asarray(z, dtype=complex)
    shape = z.shape
    zf = z.ravel()
    zf = np.where(zf.imag == 0, zf + 1e-13j, zf)   # never exactly on a real pole of R
    D = sp.diags(zf, format="csr")
    if method not in SCIPY_METHODS:
        options = {"growth_limit": None, **options}   # |R| far above 1 is what is measured here
    with np.errstate(all="ignore"):
        res = solve(lambda t, x: zf * x, (0.0, 1.0), np.ones_like(zf), method=method, h=1.0,
                    jac=lambda t, x: D, **options)
        out = np.abs(res.y[:, -1]) if res.success else np.full(zf.shape, np.inf)
    return np.where(np.isfinite(out), out, np.inf).reshape(shape)


def real_stability_length(method: str, x_max: float = 1e5, n: int = 200_000, **options) -> float:
    """Largest ``beta`` with ``|R(-x)| <= 1`` on all of ``[0, beta]`` (sampled, then bisected)."""
    x = np.linspace(0.0, x_max, n)
    r = amplification(method, -x, **options)
    bad = np.flatnonzero(r > 1 + 1e-12)
    if not len(bad):
        return x_max
    lo, hi = x[bad[0] - 1], x[bad[0]]
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if amplification(method, np.array([-mid]), **options)[0] <= 1 + 1e-12:
            lo = mid
        else:
            hi = mid
    return lo


def local_errors(problem, method: str, hs, reference=None, **options) -> np.ndarray:
    """Local error ``e(h) = ||x(t0 + h) - x1||_inf`` of one step from the problem's start.

    ``reference(h)`` gives the true ``x(t0 + h)``: the problem's closed form by default,
    else DOP853 at ``rtol = 1e-13``.
    """
    t0 = problem.t_span[0]
    if reference is None:
        if problem.exact is not None:
            reference = problem.exact
        else:
            def reference(t):
                return solve(problem.fun, (t0, t), problem.y0, "DOP853", rtol=1e-13,
                             atol=1e-15).y[:, -1]
    kw = problem.solve_kwargs()
    errs = []
    for h in hs:
        kw["t_span"] = (t0, t0 + h)
        res = solve(**kw, method=method, h=h, **options)
        errs.append(np.max(np.abs(res.y[:, -1] - reference(t0 + h))))
    return np.array(errs)


def effective_order(hs, errs) -> np.ndarray:
    """``p~ = d ln e / d ln h - 1`` (spec (2.8)) by finite differences between samples."""
    hs, errs = np.asarray(hs, float), np.asarray(errs, float)
    le = np.log(np.where(errs > 0, errs, np.nan))   # round-off zeros carry no order
    return np.diff(le) / np.diff(np.log(hs)) - 1


def work_precision(problem, runs, repeats: int = 3, error=None):
    """Error vs cost for a list of runs ``(label, method, options)`` on ``problem``.

    ``error(res)`` defaults to the max relative error at ``t_end`` against
    ``problem.reference()`` (the components in ``ref_index``). Wall time is the median of
    ``repeats`` runs. Returns a list of row dicts (label, method, error, nfev, time, ...).
    """
    ref = problem.reference()
    idx = problem.ref_index if problem.ref_index is not None else slice(None)
    if error is None:
        def error(res):
            return float(np.max(np.abs(res.y[idx, -1] - ref) / np.maximum(np.abs(ref), 1e-300)))
    rows = []
    for label, method, options in runs:
        times, res = [], None
        for _ in range(repeats):
            t0 = time.perf_counter()
            res = solve(**problem.solve_kwargs(), method=method, **options)
            times.append(time.perf_counter() - t0)
        st = res.stats
        rows.append({"label": label, "method": method, "error": error(res) if res.success else np.inf,
                     "nfev": st["nfev"], "nfev_jac": st["nfev_jac"], "njev": st["njev"], "nlu": st["nlu"], "nsolve": st["nsolve"],
                     "nsteps": st["nsteps"],
                     "time": statistics.median(times), "status": res.status,
                     **{k: v for k, v in options.items() if isinstance(v, (int, float, str))}})
    return rows


def signed_log(x, x_star: float = 1e-3, xt_star: float = 1.0, c: float | None = None):
    """The source's signed "logarithmic" axis map (spec §2.3): linear for ``|x| <= x*``."""
    c = xt_star if c is None else c
    x = np.asarray(x, dtype=float)
    ax = np.abs(x)
    with np.errstate(divide="ignore"):
        out = np.where(ax <= x_star, xt_star * x / x_star,
                       np.sign(x) * (xt_star + c * np.log(np.maximum(ax, x_star) / x_star)))
    return out


def signed_log_inverse(xt, x_star: float = 1e-3, xt_star: float = 1.0, c: float | None = None):
    """Inverse of :func:`signed_log` (for rasterising on a log-mapped grid)."""
    c = xt_star if c is None else c
    xt = np.asarray(xt, dtype=float)
    a = np.abs(xt)
    return np.where(a <= xt_star, x_star * xt / xt_star,
                    np.sign(xt) * x_star * np.exp((a - xt_star) / c))


def cheapest_meeting(problem, label: str, method: str, settings, target: float, repeats: int = 3,
                     error=None):
    """Run ``settings`` (cheapest first) until the error is ``<= target``; that run's row.

    Returns the row of the first setting meeting the target (``met = True``) or of the last
    one tried (``met = False``); the wall time is the median of ``repeats`` runs.
    """
    row = None
    for options in settings:
        (row,) = work_precision(problem, [(label, method, options)], repeats=1, error=error)
        if row["error"] <= target:
            if repeats > 1:
                (row,) = work_precision(problem, [(label, method, options)], repeats, error)
            row["met"] = True
            return row
    row["met"] = False
    return row


def heat_benchmark(N: int = 1000, t_end: float = 0.1, target: float = 1e-4, repeats: int = 3,
                   methods=None):
    """The issue-4 benchmark: 1-D heat equation, each method at relative error ``<= target``.

    Implicit methods get only ``jac_sparsity`` (coloured finite differences, also for scipy).
    RK4 runs at 98 % of its real stability limit ``2.785/rho``. Returns rows (see
    :func:`work_precision`) with ``met`` flags.
    """
    from cvtfem.problems import heat1d

    p = heat1d(N, t_end)
    sparse = type(p)(**{**p.__dict__, "jac": None})
    rho = p.info["rho"]

    def error(res):
        ref = p.reference()
        return float(np.max(np.abs(res.y[:, -1] - ref)) / np.max(np.abs(ref)))

    rtols = [3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5]
    last = np.array([t_end])   # keep only the final state (RK4 takes ~1.5e5 steps)
    tol = [{"rtol": r, "atol": r * 1e-3, "t_eval": last} for r in rtols]
    plan = {
        "rk4": [{"h": t_end / np.ceil(t_end / (0.98 * 2.785 / rho)), "t_eval": last}],
        "dopri45": tol, "dumka3": tol, "rock2": tol, "rock4": tol, "rkc": tol,
        "trapezoidal": [{"h": t_end / n, "t_eval": last} for n in (10, 20, 40, 80, 160)],
        "Radau": tol, "BDF": tol,
    }
    rows = []
    for method in methods or plan:
        label = f"{method} (sparse)" if method == "trapezoidal" else method
        rows.append(cheapest_meeting(sparse, label, method, plan[method], target, repeats, error))
    return rows


def max_stable_step(method: str, eigenvalues, h_hi: float, iters: int = 40, **options) -> float:
    """Largest ``h`` with ``|R(h lambda_i)| <= 1`` for all given eigenvalues (bisection, §9.3).

    ``h_hi`` must be an unstable step (upper bracket); stability is tested by stepping.
    """
    lam = np.asarray(eigenvalues, dtype=complex)

    def stable(h):
        return bool(np.all(amplification(method, h * lam, **options) <= 1 + 1e-12))

    lo, hi = 0.0, float(h_hi)
    if stable(hi):
        return hi
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def select_stages(method: str, eigenvalues, candidates, h_hi: float, iters: int = 40, **options):
    """Stage count minimising stages per unit time ``s / h_max(s)`` over a spectrum (§11.6).

    Returns ``(s_best, {s: h_max})``; the spectral radius alone would pick the ``s`` whose
    real interval just covers ``rho h``, which over-selects when imaginary eigenvalues limit.
    """
    hmax = {s: max_stable_step(method, eigenvalues, h_hi, iters, stages=s, **options) for s in candidates}
    best = min(hmax, key=lambda s: s / hmax[s] if hmax[s] > 0 else np.inf)
    return best, hmax
