"""Newton-type solvers for ``G(y) = 0`` (spec §4.3, eqs. (2.19)-(2.23), §11.5).

``x_{k+1} = x_k + alpha_k d_k`` with ``B_k d_k = -G(x_k)``. Descent-direction variants:
``exact`` (fresh Jacobian each iteration), ``const`` (chord: frozen ``B``), ``broyden``
(dense rank-1 update (2.20)), ``fake-broyden`` (the update restricted to ``B``'s sparsity
pattern), ``hart`` (secant update of the LU factors on their patterns, no refactorisation;
:mod:`cvtfem.integrate.luupdate`), ``trim`` (frozen ``B`` with entries below
``trim_threshold * max|B|`` dropped).
Line search (2.21)-(2.22) with the ratio new/old (errata #20): the first ``alpha = 2^-i``,
``i = 0..9``, with ratio <= 0.8, else the minimiser; all ratios >= 1 means divergence.
Stopping (2.23): ``||G|| < eps_abs`` and ``||dx|| < eps_rel ||x|| + eps_abs`` (inf-norms;
``eps_abs`` is relative to ``max(1, |x_i|)`` per component, so the test stays above round-off).
Divergence or ``max_iter`` iterations refresh the Jacobian; a failure right after a refresh
raises :class:`~cvtfem.integrate.base.StepFailure`. This is ``stop="source"`` (the default
``"auto"`` uses it when no error-norm scales are given: fixed-step runs).

``stop="rate"`` (``"auto"`` with scales: adaptive runs; Hairer-Wanner IV.8, as Radau5): no line search;
the contraction rate ``theta_k = ||d_k|| / ||d_{k-1}||`` is measured in the weighted RMS norm of
the local error (``scale = atol + rtol |y|``); converged when ``theta/(1-theta) ||d_k|| <= kappa``
(the first iteration uses the previous solve's rate); divergence when ``theta >= 1`` or when the
remaining iterations cannot reach ``kappa`` at the observed rate. A failure with a Jacobian of an
earlier step refreshes it and restarts from the guess; a solve that needed more than two
iterations at a rate above ``RATE_REFRESH`` marks the Jacobian stale for the next solve.
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
STOPS = ("auto", "rate", "source")   # auto: rate when error-norm scales are given
RATE_REFRESH = 0.3    # stop="rate": slower contraction than this (after > 2 iterations) -> new Jacobian
EPS = np.finfo(float).eps


@dataclass(frozen=True)
class NewtonOptions:
    """Newton settings: ``variant``, tolerances of (2.23), iteration cap, trimming threshold."""

    variant: str = "const"
    eps_abs: float = 1e-10
    eps_rel: float = 1e-8
    max_iter: int = 12
    trim_threshold: float = 1e-3
    stop: str = "auto"

    def __post_init__(self) -> None:
        if self.variant not in VARIANTS:
            raise InputError("newton", self.variant, f"must be one of {VARIANTS}")
        if self.stop not in STOPS:
            raise InputError("newton_stop", self.stop, f"must be one of {STOPS}")
        if not (self.eps_abs > 0 and self.eps_rel >= 0):
            raise InputError("newton_tol", (self.eps_abs, self.eps_rel), "must be positive")


class NewtonSolver:
    """Keeps the iteration matrix ``B`` (and its LU) across solves, per the variant's lifecycle."""

    def __init__(self, stats, options: NewtonOptions) -> None:
        self.stats, self.opt = stats, options
        self.B = None
        self._lu = None
        self.stale = False   # the matrix B comes from a Jacobian of an earlier solve
        self._fresh = False  # B comes from a Jacobian of the current solve
        self._eta = 1.0      # stop="rate": theta/(1-theta) of the previous solve

    def invalidate(self) -> None:
        """Drop ``B`` (the step size changed, so the frozen matrix is rebuilt next solve)."""
        self.B, self._lu, self._fresh = None, None, False

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

    def solve(self, residual, y, make_matrix, eps_abs=None, scale=None, kappa=0.03):
        """Solve ``residual(y) = 0`` from the guess ``y``; returns ``(y, residual(y))``.

        ``make_matrix(y, fresh)`` returns ``dG/dy`` (``fresh``: from a new Jacobian at ``y``);
        ``eps_abs`` (scalar or per component) overrides the option, e.g. to tie the residual
        to the local-error tolerance of an adaptive run. ``stop="rate"`` needs ``scale``
        (per component, units of ``y``) and uses ``kappa`` (the tolerance in that norm).
        """
        if self.opt.stop == "rate" or (self.opt.stop == "auto" and scale is not None):
            if scale is None:
                raise InputError("newton_stop", "rate", "needs error-norm scales (an adaptive run)")
            return self._solve_rate(residual, y, make_matrix, scale, kappa)
        opt, st = self.opt, self.stats
        eps = opt.eps_abs if eps_abs is None else eps_abs
        eps = eps * np.maximum(1.0, np.abs(y))   # relative above 1: stays above round-off of G
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

    def prepare(self, y, make_matrix) -> bool:
        """Build ``B`` if missing (new step size: the last Jacobian serves) or stale (a new
        Jacobian at ``y``); True when ``B`` comes from a Jacobian of the current solve."""
        fresh = self.opt.variant == "exact" or self.stale
        if fresh and self._fresh and self.B is not None:
            return True                      # already built for this solve
        if fresh or self.B is None:
            self._set(make_matrix(y, fresh))
            self.stale, self._fresh = False, fresh
        return self._fresh

    def solve_linear(self, r):
        """``B^-1 r`` with the current matrix (e.g. a linearly implicit predictor)."""
        return -self._direction(r)

    def _solve_rate(self, residual, y0, make_matrix, scale, kappa):
        """Simplified Newton with the contraction-rate test (see module docstring)."""
        opt, st = self.opt, self.stats

        def norm(v):
            return float(np.sqrt(np.mean(np.abs(v / scale) ** 2)))

        exact = opt.variant == "exact"
        fresh = self.prepare(y0, make_matrix)
        while True:
            y, g = y0, residual(y0)
            eta = max(self._eta, EPS) ** 0.8
            dn_old, theta, ok = None, 1.0, False
            for k in range(opt.max_iter):
                d = self._direction(g)
                st.counts["nnewton"] += 1
                dn = norm(d)
                if not np.isfinite(dn):
                    break
                if dn_old is not None:
                    theta = dn / dn_old if dn_old > 0 else 0.0
                    if theta >= 1.0 or theta ** (opt.max_iter - 1 - k) / (1 - theta) * dn > kappa:
                        break   # diverges, or too slow to reach kappa within max_iter
                    eta = theta / (1.0 - theta)
                y = y + d
                g_new = residual(y)
                if eta * dn <= kappa or dn == 0.0:
                    ok = True
                    g = g_new
                    break
                if opt.variant in ("broyden", "fake-broyden", "hart"):
                    self._update(d, g_new - g)
                elif exact:
                    self._set(make_matrix(y, True))
                g, dn_old = g_new, dn
            if ok:
                self._eta, self._fresh = eta, False
                if not exact and k + 1 > 2 and theta > RATE_REFRESH:
                    self.stale = True
                return y, g
            self._eta = 1.0
            if fresh:
                break
            st.counts["njac_refresh"] += 1
            self._set(make_matrix(y0, True))
            fresh = True
        st.counts["nnewton_fail"] += 1
        self.invalidate()
        raise StepFailure(f"Newton ({opt.variant}) diverged: rate {theta:.3g}, |dy|/tol = {dn:.3g} "
                          f"after {k + 1} iterations")

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
