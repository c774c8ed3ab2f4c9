"""Linear systems with the second-order structure eliminated (spec §4.2 note, §11.4).

For ``x = [u, v, z]`` and a matrix ``A`` whose ``u`` rows are ``[0 I 0]``, the system
``(I - gamma A) k = r`` reduces to the ``y = [v, z]`` block
``M = I - gamma A_yy - gamma^2 A_yu P_v`` (``P_v`` extracts ``v`` from ``y``):
``M k_y = r_y + gamma A_yu r_u``, then ``k_u = r_u + gamma k_v``. The same ``M`` is
``dG/dy`` of the theta method's velocity-only Newton system (2.17).
Sparse matrices are factored by SuperLU (``scipy.sparse.linalg.splu``); systems of at most
``DENSE_MAX`` unknowns use dense LAPACK LU, which is far cheaper than sparse bookkeeping there.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cvtfem.integrate.base import StepFailure

__all__ = ["DENSE_MAX", "reduced_matrix", "LU"]

DENSE_MAX = 64


def reduced_matrix(J, n2: int, gamma: float):
    """``M = I - gamma J_yy - gamma^2 J_yu P_v`` of size ``n - n2`` (``n2 = 0``: ``I - gamma J``).

    Dense in, dense out; sparse in, CSC out.
    """
    n = J.shape[0]
    if not sp.issparse(J):
        M = -gamma * J[n2:, n2:]
        if n2:
            M[:, :n2] -= gamma * gamma * J[n2:, :n2]
        M.flat[::n - n2 + 1] += 1.0
        return M
    Jy = sp.csr_matrix(J)[n2:]
    M = -gamma * Jy[:, n2:]
    if n2:
        M = M - gamma * gamma * sp.hstack([Jy[:, :n2], sp.csr_matrix((n - n2, n - 2 * n2))])
    return (sp.identity(n - n2, dtype=M.dtype, format="csc") + M).tocsc()


class LU:
    """LU factorisation of a reduced matrix (SuperLU, or LAPACK when small), counting
    ``nlu`` and ``nsolve``; ``solve_full`` undoes the ``u`` elimination."""

    def __init__(self, stats, M, n2: int = 0, gamma: float = 0.0, A_yu=None) -> None:
        self.stats, self.n2, self.gamma, self.A_yu = stats, n2, gamma, A_yu
        stats.counts["nlu"] += 1
        with stats.timer("t_lu"):
            if sp.issparse(M) and M.shape[0] <= DENSE_MAX:
                M = M.toarray()
            self.dense = not sp.issparse(M)
            try:
                if self.dense:   # LAPACK getrf/getrs directly: lu_factor's checks cost more than an 8x8 LU
                    getrf, self._getrs = sla.get_lapack_funcs(("getrf", "getrs"), (M,))
                    lu, piv, info = getrf(M)
                    if info != 0:
                        raise RuntimeError("zero pivot" if info > 0 else f"getrf info {info}")
                    self.lu = (lu, piv)
                else:
                    self.lu = spla.splu(sp.csc_matrix(M))
            except (RuntimeError, ValueError) as err:
                raise StepFailure(f"singular iteration matrix ({err})") from err

    def solve_y(self, r_y: np.ndarray) -> np.ndarray:
        """Solve ``M k_y = r_y`` (the Newton system of the reduced unknowns)."""
        self.stats.counts["nsolve"] += 1
        with self.stats.timer("t_solve"):
            if self.dense:
                k, _ = self._getrs(self.lu[0], self.lu[1], r_y)
            else:
                k = self.lu.solve(r_y)
        if not np.isfinite(k.sum()):   # a finite sum means every entry is finite
            raise StepFailure("non-finite solution of the iteration matrix")
        return k

    def solve_full(self, r: np.ndarray) -> np.ndarray:
        """Solve ``(I - gamma A) k = r`` for the full state (W-methods, error filtering)."""
        n2, g = self.n2, self.gamma
        if not n2:
            return self.solve_y(r)
        r_u, r_y = r[:n2], r[n2:]
        k_y = self.solve_y(r_y + g * (self.A_yu @ r_u))
        return np.concatenate([r_u + g * k_y[:n2], k_y])
