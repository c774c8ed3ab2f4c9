"""Newton-type solvers for ``G(y) = 0`` (spec §4.3, eqs. (2.19)-(2.23), §11.5).

``x_{k+1} = x_k + alpha_k d_k`` with ``B_k d_k = -G(x_k)``. Descent-direction variants:
``exact`` (fresh Jacobian each iteration), ``const`` (chord: frozen ``B``), ``broyden``
(dense rank-1 update (2.20)), ``fake-broyden`` (the update restricted to ``B``'s sparsity
pattern), ``hart`` (secant update of the LU factors on their patterns, no refactorisation;
:mod:`cvtfem.integrate.luupdate`), ``trim`` (frozen ``B`` with entries below
``trim_threshold * max|B|`` dropped).
Line search (2.21)-(2.22) with the ratio new/old (errata #20): the first ``alpha = 2^-i``,
``i = 0..9``, with ratio <= 0.8, else the minimiser; all ratios >= 1 means divergence.
Stopping (2.23): ``||G|| < eps_abs`` and ``||dx|| < eps_rel ||x|| + eps_abs`` (inf-norms).
Divergence or ``max_iter`` iterations refresh the Jacobian; a failure right after a refresh
raises :class:`~cvtfem.integrate.base.StepFailure`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from cvtfem.errors import InputError
from cvtfem.integrate.base import StepFailure
from cvtfem.integrate.linsolve import LU
from cvtfem.integrate.luupdate import UpdatedLU

__all__ = ["NewtonOptions", "NewtonSolver", "VARIANTS"]

VARIANTS = ("exact", "const", "broyden", "fake-broyden", "hart", "trim")
ETA_ACCEPT = 0.8
N_ALPHA = 10


@dataclass(frozen=True)
class NewtonOptions:
    """Newton settings: ``variant``, tolerances of (2.23), iteration cap, trimming threshold."""

    variant: str = "const"
    eps_abs: float = 1e-10
    eps_rel: float = 1e-8
    max_iter: int = 12
    trim_threshold: float = 1e-3

    def __post_init__(self) -> None:
        if self.variant not in VARIANTS:
            raise InputError("newton", self.variant, f"must be one of {VARIANTS}")
        if not (self.eps_abs > 0 and self.eps_rel >= 0):
            raise InputError("newton_tol", (self.eps_abs, self.eps_rel), "must be positive")


class NewtonSolver:
    """Keeps the iteration matrix ``B`` (and its LU) across solves, per the variant's lifecycle."""

    def __init__(self, stats, options: NewtonOptions) -> None:
        self.stats, self.opt = stats, options
        self.B = None
        self._lu = None

    def invalidate(self) -> None:
        """Drop ``B`` (the step size changed, so the frozen matrix is rebuilt next solve)."""
        self.B, self._lu = None, None

    def _set(self, B) -> None:
        st = self.stats
        if self.opt.variant == "broyden":
            self.B = B.toarray() if sp.issparse(B) else np.array(B)
            st.counts["nlu"] += 1
            with st.timer("t_lu"):
                self._lu = sla.lu_factor(self.B, check_finite=False)
            return
        if self.opt.variant == "trim":
            B = _trim(B, self.opt.trim_threshold)
        self.B = B
        self._lu = UpdatedLU(st, B) if self.opt.variant == "hart" else LU(st, B)

    def _direction(self, g):
        if self.opt.variant == "broyden":
            self.stats.counts["nsolve"] += 1
            with self.stats.timer("t_solve"):
                return -sla.lu_solve(self._lu, g, check_finite=False)
        return -self._lu.solve_y(g)

    def _update(self, s, dg) -> None:
        ss = float(np.vdot(s, s).real)
        if ss == 0.0:
            return
        if self.opt.variant == "hart":   # update the factors, no refactorisation
            self._lu.update(s, dg)
        elif self.opt.variant == "broyden":
            self.B = self.B + np.outer(dg - self.B @ s, s) / ss
            self._set(self.B)
        elif sp.issparse(self.B):  # fake-broyden: the update restricted to B's pattern
            B = self.B.tocoo()
            r = dg - B @ s
            B.data = B.data + r[B.row] * s[B.col] / ss
            self._set(B.tocsc())
        else:
            r = dg - self.B @ s
            self._set(self.B + (self.B != 0) * np.outer(r, s) / ss)

    def solve(self, residual, y, make_matrix, eps_abs=None):
        """Solve ``residual(y) = 0`` from the guess ``y``; returns ``(y, residual(y))``.

        ``make_matrix(y, fresh)`` returns ``dG/dy`` (``fresh``: from a new Jacobian at ``y``);
        ``eps_abs`` (scalar or per component) overrides the option, e.g. to tie the residual
        to the local-error tolerance of an adaptive run.
        """
        opt, st = self.opt, self.stats
        eps = opt.eps_abs if eps_abs is None else eps_abs
        g = residual(y)
        fresh = opt.variant == "exact"
        if self.B is None or fresh:
            self._set(make_matrix(y, fresh))
        refreshed, since = fresh, 0
        total = 0
        while True:
            total += 1
            if total > 4 * opt.max_iter:
                break
            d = self._direction(g)
            st.counts["nnewton"] += 1
            if (np.all(np.abs(g) < eps) and
                    np.all(np.abs(d) <= opt.eps_rel * np.max(np.abs(y)) + eps)):
                y = y + d  # already converged: the full step is below round-off of (2.23)
                return y, residual(y)
            ok, alpha, y_new, g_new = self._line_search(residual, y, g, d)
            since += 1
            if not ok or since > opt.max_iter:
                if refreshed:
                    break
                st.counts["njac_refresh"] += 1
                self._set(make_matrix(y, True))
                refreshed, since = True, 0
                continue
            s = y_new - y
            converged = (np.all(np.abs(g_new) < eps) and
                         np.all(np.abs(s) <= opt.eps_rel * np.max(np.abs(y_new)) + eps))
            if opt.variant in ("broyden", "fake-broyden", "hart") and not converged:
                self._update(alpha * d, g_new - g)
            y, g = y_new, g_new
            if converged:
                return y, g
            if opt.variant == "exact":
                self._set(make_matrix(y, True))
            refreshed = refreshed and opt.variant == "exact"
        st.counts["nnewton_fail"] += 1
        self.invalidate()
        raise StepFailure(f"Newton ({opt.variant}) diverged: |G| = {np.max(np.abs(g)):.3g}")

    def _line_search(self, residual, y, g, d):
        n0 = float(np.vdot(g, g).real)
        if n0 == 0.0:
            return True, 1.0, y + d, residual(y + d)
        best = (np.inf, None, None, None)
        alpha = 1.0
        for _ in range(N_ALPHA):
            y_a = y + alpha * d
            g_a = residual(y_a)
            eta = float(np.vdot(g_a, g_a).real) / n0 if np.all(np.isfinite(g_a)) else np.inf
            if eta <= ETA_ACCEPT:
                return True, alpha, y_a, g_a
            if eta < best[0]:
                best = (eta, alpha, y_a, g_a)
            alpha *= 0.5
        if best[0] >= 1.0:
            return False, 0.0, y, g
        return True, best[1], best[2], best[3]


def _trim(B, threshold: float):
    """Drop off-diagonal entries below ``threshold * max|B|`` (the ``trim`` variant)."""
    if not sp.issparse(B):
        small = np.abs(B) < threshold * np.abs(B).max()
        np.fill_diagonal(small, False)
        return np.where(small, 0.0, B)
    B = sp.coo_matrix(B)
    keep = (np.abs(B.data) >= threshold * np.abs(B.data).max()) | (B.row == B.col)
    return sp.csc_matrix((B.data[keep], (B.row[keep], B.col[keep])), shape=B.shape)
