"""LU factors updated by a sparse secant step, without refactorisation (Newton ``hart``).

Our reading of Hart & Soesianto (1992), after Dennis & Marwil's direct secant updates of
matrix factorisations (Math. Comp. 38, 1982): with ``Pr B Pc = L U`` the unit-lower factor
``L`` is kept and ``U`` receives Schubert's row-wise sparse secant update restricted to its own
pattern, so that the updated product satisfies the secant equation ``B+ s = y`` exactly and
keeps both zero patterns. Solves use the (fixed) ``L`` and the updated ``U``.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.integrate.base import StepFailure

__all__ = ["UpdatedLU"]


class UpdatedLU:
    """``B = Pr^T L U Pc^T`` (dense: ``scipy.linalg.lu``; sparse: SuperLU factors)."""

    def __init__(self, stats, B) -> None:
        self.stats = stats
        stats.counts["nlu"] += 1
        with stats.timer("t_lu"):
            self.sparse = sp.issparse(B)
            n = B.shape[0]
            if self.sparse:
                try:
                    f = spla.splu(sp.csc_matrix(B))
                except RuntimeError as err:
                    raise StepFailure(f"singular iteration matrix ({err})") from err
                self.L, self.U = f.L.tocsr(), f.U.tocsr()
                self.pr, self.pc = f.perm_r, f.perm_c
            else:
                P, L, U = sla.lu(np.asarray(B))
                self.L, self.U = L, U
                self.pr = np.argmax(P, axis=0)      # row i of B goes to row pr[i] of L U
                self.pc = np.arange(n)
        self.mask = (self.U != 0).astype(float) if not self.sparse else None

    def _tri(self, M, b, lower):
        if self.sparse:
            return spla.spsolve_triangular(M, b, lower=lower, unit_diagonal=lower)
        return sla.solve_triangular(M, b, lower=lower, unit_diagonal=lower, check_finite=False)

    def solve_y(self, b: np.ndarray) -> np.ndarray:
        """Solve ``B x = b``."""
        self.stats.counts["nsolve"] += 1
        with self.stats.timer("t_solve"):
            bp = np.empty_like(b)
            bp[self.pr] = b
            w = self._tri(self.U, self._tri(self.L, bp, True), False)
            x = w[self.pc]
        if not np.all(np.isfinite(x)):
            raise StepFailure("non-finite solution of the updated LU factors")
        return x

    def update(self, s: np.ndarray, y: np.ndarray) -> None:
        """Schubert update of ``U`` on its pattern so that the product maps ``s`` to ``y``."""
        sp_ = np.empty_like(s)
        sp_[self.pc] = s
        yp = np.empty_like(y)
        yp[self.pr] = y
        self.stats.counts["nsolve"] += 1
        r = self._tri(self.L, yp, True) - self.U @ sp_
        if self.sparse:
            U = self.U.tocoo()
            d = np.bincount(U.row, weights=sp_[U.col] ** 2, minlength=U.shape[0])
            scale = np.divide(r, d, out=np.zeros_like(r), where=d > 0)
            U.data = U.data + scale[U.row] * sp_[U.col]
            self.U = U.tocsr()
        else:
            d = self.mask @ (sp_ ** 2)
            scale = np.divide(r, d, out=np.zeros_like(r), where=d > 0)
            self.U = self.U + self.mask * np.outer(scale, sp_)
