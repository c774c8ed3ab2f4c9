"""Jacobian providers (spec §11.3): analytic, graph-coloured finite differences, dense FD.

Columns ``i, j`` of ``dF/dx`` may share a finite-difference evaluation when no row has
non-zeros in both (Curtis-Powell-Reid; Ypma 1987): a colouring of the column intersection
graph ``S^T S``. Cost of one Jacobian = number of colours RHS calls (``F(x)`` is reused).
For second-order systems the ``u' = v`` rows ``[0 I 0]`` are set analytically.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from cvtfem.integrate.linsolve import DENSE_MAX

__all__ = ["color_columns", "JacobianProvider"]


def color_columns(pattern: sp.spmatrix, order: str = "largest_first") -> np.ndarray:
    """Greedy colouring of the column intersection graph of ``pattern`` (n_rows, n).

    Returns ``colors`` (n,) with ``colors[j]`` the group of column ``j``; columns in one group
    have disjoint row supports. ``order``: ``"largest_first"`` (by degree) or ``"natural"``.
    """
    S = sp.csc_matrix(pattern, dtype=bool).astype(np.int8)
    G = (S.T @ S).tocsr()
    n = G.shape[0]
    degree = np.diff(G.indptr)
    visit = np.argsort(-degree, kind="stable") if order == "largest_first" else np.arange(n)
    colors = np.full(n, -1, dtype=np.int64)
    for j in visit:
        used = set(colors[G.indices[G.indptr[j]:G.indptr[j + 1]]].tolist())
        c = 0
        while c in used:
            c += 1
        colors[j] = c
    return colors


class JacobianProvider:
    """Computes ``J = dF/dx`` at ``(t, x)`` as CSR: analytic, coloured FD or dense FD.

    Counts ``njev``, and ``nfev_jac`` (also added to ``nfev``) for the RHS calls it makes.
    """

    def __init__(self, stepper) -> None:
        self.stepper = stepper
        system = stepper.system
        self.n, self.n2 = system.n, system.n2
        self.analytic = system.jac
        self.colors = None
        self.pattern = None
        if self.analytic is None:
            pattern = system.jac_sparsity
            if pattern is None:
                pattern = sp.csr_matrix(np.ones((self.n, self.n), dtype=bool))
            pattern = sp.csr_matrix(pattern, dtype=bool)
            n2 = self.n2
            if n2:  # rows u' = v are known: difference only the F_v, F_z rows
                pattern = sp.vstack([sp.csr_matrix((n2, self.n), dtype=bool), pattern[n2:]]).tocsr()
            self.pattern = pattern.tocoo()
            self.colors = color_columns(pattern)
        self.n_colors = None if self.colors is None else int(self.colors.max()) + 1

    def __call__(self, t: float, x: np.ndarray):
        """``J`` as an ndarray (``n <= DENSE_MAX``) or CSR matrix."""
        st = self.stepper.stats
        st.counts["njev"] += 1
        with st.timer("t_jac"):
            J = self.analytic(t, x) if self.analytic is not None else self._fd(t, x)
        if self.n <= DENSE_MAX:
            return J.toarray() if sp.issparse(J) else np.array(J, dtype=float)
        return sp.csr_matrix(J)

    def _fd(self, t, x):
        f = self.stepper.f
        f0 = f(t, x)
        saved = self.stepper._cache
        eps = np.sqrt(np.finfo(float).eps)
        delta = eps * np.maximum(np.abs(x), 1.0)
        delta = (x + delta) - x  # representable increments
        rows, cols = self.pattern.row, self.pattern.col
        vals = np.empty(len(rows), dtype=np.result_type(x, f0))
        st = self.stepper.stats
        for c in range(self.n_colors):
            mask = self.colors == c
            xp = x.copy()
            xp[mask] += delta[mask]
            st.counts["nfev_jac"] += 1
            df = f(t, xp) - f0
            sel = mask[cols]
            vals[sel] = df[rows[sel]] / delta[cols[sel]]
        self.stepper._cache = saved
        J = sp.csr_matrix((vals, (rows, cols)), shape=(self.n, self.n))
        if self.n2:
            n2 = self.n2
            J = J + sp.csr_matrix((np.ones(n2), (np.arange(n2), np.arange(n2, 2 * n2))), shape=J.shape)
        return J
