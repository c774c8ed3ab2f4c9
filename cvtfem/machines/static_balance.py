"""Newton solve of a quasi-static balance ``r(y) = 0`` whose Jacobian is sparse, indefinite and singular, as the
chains' with independent pin halves (A5) and per-plate links (A3/A4) on the sheaves are: :func:`lifted_newton`."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: Phase 1: iteration limit.  Phase 2: floors of the lift (fractions of the largest diagonal entry of the Jacobian),
#: step lengths tried along each lifted Newton step, iteration limit.
DAMPED_ITERATIONS = 60
LIFTS = (1e-9, 1e-7, 1e-5, 1e-4)
STEPS = (1.0, 0.5, 0.25, 0.1, 0.03, 0.01)
NEWTON_ITERATIONS = 150
#: A step below this (m, rad) ends the iteration (the round-off of the coordinates).
SMALLEST_STEP = 1e-13
#: A full lifted Newton step that lowers ``|r|`` to this fraction is taken without trying the others.
ACCEPT = 0.5


def lifted_newton(residual, jacobian, y0, tol: float, damped: int = DAMPED_ITERATIONS, lifts=LIFTS,
                  steps=STEPS, iterations: int = NEWTON_ITERATIONS) -> SimpleNamespace:
    """Solve ``residual(y) = 0`` from ``y0`` with ``jacobian(y)`` (dense or sparse ``dr/dy``) in two phases.

    1. Damped steps ``-(J - mu S)^-1 r`` (scipy ``splu``), ``S`` the Jacobian's diagonal magnitudes floored at 1e-9
       of the largest, ``mu`` divided by 10 after a step that lowers ``|r|`` and multiplied by 10 (from the same
       point) otherwise, until no ``mu`` lowers ``|r|``.  Robust far from the balance; with an indefinite ``J`` (a
       balance that is a saddle of the energy) the shifted step is no descent direction of ``|r|^2`` and this
       phase stalls (A5: at about 2e-2 of F2).  At most ``damped`` iterations (0: none).
    2. Newton steps ``-(J - L)^-1 r`` whose shift ``L = diag(max(f max|J_ii| - |J_ii|, 0))`` lifts only the
       coordinates without stiffness of their own (a singular ``J``: A5's axial positions of the halves on the
       spans, which no force fixes, so ``r`` has no part along them); elsewhere the step is Newton's and so a
       descent direction of ``|r|^2`` however indefinite ``J`` is.  Each iteration takes the first full step
       (floors ``f`` in ``lifts``, default :data:`LIFTS`, in turn) that lowers ``|r|`` to :data:`ACCEPT` of it, else
       the best by ``|r|`` of the floors and step lengths ``steps`` (:data:`STEPS`), while that lowers ``|r|`` (a
       Levenberg-Marquardt step ``-(J^T J + m D)^-1 J^T r`` where none does only crawled: A5 2.46e-5 of F2 after 3906
       evaluations against 2.34e-5 after 1623 without it).  At most ``iterations`` iterations.

    Ends when ``max |r| < 1e-3 tol`` or a step is below :data:`SMALLEST_STEP`; returns ``x``,
    ``nfev``, ``status`` (1 converged, 0 not) and ``message``."""
    y, r = np.asarray(y0, float).copy(), residual(y0)
    nfev, mu = 1, 1e-6

    def done(dy):
        return np.abs(r).max() < 1e-3 * tol or np.abs(dy).max() < SMALLEST_STEP

    for _ in range(damped):
        J = sp.csc_matrix(jacobian(y))
        S = sp.diags(np.maximum(np.abs(J.diagonal()), 1e-9 * np.abs(J.diagonal()).max()))
        while mu < 1e8:
            dy = _solve(J - mu * S, -r)
            r_new = residual(y + dy) if dy is not None else r
            nfev += dy is not None
            if np.linalg.norm(r_new) < np.linalg.norm(r):
                y, r, mu = y + dy, r_new, max(mu / 10, 1e-12)
                break
            mu *= 10
        else:
            break
        if done(dy):
            return SimpleNamespace(x=y, nfev=nfev, status=1, message="converged")
    message = "the iteration limit was reached"
    for _ in range(iterations):
        dy, r_new, n = _lifted_step(residual, sp.csc_matrix(jacobian(y)), y, r, lifts, steps)
        nfev += n
        if dy is None:
            message = "no step lowered the residual"
            break
        y, r = y + dy, r_new
        if done(dy):
            return SimpleNamespace(x=y, nfev=nfev, status=1, message="converged")
    return SimpleNamespace(x=y, nfev=nfev, status=0, message=message)


def _lifted_step(residual, J, y, r, lifts, steps):
    """Phase 2's step from ``y`` (residual ``r``, Jacobian ``J``): the first full lifted Newton step that lowers
    ``|r|`` by :data:`ACCEPT` at least, else the best by ``|r|`` of all floors and step lengths; ``(dy, r(y + dy),
    evaluations)``, ``dy`` None where none lowers ``|r|``."""
    d = np.abs(J.diagonal())
    r0 = np.linalg.norm(r)
    best, nfev = (r0, None, None), 0
    for f in lifts:
        dy = _solve(J - sp.diags(np.maximum(f * d.max() - d, 0.0)), -r)
        for a in steps if dy is not None else ():
            r_new = residual(y + a * dy)
            nfev += 1
            if np.linalg.norm(r_new) < best[0]:
                best = (np.linalg.norm(r_new), a * dy, r_new)
            if a == 1.0 and best[0] < ACCEPT * r0:
                return best[1], best[2], nfev
    return best[1], best[2], nfev


def _solve(A, b):
    """``A^-1 b`` by scipy's sparse LU, or None where ``A`` is exactly singular."""
    try:
        return spla.splu(sp.csc_matrix(A)).solve(b)
    except RuntimeError:
        return None
